#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "Image/Volume.h"

TEST(Volume, IndexToLpsRoundTripWithObliqueDirection) {
  const Eigen::Matrix3d direction = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  auto volume = fct::Volume::create({10, 20, 30}, {0.5, 0.75, 2.0}, {-100, 50, 20}, direction);
  ASSERT_TRUE(volume.ok()) << volume.error();
  const Eigen::Vector3d ijk(3.25, 7.5, 12.0);
  const Eigen::Vector3d p = volume.value().lpsFromIjk(ijk);
  EXPECT_NEAR((volume.value().ijkFromLps(p) - ijk).norm(), 0.0, 1e-9);
  EXPECT_NEAR((volume.value().T_lps_from_ijk() * ijk - p).norm(), 0.0, 1e-9);
  EXPECT_NEAR((volume.value().T_ijk_from_lps() * p - ijk).norm(), 0.0, 1e-9);
  // One step in k moves 2 mm along the third direction cosine.
  EXPECT_NEAR((volume.value().lpsFromIjk(ijk + Eigen::Vector3d::UnitZ()) - p - 2.0 * direction.col(2)).norm(), 0.0, 1e-9);
}

TEST(Volume, StoresVoxelsIFastest) {
  auto volume = fct::Volume::create({4, 3, 2}, {1, 1, 1}).value();
  volume.at(3, 2, 1) = 1000.0f;
  EXPECT_EQ(volume.voxels().back(), 1000.0f);
  volume.at(1, 0, 0) = -1000.0f;
  EXPECT_EQ(volume.voxels()[1], -1000.0f);
  const auto [lo, hi] = volume.valueRange();
  EXPECT_EQ(lo, -1000.0f);
  EXPECT_EQ(hi, 1000.0f);
}

TEST(Volume, RejectsBadGeometry) {
  EXPECT_FALSE(fct::Volume::create({0, 10, 10}, {1, 1, 1}).ok());
  EXPECT_NE(fct::Volume::create({10, 10, 10}, {1, -1, 1}).error().find("spacing"), std::string::npos);
  Eigen::Matrix3d skewed = Eigen::Matrix3d::Identity();
  skewed(0, 1) = 0.5;
  EXPECT_NE(fct::Volume::create({10, 10, 10}, {1, 1, 1}, {0, 0, 0}, skewed).error().find("orthonormal"), std::string::npos);
}

TEST(Volume, FromVoxelsTakesTheValuesAndChecksTheirCount) {
  std::vector<float> values(4 * 3 * 2);
  for (std::size_t n = 0; n < values.size(); ++n) values[n] = static_cast<float>(n);
  const auto volume = fct::Volume::fromVoxels({4, 3, 2}, {0.5, 1, 2}, {1, 2, 3}, Eigen::Matrix3d::Identity(), values);
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_EQ(volume.value().at(3, 2, 1), 23.0f);
  EXPECT_EQ(volume.value().spacing_mm(), Eigen::Vector3d(0.5, 1, 2));
  const auto tooFew = fct::Volume::fromVoxels({4, 3, 3}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity(), values);
  ASSERT_FALSE(tooFew.ok());
  EXPECT_NE(tooFew.error().find("24 voxel values given for a 4x3x3 volume (36 voxels)"), std::string::npos) << tooFew.error();
  EXPECT_FALSE(fct::Volume::fromVoxels({4, 3, 2}, {1, 0, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity(), values).ok());
}

TEST(Volume, ValueRangeOfALargeVolumeSkipsNaN) {
  auto volume = fct::Volume::create({300, 200, 10}, {1, 1, 1}, {0, 0, 0}, Eigen::Matrix3d::Identity(), 5.0f).value();
  volume.at(7, 150, 9) = -3.0f;
  volume.at(299, 0, 0) = 42.0f;
  volume.at(0, 0, 0) = NAN;
  const auto [lo, hi] = volume.valueRange();
  EXPECT_EQ(lo, -3.0f);
  EXPECT_EQ(hi, 42.0f);
}
