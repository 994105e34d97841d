#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "Simulation/Physics/CubicBsplinePatient.h"

namespace {

constexpr int kSoft = static_cast<int>(fct::Material::SoftTissue);

/// A rotated, anisotropic 0 HU grid of 17 x 23 x 11 voxels.
fct::Volume rotatedCt(float fill_hu) {
  const Eigen::Matrix3d direction = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  return fct::Volume::create(Eigen::Vector3i(17, 23, 11), Eigen::Vector3d(1.3, 0.9, 2.5), Eigen::Vector3d(5, -3, 2),
                             direction, fill_hu)
      .value();
}

}  // namespace

TEST(CubicBsplinePatient, InterpolatesTheCtSamplesAndReproducesARamp) {
  // HU = 10 i + 3 j² − 5 k: the interpolant passes through every sample; between samples, away from the mirrored
  // boundary, it reproduces the (at most cubic) polynomial.
  fct::Volume ct = rotatedCt(0.0f);
  for (int k = 0; k < 11; ++k)
    for (int j = 0; j < 23; ++j)
      for (int i = 0; i < 17; ++i) ct.at(i, j, k) = static_cast<float>(10.0 * i + 3.0 * j * j - 5.0 * k);
  auto patient = fct::CubicBsplinePatient::create(ct, {}, 0.0);
  ASSERT_TRUE(patient.ok()) << patient.error();
  for (const Eigen::Vector3d ijk : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(16, 22, 10), Eigen::Vector3d(7, 3, 5)}) {
    EXPECT_NEAR(patient.value().value_hu(ct.lpsFromIjk(ijk)), ct.at(int(ijk.x()), int(ijk.y()), int(ijk.z())), 1e-2);
  }
  const Eigen::Vector3d between(8.37, 11.61, 5.25);
  const double expected = 10.0 * between.x() + 3.0 * between.y() * between.y() - 5.0 * between.z();
  EXPECT_NEAR(patient.value().value_hu(ct.lpsFromIjk(between)), expected, 0.05);
  EXPECT_EQ(patient.value().value_hu(ct.lpsFromIjk(Eigen::Vector3d(-3, 0, 0))), -1000.0);
}

TEST(CubicBsplinePatient, IntegratesChordsOfAUniformPatientWithoutVoxelSteps) {
  // 0 HU everywhere: the soft-tissue mass path is the chord through the box; rays a fraction of a voxel apart see
  // the same smooth patient, so a sub-voxel shift of the ray changes nothing.
  const fct::Volume ct = rotatedCt(0.0f);
  const fct::CubicBsplinePatient patient = fct::CubicBsplinePatient::create(ct, {}, 0.0).value();
  const Eigen::Vector3d centre = ct.lpsFromIjk(Eigen::Vector3d(8, 11, 5));
  const Eigen::Vector3d k = ct.direction_lps().col(2);
  EXPECT_NEAR(patient.trace(centre - 100.0 * k, k)[kSoft], 2.75, 1e-4);  // 11 × 2.5 mm, in cm · g/cm³
  for (double shift : {0.1, 0.25, 0.5}) {
    const Eigen::Vector3d offset = ct.direction_lps().col(0) * shift * 1.3;
    EXPECT_NEAR(patient.trace(centre + offset - 100.0 * k, k)[kSoft], 2.75, 1e-4) << shift;
  }
  EXPECT_EQ(patient.trace(centre + Eigen::Vector3d(500, 0, 0), k)[kSoft], 0.0);  // a miss
}

TEST(CubicBsplinePatient, ContinuesThePatientBeyondTheEndFaces) {
  // Along k, a 40 mm extension adds the mirrored end slabs on both sides: 27.5 mm + 2 × 40 mm of tissue.
  const fct::Volume ct = rotatedCt(0.0f);
  const fct::CubicBsplinePatient patient = fct::CubicBsplinePatient::create(ct, {}, 40.0).value();
  const Eigen::Vector3d centre = ct.lpsFromIjk(Eigen::Vector3d(8, 11, 5));
  const Eigen::Vector3d k = ct.direction_lps().col(2);
  EXPECT_NEAR(patient.trace(centre - 200.0 * k, k)[kSoft], 10.75, 1e-3);
  EXPECT_NEAR(patient.value_hu(ct.lpsFromIjk(Eigen::Vector3d(8, 11, 20))), 0.0, 1e-3);  // 25 mm beyond the top
  EXPECT_EQ(patient.value_hu(ct.lpsFromIjk(Eigen::Vector3d(8, 11, 30))), -1000.0);        // 50 mm beyond: air
  // In-plane the patient ends at the box: a ray along i crosses 17 × 1.3 mm.
  const Eigen::Vector3d i = ct.direction_lps().col(0);
  EXPECT_NEAR(patient.trace(centre - 100.0 * i, i)[kSoft], 2.21, 1e-3);
}

TEST(CubicBsplinePatient, RejectsBadInput) {
  fct::Volume ct = rotatedCt(0.0f);
  EXPECT_FALSE(fct::CubicBsplinePatient::create(fct::Volume(), {}, 0.0).ok());
  EXPECT_FALSE(fct::CubicBsplinePatient::create(ct, {}, -1.0).ok());
  EXPECT_FALSE(fct::CubicBsplinePatient::create(ct, {}, std::numeric_limits<double>::quiet_NaN()).ok());
  fct::HuMaterialModel badModel;
  badModel.boneFrom_hu = badModel.airBelow_hu - 1.0;
  EXPECT_FALSE(fct::CubicBsplinePatient::create(ct, badModel, 0.0).ok());
  ct.at(1, 2, 3) = std::numeric_limits<float>::infinity();
  auto rejected = fct::CubicBsplinePatient::create(ct, {}, 0.0);
  ASSERT_FALSE(rejected.ok());
  EXPECT_NE(rejected.error().find("finite"), std::string::npos) << rejected.error();
}
