#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "DrrVolume.h"

namespace {

fct::Volume fourVoxelCt() {
  fct::Volume ct = fct::Volume::create({4, 1, 1}, {0.5, 0.7, 2.0}, {10, 20, 30}).value();
  ct.voxels() = {-1200.0f, -1000.0f, 0.0f, 1000.0f};
  return ct;
}

}  // namespace

TEST(DrrVolume, ConvertsHuToAttenuationWithAirClampedToZero) {
  const auto volume = fct::DrrVolume::create(fourVoxelCt());
  ASSERT_TRUE(volume.ok()) << volume.error();
  const double mu = fct::DrrValueOptions::kWaterAttenuationAt60keV_per_mm;
  const std::vector<float>& v = volume.value().values().voxels();
  EXPECT_EQ(v[0], 0.0f);
  EXPECT_EQ(v[1], 0.0f);
  EXPECT_NEAR(v[2], mu, 1e-7);
  EXPECT_NEAR(v[3], 2.0 * mu, 1e-7);
  EXPECT_EQ(volume.value().options().kind, fct::DrrValueKind::Attenuation);
}

TEST(DrrVolume, RawValuesAndGeometryAreThoseOfTheCt) {
  const fct::Volume ct = fourVoxelCt();
  fct::DrrValueOptions options;
  options.kind = fct::DrrValueKind::Raw;
  const auto volume = fct::DrrVolume::create(ct, options);
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_EQ(volume.value().values().voxels(), ct.voxels());
  const Eigen::Vector3d p_ct_mm(11.3, 19.0, 33.0);
  EXPECT_NEAR((volume.value().T_ct_from_ijk() * (volume.value().T_ijk_from_ct() * p_ct_mm) - p_ct_mm).norm(), 0.0, 1e-12);
  EXPECT_NEAR((volume.value().T_ijk_from_ct() * p_ct_mm - ct.ijkFromLps(p_ct_mm)).norm(), 0.0, 1e-12);
  EXPECT_EQ(volume.value().boxMax_ijk(), Eigen::Vector3d(3.5, 0.5, 0.5));
}

TEST(DrrVolume, RejectsEmptyCtNonFiniteVoxelsAndBadWaterAttenuation) {
  EXPECT_FALSE(fct::DrrVolume::create(fct::Volume()).ok());
  fct::Volume ct = fourVoxelCt();
  ct.voxels()[2] = std::numeric_limits<float>::quiet_NaN();
  const auto nan = fct::DrrVolume::create(ct);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().find("1 voxels that are NaN"), std::string::npos) << nan.error();
  fct::DrrValueOptions options;
  options.waterAttenuation_per_mm = 0.0;
  EXPECT_FALSE(fct::DrrVolume::create(fourVoxelCt(), options).ok());
}

TEST(DrrVolume, ParsesValueKindNames) {
  for (const auto kind : {fct::DrrValueKind::Attenuation, fct::DrrValueKind::Raw}) {
    const auto parsed = fct::DrrVolume::parseValueKind(fct::DrrVolume::valueKindName(kind));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(parsed.value(), kind);
  }
  EXPECT_FALSE(fct::DrrVolume::parseValueKind("hu").ok());
}
