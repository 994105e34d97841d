// Two checks that guard every accuracy study (ENGINEERING.md §5b), on the small phantom with X-rays from the study's
// physical simulator (a continuous patient, scatter, noise): registration started at the true pose stays there, and
// the same patient scanned on a grid shifted by half a voxel registers with the same error. Fast preset, 96 x 96
// detector; prints the errors (about 3 s).
//
// DISABLED: both checks fail today. Measured on 2026-12-01 (2-core Debian 12 development machine, `fluoroct_logic_tests
// --gtest_also_run_disabled_tests --gtest_filter='CrimeFree*'`): 0.637 mm on the CT's grid, 0.561 mm on the grid
// shifted by half a voxel. The optimum of the registration itself is biased on crime-free images (docs/evaluation.md,
// "Start at the truth"); enable this test when that bias is removed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "Evaluation/StudyRunner.h"
#include "Evaluation/StudyXraySource.h"
#include "Image/BoneSurface.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationCase.h"
#include "Simulation/PhantomBuilder.h"
#include "Simulation/Physics/CubicBsplinePatient.h"
#include "Simulation/StandardViews.h"

namespace {

/// The phantom: 64 x 64 x 48 voxels of 2.5 mm.
fct::Volume phantom() {
  fct::PhantomOptions options;
  options.dims = Eigen::Vector3i(64, 64, 48);
  options.spacing_mm = 2.5;
  return fct::PhantomBuilder::build(options).value();
}

/// The same patient sampled (its cubic B-spline interpolant) on a grid shifted by half a voxel along i, j and k.
fct::Volume shiftedByHalfAVoxel(const fct::Volume& ct) {
  const Eigen::Vector3d shift_mm = ct.direction_lps() * (0.5 * ct.spacing_mm());
  fct::Volume shifted = fct::Volume::create(ct.dims() - Eigen::Vector3i::Ones(), ct.spacing_mm(),
                                            ct.origin_lps_mm() + shift_mm, ct.direction_lps())
                            .value();
  const fct::CubicBsplinePatient patient = fct::CubicBsplinePatient::create(ct, {}, 0.0).value();
  for (int k = 0; k < shifted.dims().z(); ++k)
    for (int j = 0; j < shifted.dims().y(); ++j)
      for (int i = 0; i < shifted.dims().x(); ++i) {
        shifted.at(i, j, k) = static_cast<float>(patient.value_hu(shifted.lpsFromIjk(Eigen::Vector3d(i, j, k))));
      }
  return shifted;
}

/// Mean bone-surface error (mm) of a fast-preset registration on `registrationCt`, started at the truth.
double errorFromTruth(const fct::Volume& registrationCt, const std::vector<fct::RegistrationView>& views,
                      const Eigen::Isometry3d& T_truth) {
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.cutFaceMargin_mm = 5.0;  // as the studies: the simulated patient continues beyond the CT's end faces
  auto registrationCase = fct::RegistrationCase::create(registrationCt, views, caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  if (!registrationCase) return 1e9;
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin("fast").value();
  options.seed = 5;
  auto result = fct::Registration::run(registrationCase.value(), T_truth, options);
  EXPECT_TRUE(result.ok()) << result.error();
  if (!result) return 1e9;
  return registrationCase.value().bone()->meanDistance_mm(result.value().T_world_from_ct, T_truth);
}

}  // namespace

TEST(CrimeFreeEvaluation, DISABLED_StartAtTruthStaysAndAHalfVoxelShiftChangesNothing) {
  const fct::Volume ct = phantom();
  const Eigen::Isometry3d T_truth = fct::StudyRunner::truthPose(fct::BoneSurface::extract(ct).value());
  fct::StandardViewOptions viewOptions;
  viewOptions.count = 3;
  viewOptions.cols = viewOptions.rows = 128;
  viewOptions.pixelSpacing_mm = 2.4;
  auto views = fct::StandardViews::build(Eigen::Vector3d::Zero(), viewOptions);
  ASSERT_TRUE(views.ok()) << views.error();
  auto xrays = fct::StudyXraySource::simulate(ct, views.value(), T_truth, 3, false);
  ASSERT_TRUE(xrays.ok()) << xrays.error();

  const double onGrid = errorFromTruth(ct, xrays.value(), T_truth);
  const double shifted = errorFromTruth(shiftedByHalfAVoxel(ct), xrays.value(), T_truth);
  std::printf("start at truth: error %.3f mm on the CT's grid, %.3f mm on the grid shifted by half a voxel\n", onGrid,
              shifted);
  EXPECT_LT(onGrid, 0.1);
  EXPECT_LT(shifted, 0.1);
  EXPECT_NEAR(onGrid, shifted, 0.05);
}
