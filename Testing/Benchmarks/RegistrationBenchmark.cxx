// Registration benchmark: time, DRR count per stage and accuracy of 3-view registrations with the `fast` and `paper`
// presets, each with exact (Siddon) DRRs and with per-view Transgraph tables, on the built-in phantom, the clinical
// pelvis CT and the head phantom CT (when present), against a plain baseline measured in the same run: NCC on
// full-resolution whole images, exact Siddon DRRs, downhill simplex only (no ROIs, no pyramid, no Transgraph, no
// global search). Known-truth cases are simulated in-process (RegistrationTestCase.h); every run starts at 10 mm mean
// bone-surface distance from the truth. The Transgraph tables of a case are built once (no disk cache), around the
// first start pose, and their build time is reported apart from the registrations.
//
// Usage: fluoroct_registration_benchmark [--no-baseline] [--no-transgraph] [--detector PIXELS PIXEL_MM] [STARTS]
//                                        [phantom|pelvis|head|all] [PRESET ...]
//   defaults: 2 starts, all cases, presets "fast" and "paper" (a PRESET may be a preset JSON file)
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "IO/Volume/CtLoader.h"
#include "Registration/Registration.h"
#include "RegistrationTestCase.h"
#include "Simulation/PhantomBuilder.h"

namespace {

struct Summary {
  std::string label;
  std::vector<double> seconds;
  std::vector<double> error_mm;
  std::vector<double> drrs;
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
  stage.simplex.initialStep = 3.0;
  stage.simplex.tolerance = 0.02;
  stage.simplex.maxEvaluations = 3000;
  stage.simplex.restarts = 1;
  schedule.stages.push_back(stage);
  return schedule;
}

struct Flags {
  bool baseline = true;
  bool transgraph = true;
  int starts = 2;
  fct::test::KnownTruthOptions detector;
  std::vector<std::string> presets;
};

int runCase(const std::string& caseName, fct::Volume ct, const Flags& flags) {
  auto simulated = fct::test::simulateCase(std::move(ct), flags.detector);
  if (!simulated) {
    fmt::print(stderr, "{}: {}\n", caseName, simulated.error());
    return 1;
  }
  const auto& sim = simulated.value();
  auto exactCase = fct::RegistrationCase::create(sim.ct, sim.views);
  if (!exactCase) {
    fmt::print(stderr, "{}: {}\n", caseName, exactCase.error());
    return 1;
  }
  const auto& bone = *exactCase.value().bone();
  std::vector<Eigen::Isometry3d> starts;
  for (int s = 0; s < flags.starts; ++s) starts.push_back(fct::test::startPose(exactCase.value(), sim.T_truth, 10.0, 100 + s));
  fmt::print("\n== {}: CT {}x{}x{} at {:.2f} mm, 3 views {}x{} at {} mm, bone radius {:.1f} mm, {} starts at 10 mm\n",
             caseName, sim.ct.dims().x(), sim.ct.dims().y(), sim.ct.dims().z(), sim.ct.spacing_mm().x(),
             sim.views[0].xray.cols, sim.views[0].xray.rows, flags.detector.pixelSpacing_mm,
             exactCase.value().boneRadius_mm(), flags.starts);

  // The Transgraph case: one table per view around the first start pose, built here (no cache), timed.
  std::optional<fct::RegistrationCase> transgraphCase;
  if (flags.transgraph) {
    fct::RegistrationCaseOptions options;
    options.drr.method = fct::DrrMethod::Transgraph;
    options.drr.transgraphCacheFolder = std::nullopt;
    options.T_expected_world_from_ct = starts.front();
    auto created = fct::RegistrationCase::create(sim.ct, sim.views, options);
    if (!created) {
      fmt::print(stderr, "{}: transgraph: {}\n", caseName, created.error());
      return 1;
    }
    transgraphCase = std::move(created).value();
    std::vector<std::string> tables;
    for (std::size_t v = 0; v < transgraphCase->viewCount(); ++v) {
      const auto& t = transgraphCase->transgraph(v)->transgraph();
      tables.push_back(fmt::format("{} {:.1f} M rays {:.1f} s", transgraphCase->viewName(v), t.rayCount() / 1e6,
                                   t.buildInfo().build_s));
    }
    fmt::print("  transgraph tables built in {:.2f} s ({})\n", transgraphCase->viewRendererSetupSeconds(),
               fmt::join(tables, ", "));
  }

  struct Config {
    std::string label;
    fct::RegistrationSchedule schedule;
    fct::RegistrationCase* registrationCase;
  };
  std::vector<Config> configs;
  for (const std::string& preset : flags.presets) {
    auto schedule = fct::RegistrationSchedule::resolve(preset);
    if (!schedule) {
      fmt::print(stderr, "{}\n", schedule.error());
      return 1;
    }
    configs.push_back({schedule.value().name + " siddon", schedule.value(), &exactCase.value()});
    if (transgraphCase) configs.push_back({schedule.value().name + " transgraph", schedule.value(), &*transgraphCase});
  }
  if (flags.baseline) configs.push_back({"baseline", baselineSchedule(), &exactCase.value()});
  std::vector<Summary> summaries;
  for (const Config& config : configs) {
    Summary summary{config.label, {}, {}, {}};
    for (int s = 0; s < flags.starts; ++s) {
      fct::RegistrationOptions options;
      options.schedule = config.schedule;
      options.seed = 1 + s;
      auto result = fct::Registration::run(*config.registrationCase, starts[static_cast<std::size_t>(s)], options);
      if (!result) {
        fmt::print("  {} start {}: error: {}\n", config.label, s, result.error());
        continue;
      }
      const auto& r = result.value();
      const double error = bone.meanDistance_mm(r.T_world_from_ct, sim.T_truth);
      std::vector<std::string> perStage;
      long fallbackRays = 0;
      for (std::size_t i = 0; i < r.stages.size(); ++i) {
        const auto& stage = r.stages[i];
        const bool exact = r.drrMethod == "transgraph" && r.schedule.stages[i].exactDrr;
        perStage.push_back(fmt::format("{}{} {} DRRs {:.2f} s", stage.name, exact ? " (exact)" : "", stage.drrs,
                                       stage.seconds));
        fallbackRays += stage.fallbackRays;
      }
      fmt::print("  {:<17} start {}: {:7.2f} s, {:6} DRRs, error {:6.3f} mm{}  [{}]\n", config.label, s,
                 r.totalSeconds, r.totalDrrs, error,
                 fallbackRays ? fmt::format(", {} rays outside the tables", fallbackRays) : "", fmt::join(perStage, "; "));
      std::fflush(stdout);
      summary.seconds.push_back(r.totalSeconds);
      summary.error_mm.push_back(error);
      summary.drrs.push_back(static_cast<double>(r.totalDrrs));
    }
    summaries.push_back(summary);
  }
  const double baselineTime = flags.baseline ? median(summaries.back().seconds) : 0.0;
  fmt::print("  -- summary ({}):\n", caseName);
  for (const Summary& s : summaries) {
    const long within = std::count_if(s.error_mm.begin(), s.error_mm.end(), [](double e) { return e < 0.5; });
    fmt::print("  {:<17} median {:7.2f} s, median {:7.0f} DRRs, median error {:6.3f} mm, {}/{} within 0.5 mm{}\n",
               s.label, median(s.seconds), median(s.drrs), median(s.error_mm), within, s.error_mm.size(),
               flags.baseline ? fmt::format(", baseline/this time ratio {:5.1f}x",
                                            baselineTime / std::max(1e-9, median(s.seconds)))
                              : "");
  }
  if (transgraphCase) {
    // What a table buys per registration, and after how many registrations its build has paid for itself.
    for (std::size_t i = 0; i + 1 < summaries.size(); i += 2) {
      if (summaries[i + 1].label.find("transgraph") == std::string::npos) continue;
      const double saving = median(summaries[i].seconds) - median(summaries[i + 1].seconds);
      fmt::print("  transgraph {}: saves {:.2f} s per registration; tables built in {:.2f} s{}\n",
                 summaries[i].label.substr(0, summaries[i].label.find(' ')), saving,
                 transgraphCase->viewRendererSetupSeconds(),
                 saving > 0 ? fmt::format(" (paid back after {:.1f} registrations)",
                                          transgraphCase->viewRendererSetupSeconds() / saving)
                            : " (no saving)");
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Flags flags;
  std::vector<std::string> args(argv + 1, argv + argc);
  std::vector<std::string> positional;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--no-baseline") {
      flags.baseline = false;
    } else if (args[i] == "--no-transgraph") {
      flags.transgraph = false;
    } else if (args[i] == "--detector" && i + 2 < args.size()) {
      flags.detector.cols = flags.detector.rows = std::atoi(args[i + 1].c_str());
      flags.detector.pixelSpacing_mm = std::atof(args[i + 2].c_str());
      i += 2;
    } else {
      positional.push_back(args[i]);
    }
  }
  if (!positional.empty()) flags.starts = std::max(1, std::atoi(positional[0].c_str()));
  const std::string which = positional.size() > 1 ? positional[1] : "all";
  if (positional.size() > 2) flags.presets.assign(positional.begin() + 2, positional.end());
  if (flags.presets.empty()) flags.presets = {"fast", "paper"};
  fmt::print("registration benchmark: {} starts per configuration, presets {}, baseline {}, transgraph {}\n",
             flags.starts, fmt::join(flags.presets, ", "), flags.baseline ? "on" : "off",
             flags.transgraph ? "on" : "off");

  const char* env = std::getenv("FLUOROCT_DATA_DIR");
  const std::filesystem::path data = env ? env : FCT_DEFAULT_DATA_DIR;
  int status = 0;
  if (which == "all" || which == "phantom") {
    fct::PhantomOptions phantom;
    phantom.dims = Eigen::Vector3i(80, 80, 60);
    phantom.spacing_mm = 2.0;
    status |= runCase("phantom", fct::PhantomBuilder::build(phantom).value(), flags);
  }
  const std::vector<std::pair<std::string, std::string>> realCases{{"pelvis", "ct/pelvis_totalseg.nii.gz"},
                                                                   {"head", "ct/head_phantom_philips_bone"}};
  for (const auto& [name, path] : realCases) {
    if (which != "all" && which != name) continue;
    auto ct = fct::CtLoader::load(data / path);
    if (ct) {
      status |= runCase(name, std::move(ct).value(), flags);
    } else {
      fmt::print("{} skipped: {}\n", name, ct.error());
    }
  }
  return status;
}
