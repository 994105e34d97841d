// Registration benchmark: time, DRR count per stage and accuracy of 3-view registrations with the `fast` and `paper`
// presets on the built-in phantom and the clinical pelvis CT (if present), against a plain baseline measured in the
// same run: NCC on full-resolution whole images, trilinear ray casting, downhill simplex only (no ROIs, no pyramid,
// no global search). Known-truth cases are simulated in-process (RegistrationTestCase.h); every run starts at 10 mm
// mean bone-surface distance from the truth.
//
// Usage: fluoroct_registration_benchmark [--no-baseline] [--detector PIXELS PIXEL_MM] [STARTS] [phantom|pelvis|all]
//                                        [PRESET ...]
//   defaults: 3 starts, all cases, presets "fast" and "paper" (a PRESET may be a preset JSON file)
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "PhantomBuilder.h"
#include "Registration.h"
#include "RegistrationTestCase.h"
#include "VolumeFileIO.h"

namespace {

struct Summary {
  std::string label;
  std::vector<double> seconds;
  std::vector<double> error_mm;
  std::vector<long> drrs;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

fct::RegistrationSchedule baselineSchedule() {
  fct::RegistrationSchedule schedule;
  schedule.name = "baseline";
  fct::RegistrationStage stage;
  stage.name = "ncc-whole-1:1-simplex";
  stage.metric = fct::SimilarityMetric::Ncc;
  stage.level = 0;
  stage.pixels.kind = fct::PixelSetKind::WholeImage;
  stage.search = fct::SearchStrategy::Local;
  stage.maxEvaluations = 3000;
  stage.simplex = {3.0, 0.02, 3000, 1};
  schedule.stages.push_back(stage);
  return schedule;
}

int runCase(const std::string& caseName, fct::Volume ct, int starts, const std::vector<std::string>& presets,
            bool withBaseline, const fct::test::KnownTruthOptions& detector) {
  auto simulated = fct::test::simulateCase(std::move(ct), detector);
  if (!simulated) {
    fmt::print(stderr, "{}: {}\n", caseName, simulated.error());
    return 1;
  }
  const auto& sim = simulated.value();
  // The simulated X-rays have no collimator: no field-of-view detection (it would take the pelvis's darkest band at
  // the border of the lateral view for background).
  fct::RegistrationCaseOptions siddon;
  siddon.preparation.detectFieldOfView = false;
  fct::RegistrationCaseOptions raycast = siddon;
  raycast.drr.method = fct::DrrMethod::RayCast;
  auto fastCase = fct::RegistrationCase::create(sim.ct, sim.views, siddon);
  auto baseCase = fct::RegistrationCase::create(sim.ct, sim.views, raycast);
  if (!fastCase || !baseCase) {
    fmt::print(stderr, "{}: {}{}\n", caseName, fastCase.error(), baseCase.error());
    return 1;
  }
  const auto& bone = *fastCase.value().bone();
  fmt::print("\n== {}: CT {}x{}x{} at {:.2f} mm, 3 views {}x{}, bone radius {:.1f} mm, {} starts at 10 mm\n", caseName,
             sim.ct.dims().x(), sim.ct.dims().y(), sim.ct.dims().z(), sim.ct.spacing_mm().x(), sim.views[0].xray.cols,
             sim.views[0].xray.rows, fastCase.value().boneRadius_mm(), starts);

  struct Config {
    std::string label;
    fct::RegistrationSchedule schedule;
    fct::RegistrationCase* registrationCase;
  };
  std::vector<Config> configs;
  for (const std::string& preset : presets) {
    auto schedule = fct::RegistrationSchedule::resolve(preset);
    if (!schedule) {
      fmt::print(stderr, "{}\n", schedule.error());
      return 1;
    }
    configs.push_back({schedule.value().name + " (siddon)", schedule.value(), &fastCase.value()});
  }
  if (withBaseline) configs.push_back({"baseline", baselineSchedule(), &baseCase.value()});
  std::vector<Summary> summaries;
  for (const Config& config : configs) {
    Summary summary{config.label, {}, {}, {}};
    for (int s = 0; s < starts; ++s) {
      const Eigen::Isometry3d start = fct::test::startPose(*config.registrationCase, sim.T_truth, 10.0, 100 + s);
      fct::RegistrationOptions options;
      options.schedule = config.schedule;
      options.seed = 1 + s;
      auto result = fct::Registration::run(*config.registrationCase, start, options);
      if (!result) {
        fmt::print("  {} start {}: error: {}\n", config.label, s, result.error());
        continue;
      }
      const auto& r = result.value();
      const double error = bone.meanDistance_mm(r.T_world_from_ct, sim.T_truth);
      std::vector<std::string> perStage;
      for (const auto& stage : r.stages) {
        perStage.push_back(fmt::format("{} {} DRRs {:.2f} s sim {:.4f}", stage.name, stage.drrs, stage.seconds,
                                       stage.similarity));
      }
      fmt::print("  {:<15} start {:2}: {:6.2f} s, {:6} DRRs, error {:6.3f} mm  [{}]\n", config.label, s, r.totalSeconds,
                 r.totalDrrs, error, fmt::join(perStage, "; "));
      std::fflush(stdout);
      summary.seconds.push_back(r.totalSeconds);
      summary.error_mm.push_back(error);
      summary.drrs.push_back(r.totalDrrs);
    }
    summaries.push_back(summary);
  }
  const double baselineTime = withBaseline ? median(summaries.back().seconds) : 0.0;
  fmt::print("  -- summary ({}):\n", caseName);
  for (const Summary& s : summaries) {
    const long within = std::count_if(s.error_mm.begin(), s.error_mm.end(), [](double e) { return e < 0.5; });
    const double drrMedian = median(std::vector<double>(s.drrs.begin(), s.drrs.end()));
    fmt::print("  {:<15} median {:6.2f} s, median {:7.0f} DRRs, median error {:6.3f} mm, {}/{} within 0.5 mm, "
               "baseline/this time ratio {:5.1f}x\n",
               s.label, median(s.seconds), drrMedian, median(s.error_mm), within, s.error_mm.size(),
               baselineTime / std::max(1e-9, median(s.seconds)));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const bool withBaseline = !(argc > 1 && std::string(argv[1]) == "--no-baseline");
  if (!withBaseline) {
    --argc;
    ++argv;
  }
  fct::test::KnownTruthOptions detector;
  if (argc > 3 && std::string(argv[1]) == "--detector") {
    detector.cols = detector.rows = std::atoi(argv[2]);
    detector.pixelSpacing_mm = std::atof(argv[3]);
    argc -= 3;
    argv += 3;
  }
  const int starts = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  const std::string which = argc > 2 ? argv[2] : "all";
  std::vector<std::string> presets(argv + std::min(argc, 3), argv + argc);
  if (presets.empty()) presets = {"fast", "paper"};
  int status = 0;
  if (which == "all" || which == "phantom") {
    fct::PhantomOptions phantom;
    phantom.dims = Eigen::Vector3i(80, 80, 60);
    phantom.spacing_mm = 2.0;
    status |= runCase("phantom", fct::PhantomBuilder::build(phantom).value(), starts, presets, withBaseline, detector);
  }
  if (which == "all" || which == "pelvis") {
    const char* env = std::getenv("FLUOROCT_DATA_DIR");
    const std::filesystem::path data = env ? env : FCT_DEFAULT_DATA_DIR;
    auto pelvis = fct::VolumeFileIO::read(data / "ct/pelvis_totalseg.nii.gz");
    if (pelvis) {
      status |= runCase("pelvis", std::move(pelvis).value(), starts, presets, withBaseline, detector);
    } else {
      fmt::print("pelvis skipped: {}\n", pelvis.error());
    }
  }
  return status;
}
