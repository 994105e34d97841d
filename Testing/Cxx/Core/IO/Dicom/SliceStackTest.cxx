#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "IO/Dicom/SliceStack.h"

namespace {

using Eigen::Vector2d;
using Eigen::Vector2i;
using Eigen::Vector3d;

/// A linear HU field over LPS space: exact under linear and bilinear interpolation.
float rampHu(const Vector3d& p_lps_mm) { return static_cast<float>(-500.0 + 2.0 * p_lps_mm.x() - 3.0 * p_lps_mm.y() + 10.0 * p_lps_mm.z()); }

/// Fills every pixel of every slice with rampHu at its LPS position.
void fillWithRamp(fct::SliceStack& stack, const Vector3d& row, const Vector3d& col) {
  for (int k = 0; k < stack.sliceCount(); ++k) {
    float* pixels = stack.slice(k);
    for (int j = 0; j < stack.size_px().y(); ++j) {
      for (int i = 0; i < stack.size_px().x(); ++i) {
        const Vector3d p = stack.sliceOrigins_lps_mm()[k] + i * stack.pixelSpacing_mm().x() * row +
                           j * stack.pixelSpacing_mm().y() * col;
        pixels[j * stack.size_px().x() + i] = rampHu(p);
      }
    }
  }
}

}  // namespace

TEST(SliceStack, RegularStackBecomesVolumeWithoutInterpolation) {
  const Vector3d row = Vector3d(1, 1, 0).normalized(), col = Vector3d(-1, 1, 0).normalized();
  auto stack = fct::SliceStack::create({4, 3}, {0.5, 0.75}, row, col,
                                       {Vector3d(10, 20, 30), Vector3d(10, 20, 32.5), Vector3d(10, 20, 35)});
  ASSERT_TRUE(stack.ok()) << stack.error();
  fillWithRamp(stack.value(), row, col);
  const auto layout = stack.value().layout();
  EXPECT_TRUE(layout.isRegular());
  EXPECT_NEAR(layout.meanGap_mm, 2.5, 1e-12);
  EXPECT_NEAR(layout.tilt_deg, 0.0, 1e-9);
  const std::vector<float> pixels(stack.value().slice(0), stack.value().slice(0) + 4 * 3 * 3);

  auto volume = std::move(stack.value()).toVolume();
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_EQ(volume.value().dims(), Eigen::Vector3i(4, 3, 3));
  EXPECT_TRUE(volume.value().spacing_mm().isApprox(Vector3d(0.5, 0.75, 2.5)));
  EXPECT_TRUE(volume.value().origin_lps_mm().isApprox(Vector3d(10, 20, 30)));
  EXPECT_TRUE(volume.value().direction_lps().col(2).isApprox(Vector3d::UnitZ()));
  EXPECT_EQ(volume.value().voxels(), pixels);
}

TEST(SliceStack, ResamplesLinearRampAtIrregularPositionsExactly) {
  const Vector3d row = Vector3d::UnitX(), col = Vector3d::UnitY();
  auto stack = fct::SliceStack::create({5, 4}, {0.8, 0.5}, row, col,
                                       {Vector3d(0, 0, 0), Vector3d(0, 0, 1), Vector3d(0, 0, 3), Vector3d(0, 0, 7)});
  ASSERT_TRUE(stack.ok()) << stack.error();
  fillWithRamp(stack.value(), row, col);
  const auto layout = stack.value().layout();
  EXPECT_FALSE(layout.uniformSpacing);
  EXPECT_TRUE(layout.alongNormal);
  EXPECT_DOUBLE_EQ(layout.minGap_mm, 1.0);
  EXPECT_DOUBLE_EQ(layout.maxGap_mm, 4.0);

  auto volume = stack.value().resampled(0.5, -1024.0f);
  ASSERT_TRUE(volume.ok()) << volume.error();
  const fct::Volume& v = volume.value();
  ASSERT_EQ(v.dims(), Eigen::Vector3i(5, 4, 15));  // 0, 0.5, ..., 7.0 mm
  EXPECT_TRUE(v.origin_lps_mm().isApprox(Vector3d::Zero()));
  for (int k = 0; k < v.dims().z(); ++k) {
    for (int j = 0; j < v.dims().y(); ++j) {
      for (int i = 0; i < v.dims().x(); ++i) {
        const Vector3d p = v.lpsFromIjk(Vector3d(i, j, k));
        EXPECT_NEAR(p.z(), 0.5 * k, 1e-9);
        ASSERT_NEAR(v.at(i, j, k), rampHu(p), 1e-3) << i << "," << j << "," << k;
      }
    }
  }
}

TEST(SliceStack, ResamplesTiltedStackOntoOrthogonalGrid) {
  // Slices in axial planes whose origins step 1.0 mm along +y per 2.0 mm along z: a 26.57° tilt.
  const Vector3d row = Vector3d::UnitX(), col = Vector3d::UnitY();
  std::vector<Vector3d> origins;
  for (int m = 0; m < 6; ++m) origins.emplace_back(5.0, 1.0 * m, 2.0 * m);
  auto stack = fct::SliceStack::create({6, 8}, {1.0, 0.5}, row, col, origins);
  ASSERT_TRUE(stack.ok()) << stack.error();
  fillWithRamp(stack.value(), row, col);
  const auto layout = stack.value().layout();
  EXPECT_FALSE(layout.alongNormal);
  EXPECT_TRUE(layout.uniformSpacing);
  EXPECT_NEAR(layout.tilt_deg, std::atan2(1.0, 2.0) * 180.0 / std::numbers::pi, 1e-9);

  auto volume = stack.value().resampled(1.0, -1000.0f);
  ASSERT_TRUE(volume.ok()) << volume.error();
  const fct::Volume& v = volume.value();
  // In-plane extent covers all shifted slices: 8 rows + 5 mm / 0.5 mm shift = 18 rows; 10 mm / 1 mm = 11 slices.
  ASSERT_EQ(v.dims(), Eigen::Vector3i(6, 18, 11));
  EXPECT_TRUE((v.direction_lps() - Eigen::Matrix3d::Identity()).isZero(1e-12));
  int inside = 0, outside = 0;
  for (int k = 0; k < v.dims().z(); ++k) {
    for (int j = 0; j < v.dims().y(); ++j) {
      for (int i = 0; i < v.dims().x(); ++i) {
        const Vector3d p = v.lpsFromIjk(Vector3d(i, j, k));
        // Covered by both neighbouring slices: y within [shift of the upper slice, shift of the lower + 3.5 mm].
        const double lowerShift = std::floor(p.z() / 2.0), upperShift = std::min(5.0, lowerShift + 1.0);
        if (p.y() >= upperShift - 1e-9 && p.y() <= lowerShift + 3.5 + 1e-9) {
          ASSERT_NEAR(v.at(i, j, k), rampHu(p), 1e-3) << i << "," << j << "," << k;
          ++inside;
        } else if (p.y() < lowerShift - 0.5 || p.y() > upperShift + 4.0) {
          ASSERT_FLOAT_EQ(v.at(i, j, k), -1000.0f) << i << "," << j << "," << k;
          ++outside;
        }
      }
    }
  }
  EXPECT_GT(inside, 200);
  EXPECT_GT(outside, 200);
}

TEST(SliceStack, RejectsBadStacks) {
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY();
  EXPECT_FALSE(fct::SliceStack::create({4, 4}, {1, 1}, x, y, {Vector3d::Zero()}).ok());
  EXPECT_FALSE(fct::SliceStack::create({4, 4}, {1, 1}, x, y, {Vector3d(0, 0, 1), Vector3d::Zero()}).ok());
  EXPECT_FALSE(fct::SliceStack::create({4, 4}, {1, 1}, x, y, {Vector3d::Zero(), Vector3d(5, 0, 0)}).ok());
  EXPECT_FALSE(fct::SliceStack::create({4, 4}, {1, 1}, x, Vector3d(1, 1, 0), {Vector3d::Zero(), Vector3d::UnitZ()}).ok());
  EXPECT_FALSE(fct::SliceStack::create({0, 4}, {1, 1}, x, y, {Vector3d::Zero(), Vector3d::UnitZ()}).ok());
  EXPECT_FALSE(fct::SliceStack::create({4, 4}, {0, 1}, x, y, {Vector3d::Zero(), Vector3d::UnitZ()}).ok());

  auto irregular = fct::SliceStack::create({4, 4}, {1, 1}, x, y, {Vector3d::Zero(), Vector3d(0, 0, 1), Vector3d(0, 0, 3)});
  ASSERT_TRUE(irregular.ok());
  EXPECT_FALSE(irregular.value().resampled(0.0, -1024.0f).ok());
  EXPECT_FALSE(irregular.value().resampled(std::nan(""), -1024.0f).ok());
  const auto notRegular = std::move(irregular.value()).toVolume();
  ASSERT_FALSE(notRegular.ok());
  EXPECT_NE(notRegular.error().find("1.000–2.000 mm"), std::string::npos) << notRegular.error();
}

TEST(SliceStack, RefusesAGridFarLargerThanItsSlicesAsImplausiblePositions) {
  const Vector3d row(1, 0, 0), col(0, 1, 0);
  // A slice origin 10 m off in-plane (a damaged ImagePositionPatient, found by fuzzing) would need a grid of ~10^8
  // voxels for 60 pixels of data.
  auto stack = fct::SliceStack::create({5, 4}, {0.8, 0.5}, row, col,
                                       {Vector3d(0, 0, 0), Vector3d(10000, 0, 1), Vector3d(0, 0, 3)});
  ASSERT_TRUE(stack.ok()) << stack.error();
  const auto resampled = stack.value().resampled(1.0, -1000.0f);
  ASSERT_FALSE(resampled.ok());
  EXPECT_NE(resampled.error().find("looks damaged"), std::string::npos) << resampled.error();
}
