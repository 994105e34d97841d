#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "Simulation/CtSliceDegrader.h"

namespace {

constexpr float kAir = fct::CtSliceDegrader::kAir_hu;

/// A 1 mm CT, 8 x 8 x 101 voxels (slab −0.5..100.5 mm along k), tilted, with 1000 HU over slices 40..59 in 0 HU.
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

/// Position along the CT's k axis (mm from the ORIGINAL slice 0 centre, through the volume's own origin) of slice k.
double sliceAxis_mm(const fct::Volume& volume, const fct::Volume& original, int k) {
  const Eigen::Vector3d p = volume.lpsFromIjk(Eigen::Vector3d(3, 4, k));
  return original.direction_lps().col(2).dot(p - original.origin_lps_mm());
}

/// Attenuation-weighted (HU above air) centroid along k of column (3, 4), in mm as sliceAxis_mm.
double attenuationCentroid_mm(const fct::Volume& volume, const fct::Volume& original) {
  double mass = 0.0, moment = 0.0;
  for (int k = 0; k < volume.dims().z(); ++k) {
    const double w = volume.at(3, 4, k) - kAir;
    mass += w;
    moment += w * sliceAxis_mm(volume, original, k);
  }
  return moment / mass;
}

}  // namespace

TEST(CtSliceDegrader, CoversExactlyTheOriginalSlab) {
  const fct::Volume ct = slabCt();
  for (double thickness : {1.0, 2.4, 4.2, 7.0}) {
    SCOPED_TRACE(thickness);
    auto degraded = fct::CtSliceDegrader::degrade(ct, thickness);
    ASSERT_TRUE(degraded.ok()) << degraded.error();
    const fct::Volume& out = degraded.value();
    EXPECT_TRUE(out.direction_lps().isApprox(ct.direction_lps()));
    EXPECT_EQ(out.dims().head<2>(), ct.dims().head<2>());
    EXPECT_NEAR(out.dims().z() * out.spacing_mm().z(), 101.0, 1e-9);
    EXPECT_NEAR(out.spacing_mm().z(), thickness, 0.5 * thickness / out.dims().z() + 1e-12);
    // End faces: first slab starts and last slab ends where the original's do.
    EXPECT_NEAR(sliceAxis_mm(out, ct, 0) - 0.5 * out.spacing_mm().z(), -0.5, 1e-9);
    EXPECT_NEAR(sliceAxis_mm(out, ct, out.dims().z() - 1) + 0.5 * out.spacing_mm().z(), 100.5, 1e-9);
    // In-plane position of voxel (i, j) is unchanged.
    const Eigen::Vector3d inPlane = out.lpsFromIjk(Eigen::Vector3d(5, 2, 0)) - ct.lpsFromIjk(Eigen::Vector3d(5, 2, 0));
    EXPECT_NEAR(inPlane.dot(ct.direction_lps().col(0)), 0.0, 1e-9);
    EXPECT_NEAR(inPlane.dot(ct.direction_lps().col(1)), 0.0, 1e-9);
  }
}

TEST(CtSliceDegrader, KeepsTheAttenuationCentroidAndIntegral) {
  const fct::Volume ct = slabCt();
  const double centroid = attenuationCentroid_mm(ct, ct);
  for (double thickness : {2.4, 4.2}) {
    SCOPED_TRACE(thickness);
    const fct::Volume out = fct::CtSliceDegrader::degrade(ct, thickness).value();
    EXPECT_NEAR(attenuationCentroid_mm(out, ct), centroid, 0.05);
    double integral = 0.0;
    for (int k = 0; k < out.dims().z(); ++k) integral += out.at(3, 4, k) * out.spacing_mm().z();
    EXPECT_NEAR(integral, 20.0 * 1000.0, 0.02 * 20000.0);
  }
}

TEST(CtSliceDegrader, KeepsAThinPlateWhereItIs) {
  // A 1 mm plate in one original slice lands, with all its mass, in the thick slice(s) whose slab overlaps it: their
  // profile-weighted centre is within half a thick slice of the plate, never shifted by the end faces.
  for (int plateSlice : {2, 37, 73, 99}) {
    fct::Volume ct = slabCt();
    std::fill(ct.voxels().begin(), ct.voxels().end(), 0.0f);
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) ct.at(i, j, plateSlice) = 3000.0f;
    for (double thickness : {2.4, 4.2}) {
      SCOPED_TRACE(::testing::Message() << "plate " << plateSlice << " mm, thickness " << thickness);
      const fct::Volume out = fct::CtSliceDegrader::degrade(ct, thickness).value();
      const double halfSpacing = 0.5 * out.spacing_mm().z();
      double mass = 0.0, moment = 0.0;
      for (int k = 0; k < out.dims().z(); ++k) {
        const double w = out.at(3, 4, k), z = sliceAxis_mm(out, ct, k);
        if (std::abs(z - plateSlice) > halfSpacing + 0.5 + 1e-9) {
          EXPECT_NEAR(w, 0.0, 1e-3) << "slice at " << z << " mm";
        }
        mass += w;
        moment += w * z;
      }
      EXPECT_LE(std::abs(moment / mass - plateSlice), halfSpacing);
      EXPECT_NEAR(mass * out.spacing_mm().z(), 3000.0, 0.01 * 3000.0);  // profile width vs. spacing: < 1 %
    }
  }
}

TEST(CtSliceDegrader, SeesAirBeyondTheEndFaces) {
  // A uniform 0 HU CT: slabs inside stay 0; an end slab whose profile overhangs the face mixes in air.
  fct::Volume ct = slabCt();
  std::fill(ct.voxels().begin(), ct.voxels().end(), 0.0f);
  const fct::Volume out = fct::CtSliceDegrader::degrade(ct, 4.0).value();  // 101 / 4 -> 25 slabs of 4.04 mm
  ASSERT_EQ(out.dims().z(), 25);
  EXPECT_NEAR(out.at(3, 4, 12), 0.0, 1e-3);
  EXPECT_NEAR(out.at(3, 4, 0), 0.0, 1e-3);  // a 4 mm profile inside a 4.04 mm slab: no overhang
  const fct::Volume wide = fct::CtSliceDegrader::degrade(ct, 5.0).value();  // 101 / 5 -> 20 slabs of 5.05 mm
  EXPECT_NEAR(wide.at(3, 4, 0), 0.0, 1e-3);
  const fct::Volume over = fct::CtSliceDegrader::degrade(ct, 5.4).value();  // 19 slabs of 5.316 mm, 5.4 mm profile
  const double overhang = 0.5 * (5.4 - 101.0 / 19) / 5.4;
  EXPECT_NEAR(over.at(3, 4, 0), overhang * kAir, 1e-3);
  EXPECT_NEAR(over.at(3, 4, 18), overhang * kAir, 1e-3);
}

TEST(CtSliceDegrader, RejectsFinerOrInvalidThickness) {
  const fct::Volume ct = slabCt();
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(ct, 0.5).ok());
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(ct, 0.0).ok());
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(ct, std::numeric_limits<double>::quiet_NaN()).ok());
  EXPECT_FALSE(fct::CtSliceDegrader::degrade(fct::Volume(), 2.4).ok());
}
