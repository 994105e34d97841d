// fluoroct evaluate: runs one of the paper's studies (StudyCatalog) with simulated X-rays of known truth, writes every
// trial to DIR/trials.csv (resumable), then DIR/report.md and PNG charts (StudyReport).
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "CliSupport.h"
#include "CtLoader.h"
#include "PhantomBuilder.h"
#include "StudyCatalog.h"
#include "StudyReport.h"
#include "StudyRunner.h"
#include "TrialStore.h"

namespace fct::cli {

namespace {

namespace fs = std::filesystem;

struct EvaluateOptions {
  std::string study;
  std::string out;
  bool quick = false;
  int jobs = 1;
  int trials = 0;  ///< > 0: at most this many trials per condition
  std::vector<std::string> cts;
};

std::atomic<bool> g_cancel{false};
extern "C" void onEvaluateInterrupt(int) { g_cancel.store(true); }

/// The shared data folder: $FLUOROCT_DATA_DIR, else ../shared/data from the working folder.
fs::path dataDir() {
  const char* env = std::getenv("FLUOROCT_DATA_DIR");
  return env && *env ? fs::path(env) : fs::path("../shared/data");
}

/// A label for a CT path: its file or folder name without image extensions, unique among `taken`.
std::string labelFor(const fs::path& path, const std::vector<StudyCt>& taken) {
  std::string name = path.filename().string();
  if (name.empty()) name = path.parent_path().filename().string();
  for (const char* ext : {".nii.gz", ".nii", ".nrrd", ".nhdr", ".mha", ".mhd"}) {
    const std::string e(ext);
    if (name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0) {
      name.resize(name.size() - e.size());
      break;
    }
  }
  std::string label = name;
  for (int n = 2; std::any_of(taken.begin(), taken.end(), [&](const StudyCt& c) { return c.label == label; }); ++n) {
    label = fmt::format("{}-{}", name, n);
  }
  return label;
}

/// The CTs of the run: --ct paths; else the phantom (--quick); else the shared data's (pelvis, and the head phantom
/// for table2). An empty list with no error means "skip": the shared data is missing.
Result<std::vector<StudyCt>> loadCts(const EvaluateOptions& o, bool& skip) {
  std::vector<StudyCt> cts;
  std::vector<std::pair<std::string, fs::path>> paths;
  for (const std::string& p : o.cts) paths.emplace_back("", p);
  if (paths.empty() && o.quick) {
    PhantomOptions phantom;
    phantom.dims = Eigen::Vector3i(80, 80, 60);
    phantom.spacing_mm = 2.0;
    auto volume = PhantomBuilder::build(phantom);
    if (!volume) return fail(volume.error());
    cts.push_back(StudyCt{"phantom", std::move(volume).value()});
    return cts;
  }
  if (paths.empty()) {
    const fs::path data = dataDir();
    paths.emplace_back("pelvis", data / "ct/pelvis_totalseg.nii.gz");
    if (o.study == "table2") paths.emplace_back("head", data / "ct/head_phantom_philips_bone");
    for (const auto& [label, path] : paths) {
      if (!fs::exists(path)) {
        fmt::print(stderr, "evaluate: skipped: the full '{}' study needs {}, which does not exist (set "
                           "FLUOROCT_DATA_DIR to the shared data folder, give --ct PATH, or run --quick)\n",
                   o.study, path.string());
        skip = true;
        return cts;
      }
    }
  }
  for (const auto& [label, path] : paths) {
    fmt::print(stderr, "evaluate: loading CT {}\n", path.string());
    auto volume = CtLoader::load(path);
    if (!volume) return fail(fmt::format("--ct {}: {}", path.string(), volume.error()));
    for (const std::string& warning : volume.warnings()) fmt::print(stderr, "warning: {}\n", warning);
    cts.push_back(StudyCt{label.empty() ? labelFor(path, cts) : label, std::move(volume).value()});
  }
  return cts;
}

/// Creates `out` and checks that a file can be written in it.
Status prepareOutput(const fs::path& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out)) {
    return fail(fmt::format("cannot create the output folder '{}': {}; choose a writable --out", out.string(),
                            ec ? ec.message() : "not a folder"));
  }
  const fs::path probe = out / ".fluoroct-write-test";
  const bool writable = static_cast<bool>(std::ofstream(probe) << "test");
  fs::remove(probe, ec);
  if (!writable) return fail(fmt::format("cannot write in the output folder '{}'; choose a writable --out", out.string()));
  return Ok{};
}

int runEvaluate(const EvaluateOptions& o) {
  // The study name is checked before anything is loaded (the CT labels are placeholders here).
  if (auto known = StudyCatalog::define(o.study, o.quick, {"ct"}); !known) return reportError(known.error());
  if (o.jobs < 1) return reportError(fmt::format("--jobs must be at least 1, got {}", o.jobs));
  if (o.trials < 0) return reportError(fmt::format("--trials must be positive, got {}", o.trials));
  if (Status ready = prepareOutput(o.out); !ready) return reportError(ready.error());
  auto store = TrialStore::open(fs::path(o.out) / "trials.csv");
  if (!store) return reportError(store.error());

  bool skip = false;
  auto cts = loadCts(o, skip);
  if (!cts) return reportError(cts.error());
  if (skip) return 0;
  std::vector<std::string> labels;
  for (const StudyCt& ct : cts.value()) labels.push_back(ct.label);
  auto study = StudyCatalog::define(o.study, o.quick, labels);
  if (!study) return reportError(study.error());
  std::size_t total = 0;
  for (StudyCondition& c : study.value().conditions) {
    if (o.trials > 0) c.trials = std::min(c.trials, o.trials);
    total += static_cast<std::size_t>(c.trials);
  }
  fmt::print(stderr, "evaluate: study '{}'{} on {}: {} conditions, {} trials, {} job(s)\n", o.study,
             o.quick ? " (quick)" : "", fmt::join(labels, ", "), study.value().conditions.size(), total, o.jobs);

  StudyRunOptions run;
  run.jobs = o.jobs;
  run.cancel = &g_cancel;
  run.onMessage = [](const std::string& text) { fmt::print(stderr, "evaluate: {}\n", text); };
  run.onTrial = [](const StudyProgress& p) {
    const TrialRecord& r = p.record;
    fmt::print(stderr, "[{}/{}] {} trial {}: initial sTRE {:.2f} mm -> {:.3f} mm (max {:.3f}) {}{} {:.1f} s, {} DRRs\n",
               p.finished, p.toRun, r.condition, r.trial, r.initialStre_mm, r.error.streMean_mm, r.error.streMax_mm,
               r.status == "ok" ? (r.success ? "success" : "FAILURE") : r.status,
               r.reason.empty() ? "" : " (" + r.reason + ")", r.seconds, r.drrs);
  };
  g_cancel = false;
  const auto previousHandler = std::signal(SIGINT, onEvaluateInterrupt);
  auto summary = StudyRunner::run(study.value(), cts.value(), store.value(), run);
  std::signal(SIGINT, previousHandler);
  if (!summary) return reportError(summary.error());

  std::vector<std::string> notes = StudyRunner::notes(study.value(), cts.value());
  notes.insert(notes.begin(), fmt::format("command: `fluoroct evaluate --study {}{} --out {}{}{}`", o.study,
                                          o.quick ? " --quick" : "", o.out,
                                          o.trials > 0 ? fmt::format(" --trials {}", o.trials) : "",
                                          o.cts.empty() ? "" : fmt::format(" --ct {}", fmt::join(o.cts, " "))));
  auto written = StudyReport::write(study.value(), store.value().records(), notes, o.out);
  if (!written) return reportError(written.error());
  std::vector<std::string> names;
  for (const fs::path& path : written.value()) names.push_back(path.filename().string());
  fmt::print("{}: ran {} trials ({} failed), skipped {} already done; wrote {} and {}\n", o.study, summary.value().ran,
             summary.value().failed, summary.value().skipped, store.value().path().string(), fmt::join(names, ", "));
  if (summary.value().cancelled) {
    return reportError("cancelled; the finished trials are saved: re-run the same command to resume");
  }
  return 0;
}

}  // namespace

void registerEvaluateCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<EvaluateOptions>();
  CLI::App* command = app.add_subcommand(
      "evaluate", "Run an evaluation study (table2, capture, ablation, views) on simulated X-rays of known truth; "
                  "writes DIR/trials.csv (resumable), DIR/report.md and PNG charts");
  command->add_option("--study", options->study, "Study: table2, capture, ablation or views")->required();
  command->add_option("--out", options->out, "Output folder (re-running with the same folder resumes)")->required();
  command->add_flag("--quick", options->quick,
                    "Small version on the built-in phantom (fast preset, 128x128 detector, 2 trials per condition)");
  command->add_option("--jobs", options->jobs, "Trials run in parallel")->capture_default_str();
  command->add_option("--trials", options->trials,
                      "At most this many trials per condition (a sample of a study; the first N of each condition)");
  command->add_option("--ct", options->cts,
                      "CT volume(s) or DICOM folder(s) instead of the defaults (full: ../shared/data pelvis, plus the "
                      "head phantom for table2; quick: the phantom)");
  command->callback([&action, options] { action = [options] { return runEvaluate(*options); }; });
}

}  // namespace fct::cli
