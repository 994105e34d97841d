// Two checks that guard every accuracy study (ENGINEERING.md §5b), on the small phantom with X-rays from the study's
// physical simulator (a continuous patient continued 60 mm beyond the CT, scatter haze, noise): registration started
// at the true pose stays there, and the same patient scanned on a grid shifted by half a voxel registers with the
// same error. Fast preset on 3 views of a 128 x 128 detector at 2.4 mm; each test prints its errors.
//
// Measured on 2026-12-01 (2-core Debian 12 development machine, shared; `fluoroct_logic_tests
// --gtest_also_run_disabled_tests --gtest_filter='CrimeFree*'`, docs/evaluation.md "Start at the truth"):
// - trilinear DRRs and a full-resolution stage on every 7 x 7 window: 0.097 mm on the CT's grid, 0.087 mm shifted
//   (the enabled test);
// - the default model (exact box-voxel DRRs, final stage on 6 % of the pixels): 0.637 mm and 0.561 mm, so
//   DISABLED_WithTheDefaultModel still fails;
// - DISABLED_FactorsOneAtATime prints every factor measured (6.5 min on the loaded machine).
// Every model here keeps the CT's own bone contrast (1): `fast` has no haze removal, whose hardening curve goes with
// the cases' default contrast of 1.6 (docs/registration.md, "Bone contrast"). With 1.6 the enabled test's model ends
// 0.121 mm (grid) and 0.134 mm (shifted) from the truth (2026-12-07).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "Evaluation/StudyRunner.h"
#include "Evaluation/StudyXraySource.h"
#include "Image/BoneSurface.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationCase.h"
#include "Simulation/FluoroscopySimulator.h"
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

/// The 3 standard views of the checks: 128 x 128 pixels of 2.4 mm.
std::vector<fct::ViewSpec> views() {
  fct::StandardViewOptions viewOptions;
  viewOptions.count = 3;
  viewOptions.cols = viewOptions.rows = 128;
  viewOptions.pixelSpacing_mm = 2.4;
  return fct::StandardViews::build(Eigen::Vector3d::Zero(), viewOptions).value();
}

/// A registration model: case options (DRR, preparation, cut-face margin) and edits of the fast preset's last stage.
struct Model {
  fct::RegistrationCaseOptions caseOptions;
  double finalFraction = 0.0;   ///< > 0: the last stage's ROI fraction
  int finalWindow = 0;          ///< > 0: the last stage's window size
  double finalTolerance = 0.0;  ///< > 0: the last stage's simplex tolerance (with 400 evaluations)
};

/// The default case model: cut-face margin 5 mm as in the studies (the simulated patient continues beyond the CT), with
/// the CT's own bone contrast (see the top of the file).
Model defaultModel() {
  Model model;
  model.caseOptions.cutFaceMargin_mm = 5.0;
  model.caseOptions.boneContrast = 1.0;
  return model;
}

/// The model that meets the check: trilinear DRRs and the full-resolution stage on every complete window.
Model trilinearFullFinalStage() {
  Model model = defaultModel();
  model.caseOptions.drr.method = fct::DrrMethod::RayCast;
  model.finalFraction = 1.0;
  return model;
}

/// Mean bone-surface error (mm) of a fast-preset registration with `model` on `registrationCt`, started at the truth.
double errorFromTruth(const fct::Volume& registrationCt, const std::vector<fct::RegistrationView>& xrays,
                      const Eigen::Isometry3d& T_truth, const Model& model, std::uint32_t seed = 5) {
  auto registrationCase = fct::RegistrationCase::create(registrationCt, xrays, model.caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  if (!registrationCase) return 1e9;
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin("fast").value();
  fct::RegistrationStage& last = options.schedule.stages.back();
  if (model.finalFraction > 0.0) last.pixels.targetFraction = model.finalFraction;
  if (model.finalWindow > 0) last.pixels.windowSize = model.finalWindow;
  if (model.finalTolerance > 0.0) {
    last.simplex.tolerance = model.finalTolerance;
    last.simplex.maxEvaluations = last.maxEvaluations = 400;
  }
  options.seed = seed;
  auto result = fct::Registration::run(registrationCase.value(), T_truth, options);
  EXPECT_TRUE(result.ok()) << result.error();
  if (!result) return 1e9;
  return registrationCase.value().bone()->meanDistance_mm(result.value().T_world_from_ct, T_truth);
}

/// Runs both checks with `model` on the studies' X-rays (noise seed 3) and expects them to hold.
void expectStartAtTruthStays(const Model& model) {
  const fct::Volume ct = phantom();
  const Eigen::Isometry3d T_truth = fct::StudyRunner::truthPose(fct::BoneSurface::extract(ct).value());
  auto xrays = fct::StudyXraySource::simulate(ct, views(), T_truth, 3, false);
  ASSERT_TRUE(xrays.ok()) << xrays.error();
  const double onGrid = errorFromTruth(ct, xrays.value(), T_truth, model);
  const double shifted = errorFromTruth(shiftedByHalfAVoxel(ct), xrays.value(), T_truth, model);
  std::printf("start at truth: error %.3f mm on the CT's grid, %.3f mm on the grid shifted by half a voxel\n", onGrid,
              shifted);
  EXPECT_LT(onGrid, 0.1);
  EXPECT_LT(shifted, 0.1);
  EXPECT_NEAR(onGrid, shifted, 0.05);
}

/// The studies' forward model with one setting changed by `edit` (noise seed `seed`).
std::vector<fct::RegistrationView> simulateWith(const fct::Volume& ct, const Eigen::Isometry3d& T_truth,
                                                const std::function<void(fct::FluoroscopyOptions&)>& edit,
                                                std::uint32_t seed) {
  fct::FluoroscopyOptions options = fct::StudyXraySource::forwardModel(false);
  edit(options);
  std::vector<fct::RegistrationView> out;
  for (const fct::ViewSpec& view : views()) {
    auto image = fct::FluoroscopySimulator::render(ct, view.camera, T_truth, options, seed + out.size());
    EXPECT_TRUE(image.ok()) << image.error();
    fct::XrayImage xray;
    xray.cols = image.value().cols;
    xray.rows = image.value().rows;
    xray.pixels = image.value().pixels;
    out.push_back(fct::RegistrationView{view.name, std::move(xray), view.camera, {}});
  }
  return out;
}

}  // namespace

TEST(CrimeFreeEvaluation, StartAtTruthStaysWithTrilinearDrrsAndTheFullFinalStage) {
  expectStartAtTruthStays(trilinearFullFinalStage());
}

TEST(CrimeFreeEvaluation, DISABLED_WithTheDefaultModel) { expectStartAtTruthStays(defaultModel()); }

// One factor at a time, 3 noise/registration seeds each, on the CT's grid and the shifted grid: first the forward
// model's effects (registration model: default and trilinear), then the registration model's choices on the studies'
// X-rays. Prints mean and max errors in mm; asserts only that every registration ran.
TEST(CrimeFreeEvaluation, DISABLED_FactorsOneAtATime) {
  const fct::Volume ct = phantom();
  const fct::Volume shifted = shiftedByHalfAVoxel(ct);
  const Eigen::Isometry3d T_truth = fct::StudyRunner::truthPose(fct::BoneSurface::extract(ct).value());
  using Edit = std::function<void(fct::FluoroscopyOptions&)>;
  const auto measure = [&](const std::string& name, const Edit& edit, const Model& model) {
    double sum[2] = {0.0, 0.0};
    double largest[2] = {0.0, 0.0};
    for (std::uint32_t s = 0; s < 3; ++s) {
      const auto xrays = simulateWith(ct, T_truth, edit, 3 + 10 * s);
      for (int g = 0; g < 2; ++g) {
        const double e = errorFromTruth(g == 0 ? ct : shifted, xrays, T_truth, model, 5 + s);
        EXPECT_LT(e, 1e8);
        sum[g] += e;
        largest[g] = std::max(largest[g], e);
      }
    }
    std::printf("%-44s grid mean %.3f max %.3f | shifted mean %.3f max %.3f\n", name.c_str(), sum[0] / 3, largest[0],
                sum[1] / 3, largest[1]);
    std::fflush(stdout);
  };
  const std::vector<std::pair<std::string, Edit>> forward = {
      {"studies' forward model", [](fct::FluoroscopyOptions&) {}},
      {"no scatter haze", [](fct::FluoroscopyOptions& o) { o.scatterToPrimary = 0.0; }},
      {"no noise", [](fct::FluoroscopyOptions& o) { o.photonsPerPixel = 0.0; }},
      {"no PSF", [](fct::FluoroscopyOptions& o) { o.psfSigma_px = 0.0; }},
      {"no vignetting", [](fct::FluoroscopyOptions& o) { o.vignetting = 0.0; }},
      {"no patient extension", [](fct::FluoroscopyOptions& o) { o.patientExtension_mm = 0.0; }},
      {"monochromatic 60 keV", [](fct::FluoroscopyOptions& o) { o.monochromatic_keV = 60.0; }},
  };
  Model trilinear = defaultModel();
  trilinear.caseOptions.drr.method = fct::DrrMethod::RayCast;
  for (const auto& [name, edit] : forward) {
    measure(name + ", box DRR", edit, defaultModel());
    measure(name + ", trilinear DRR", edit, trilinear);
  }
  const Edit studies = [](fct::FluoroscopyOptions&) {};
  std::vector<std::pair<std::string, Model>> models;
  const auto variant = [&](const std::string& name, const Model& base, const std::function<void(Model&)>& change) {
    Model model = base;
    change(model);
    models.emplace_back(name, model);
  };
  variant("trilinear, step 1/4 voxel", trilinear, [](Model& m) { m.caseOptions.drr.rayCastStep_mm = 0.625; });
  variant("trilinear, cut-face margin 0 mm", trilinear, [](Model& m) { m.caseOptions.cutFaceMargin_mm = 0.0; });
  variant("trilinear, cut-face margin 10 mm", trilinear, [](Model& m) { m.caseOptions.cutFaceMargin_mm = 10.0; });
  variant("trilinear, no cut-face mask", trilinear, [](Model& m) { m.caseOptions.cutFaceMargin_mm = -1.0; });
  variant("trilinear, I0 at the 99.9th percentile", trilinear,
          [](Model& m) { m.caseOptions.preparation.intensity.referencePercentile = 99.9; });
  variant("trilinear, I0 at the 98th percentile", trilinear,
          [](Model& m) { m.caseOptions.preparation.intensity.referencePercentile = 98.0; });
  variant("trilinear, no metal mask", trilinear, [](Model& m) { m.caseOptions.preparation.excludeMetal = false; });
  for (const double contrast : {1.3, 1.6}) {
    variant(fmt::format("trilinear, bone contrast {:g}", contrast), trilinear,
            [contrast](Model& m) { m.caseOptions.boneContrast = contrast; });
  }
  for (const double fraction : {0.12, 0.25, 0.5, 1.0}) {
    variant(fmt::format("box, final stage {:g} of the pixels", fraction), defaultModel(),
            [fraction](Model& m) { m.finalFraction = fraction; });
    variant(fmt::format("trilinear, final stage {:g} of the pixels", fraction), trilinear,
            [fraction](Model& m) { m.finalFraction = fraction; });
  }
  for (const int window : {5, 11}) {
    variant(fmt::format("trilinear, final window {}", window), trilinear, [window](Model& m) { m.finalWindow = window; });
  }
  variant("trilinear, final stage 0.5, window 5", trilinear, [](Model& m) {
    m.finalFraction = 0.5;
    m.finalWindow = 5;
  });
  variant("box, final simplex tolerance 0.01", defaultModel(), [](Model& m) { m.finalTolerance = 0.01; });
  variant("trilinear, final simplex tolerance 0.01", trilinear, [](Model& m) { m.finalTolerance = 0.01; });
  for (const auto& [name, model] : models) measure(name, studies, model);
}
