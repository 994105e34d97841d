#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "Simulation/CtSliceDegrader.h"

namespace {
/// A 1 mm CT, 8 x 8 x 101 voxels, with a 1000 HU slab over slices 40..59 (z = 40..59 mm above the origin) in 0 HU.
fct::Volume slabCt() {
  const Eigen::Matrix3d direction = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(8, 8, 101), Eigen::Vector3d(0.8, 0.8, 1.0),
                                       Eigen::Vector3d(10, 20, 30), direction, 0.0f)
                       .value();
  for (int k = 40; k < 60; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) ct.at(i, j, k) = 1000.0f;
  return ct;
}
}  // namespace

TEST(CtSliceDegrader, KeepsGeometryAndTheSlabProfile) {
  const fct::Volume ct = slabCt();
  for (double spacing : {2.4, 4.2}) {
    SCOPED_TRACE(spacing);
    auto degraded = fct::CtSliceDegrader::degrade(ct, spacing);
    ASSERT_TRUE(degraded.ok()) << degraded.error();
    const fct::Volume& out = degraded.value();
    EXPECT_TRUE(out.origin_lps_mm().isApprox(ct.origin_lps_mm()));
    EXPECT_TRUE(out.direction_lps().isApprox(ct.direction_lps()));
    EXPECT_EQ(out.dims().head<2>(), ct.dims().head<2>());
    EXPECT_DOUBLE_EQ(out.spacing_mm().z(), spacing);
    const double extent = (out.dims().z() - 1) * spacing;
    EXPECT_LE(extent, 100.0 + 1e-9);
    EXPECT_GT(extent, 100.0 - spacing);
    // The slab's middle keeps its value, far slices stay 0, the profile's integral is kept.
    double integral = 0.0;
    for (int k = 0; k < out.dims().z(); ++k) {
      const double z = k * spacing, value = out.at(3, 4, k);
      integral += value * spacing;
      if (z > 42.0 + spacing && z < 57.0 - spacing) {
        EXPECT_NEAR(value, 1000.0, 1e-3) << z;
      }
      if (z < 38.0 - spacing || z > 61.0 + spacing) {
        EXPECT_NEAR(value, 0.0, 1e-3) << z;
      }
    }
    EXPECT_NEAR(integral, 20.0 * 1000.0, 0.02 * 20000.0);
  }
}

TEST(CtSliceDegrader, RejectsFinerOrInvalidSpacing) {
  const fct::Volume ct = slabCt();
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(ct, 0.5).ok());
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(ct, 0.0).ok());
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(ct, std::numeric_limits<double>::quiet_NaN()).ok());
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(fct::Volume(), 2.4).ok());
}
