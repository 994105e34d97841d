// fluoroct evaluate: runs one of the paper's studies (StudyCatalog) with simulated X-rays of known truth, writes every
// trial to DIR/trials.csv (resumable), then DIR/report.md and PNG charts (StudyReport). The options that change results
// (study, CTs, preset, detector, DRR method, ...) are kept in DIR/setup.txt (StudySetupFile); resuming with other
// options is refused. --shard K/N runs only shard K of N (StudyShard) into its own folder; --merge DIR... gathers the
// shard folders into one trials.csv, report and charts in --out, as one unsharded run would write them (StudyMerge).
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "CliSupport.h"
#include "Drr/DrrRendererFactory.h"
#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyMerge.h"
#include "Evaluation/StudyReport.h"
#include "Evaluation/StudyRunner.h"
#include "Evaluation/StudySetupFile.h"
#include "Evaluation/StudyShard.h"
#include "Evaluation/StudyTrialCase.h"
#include "Evaluation/TrackingFrameStore.h"
#include "Evaluation/TrackingReport.h"
#include "Evaluation/TrackingStudy.h"
#include "Evaluation/TrialStore.h"
#include "IO/Volume/CtLoader.h"
#include "Registration/RegistrationSchedule.h"
#include "Simulation/PhantomBuilder.h"

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
  std::string preset;    ///< empty: the study's (clinical; quick: fast)
  std::string detector;  ///< COLSxROWS; empty: the study's
  double pixel_mm = 0.0; ///< > 0: detector pixel size
  std::string method = "siddon";
  bool oneXraySet = false;  ///< every trial of a CT registers against one X-ray set (StudySetup::xraysPerTrial off)
  std::string shard;               ///< K/N: run only shard K of N; empty: every trial
  std::vector<std::string> merge;  ///< shard output folders to merge into --out instead of running trials
  std::string writeTrial;          ///< CONDITION:TRIAL: write that trial's case into --out instead of running trials
};

/// The Transgraph table cache of a run: inside its output folder, so tables are shared by its trials only.
fs::path transgraphCacheDir(const std::string& out) { return fs::path(out) / "transgraph-cache"; }

/// The study's setup with the command's overrides applied; fails on an unknown preset, a bad detector or pixel size, or
/// an unknown DRR method.
Result<StudyDefinition> defineStudy(const EvaluateOptions& o, const std::vector<std::string>& ctLabels) {
  auto method = DrrRendererFactory::parseMethod(o.method);
  if (!method) return fail("--method: " + method.error());
  if (method.value() != DrrMethod::Siddon && method.value() != DrrMethod::Transgraph) {
    return fail(fmt::format("--method must be siddon or transgraph, got '{}'", o.method));
  }
  auto study = StudyCatalog::define(o.study, o.quick, ctLabels, method.value());
  if (!study) return fail(study.error());
  StudySetup& setup = study.value().setup;
  if (!o.preset.empty()) setup.preset = o.preset;
  if (auto schedule = RegistrationSchedule::resolve(setup.preset); !schedule) return fail("--preset: " + schedule.error());
  if (!o.detector.empty() && !parseDetectorSize(o.detector, setup.detector.cols, setup.detector.rows)) {
    return fail(fmt::format("--detector must be COLSxROWS with positive sizes, e.g. 384x288, got '{}'", o.detector));
  }
  if (o.pixel_mm < 0.0 || !std::isfinite(o.pixel_mm)) {
    return fail(fmt::format("--pixel-mm must be a positive size in mm, got {}", o.pixel_mm));
  }
  if (o.pixel_mm > 0.0) setup.detector.pixelSpacing_mm = o.pixel_mm;
  if (method.value() == DrrMethod::Transgraph) setup.transgraphCacheDir = transgraphCacheDir(o.out);
  setup.xraysPerTrial = !o.oneXraySet;
  return study;
}

/// The shared data folder named by $FLUOROCT_DATA_DIR; empty when it is not set.
fs::path dataDir() {
  const char* env = std::getenv("FLUOROCT_DATA_DIR");
  return env && *env ? fs::path(env) : fs::path();
}

/// A label for a CT path: its file or folder name without image extensions, unique among `taken`.
std::string labelFor(const fs::path& path, const std::vector<std::string>& taken) {
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
  for (int n = 2; std::find(taken.begin(), taken.end(), label) != taken.end(); ++n) {
    label = fmt::format("{}-{}", name, n);
  }
  return label;
}

/// The CTs of the run: --ct paths; else the phantom (--quick); else those of the data folder $FLUOROCT_DATA_DIR
/// (pelvis, and the head phantom for table2). Fails, naming both ways to give the CTs, when neither --ct nor
/// FLUOROCT_DATA_DIR is given or the folder lacks a CT; fails on a CT that cannot be read. `sources`, when given, gets
/// the path each CT was read from (empty for the phantom). With `onlyLabel` naming one of the CTs, only that one is
/// loaded.
Result<std::vector<StudyCt>> loadCts(const EvaluateOptions& o, std::vector<fs::path>* sources = nullptr,
                                     const std::string& onlyLabel = {}) {
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
    if (sources) sources->push_back({});
    return cts;
  }
  if (paths.empty()) {
    const fs::path data = dataDir();
    if (data.empty()) {
      return fail(fmt::format("the full '{}' study needs CTs: give them with --ct PATH ..., or set FLUOROCT_DATA_DIR to "
                              "the data folder that holds ct/pelvis_totalseg.nii.gz (or use --quick for the built-in "
                              "phantom)",
                              o.study));
    }
    paths.emplace_back("pelvis", data / "ct/pelvis_totalseg.nii.gz");
    if (o.study == "table2" || o.study == "tracking") paths.emplace_back("head", data / "ct/head_phantom_philips_bone");
    for (const auto& [label, path] : paths) {
      if (!fs::exists(path)) {
        return fail(fmt::format("the full '{}' study needs {}, which does not exist; set FLUOROCT_DATA_DIR to the data "
                                "folder that holds it, or give the CTs with --ct PATH ...",
                                o.study, path.string()));
      }
    }
  }
  // A CT of --ct is labelled by its file name; the others come from the data folder.
  const bool fromCtOption = !o.cts.empty();
  std::vector<std::string> labels;
  for (auto& [label, path] : paths) {
    if (label.empty()) label = labelFor(path, labels);
    labels.push_back(label);
  }
  const bool onlyOne = std::find(labels.begin(), labels.end(), onlyLabel) != labels.end();
  for (const auto& [label, path] : paths) {
    if (onlyOne && label != onlyLabel) continue;
    fmt::print(stderr, "evaluate: loading CT {}\n", path.string());
    auto volume = CtLoader::load(path);
    if (!volume) {
      return fail(fmt::format("{} {}: {}", fromCtOption ? "--ct" : "FLUOROCT_DATA_DIR CT", path.string(),
                              volume.error()));
    }
    printWarnings(volume.warnings());
    cts.push_back(StudyCt{label, std::move(volume).value()});
    if (sources) sources->push_back(path);
  }
  return cts;
}

/// `text` with its line breaks turned into "; ".
std::string oneLine(const std::string& text) {
  std::string out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) out += (out.empty() ? "" : "; ") + line;
  return out;
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

/// A study ready to run or merge: its definition over the loaded CTs (trial counts after --trials), the CTs, its
/// shard (--shard) and its setup text.
struct PreparedStudy {
  StudyDefinition study;
  std::vector<StudyCt> cts;
  std::vector<fs::path> ctSources;  ///< the path each CT was read from (empty: the phantom)
  std::optional<StudyShard> shard;
  std::string setup;
};

/// Checks the options before anything is loaded or written; returns the study they define (over a placeholder CT
/// label). Fails with the message to report.
Result<StudyDefinition> checkOptions(const EvaluateOptions& o) {
  auto known = defineStudy(o, {"ct"});
  if (!known) return fail(known.error());
  if (o.jobs < 1 || o.jobs > StudyRunner::kMaxJobs) {
    return fail(fmt::format("--jobs must be between 1 and {}, got {}", StudyRunner::kMaxJobs, o.jobs));
  }
  if (o.trials < 0) return fail(fmt::format("--trials must be positive, got {}", o.trials));
  if (!o.shard.empty()) {
    if (auto shard = StudyShard::parse(known.value(), o.shard); !shard) return fail("--shard: " + shard.error());
  }
  return known;
}

/// Loads the CTs of the checked study `known` (only the one labelled `onlyLabel` when it names one) and defines it over
/// them. For a run, checks (or writes) DIR/setup.txt against the trials in `store`; a merge checks its folders later
/// (StudyMerge). Fails with the message to report.
Result<PreparedStudy> prepareStudy(const EvaluateOptions& o, const StudyDefinition& known, const TrialStore* store,
                                   const std::string& onlyLabel = {}) {
  PreparedStudy prepared;
  // The CTs are found before setup.txt is written, so that a run without them leaves no setup behind.
  auto cts = loadCts(o, &prepared.ctSources, onlyLabel);
  if (!cts) return fail(cts.error());
  std::vector<std::string> labels;
  for (const StudyCt& ct : cts.value()) labels.push_back(ct.label);
  auto study = defineStudy(o, labels);
  if (!study) return fail(study.error());
  StudyRunner::resolveSliceSpacings(study.value(), cts.value());
  for (StudyCondition& c : study.value().conditions) {
    if (o.trials > 0) c.trials = std::min(c.trials, o.trials);
  }
  // The shard deals out the trials of the run (after --trials); checked by checkOptions.
  if (!o.shard.empty()) prepared.shard = StudyShard::parse(study.value(), o.shard).value();
  prepared.setup = StudySetupFile::text(known, o.cts, prepared.shard ? &*prepared.shard : nullptr);
  if (store) {
    if (Status same = StudySetupFile::checkOrWrite(o.out, prepared.setup, !store->records().empty()); !same) {
      return fail("--out: " + same.error());
    }
  }
  prepared.study = std::move(study).value();
  prepared.cts = std::move(cts).value();
  return prepared;
}

/// The report's notes: the command (a merge's as the one unsharded run it stands for), the setup, the shard, and
/// StudyRunner's notes.
std::vector<std::string> reportNotes(const EvaluateOptions& o, const PreparedStudy& p) {
  std::vector<std::string> notes = StudyRunner::notes(p.study, p.cts);
  if (p.shard && p.shard->count() > 1) {
    notes.insert(notes.begin(), fmt::format("shard {}: this folder holds only that shard's trials; merge the {} shard "
                                            "folders with `--merge` for the report of the whole study",
                                            p.shard->text(), p.shard->count()));
  }
  notes.insert(notes.begin(),
               fmt::format("command: `fluoroct evaluate --study {}{} --out {}{}{}{}{}{}{} --method {}{}`; setup (compared "
                           "on resume, DIR/setup.txt): {}",
                           o.study, o.quick ? " --quick" : "", o.out,
                           p.shard ? " --shard " + p.shard->text() : "",
                           o.trials > 0 ? fmt::format(" --trials {}", o.trials) : "",
                           o.cts.empty() ? "" : fmt::format(" --ct {}", fmt::join(o.cts, " ")),
                           o.preset.empty() ? "" : " --preset " + o.preset,
                           o.detector.empty() ? "" : " --detector " + o.detector,
                           o.pixel_mm > 0 ? fmt::format(" --pixel-mm {:g}", o.pixel_mm) : "", o.method,
                           o.oneXraySet ? " --one-xray-set" : "", oneLine(p.setup)));
  return notes;
}

/// Writes the report and charts of `records` into --out; returns the names of the files written.
Result<std::vector<std::string>> writeReport(const EvaluateOptions& o, const PreparedStudy& p,
                                             const std::vector<TrialRecord>& records) {
  auto written = StudyReport::write(p.study, records, reportNotes(o, p), o.out);
  if (!written) return fail(written.error());
  std::vector<std::string> names;
  for (const fs::path& path : written.value()) names.push_back(path.filename().string());
  return names;
}

/// --merge: the trials of the shard folders into one trials.csv, report and charts in --out, as one run writes them.
int runMerge(const EvaluateOptions& o, const StudyDefinition& known) {
  if (Status ready = prepareOutput(o.out); !ready) return reportError(ready.error());
  auto prepared = prepareStudy(o, known, nullptr);
  if (!prepared) return reportError(prepared.error());
  const PreparedStudy& p = prepared.value();
  std::vector<fs::path> folders(o.merge.begin(), o.merge.end());
  auto records = StudyMerge::collect(p.study, p.setup, folders);
  if (!records) return reportError("--merge: " + records.error());
  if (Status saved = StudyMerge::write(o.out, p.setup, records.value()); !saved) {
    return reportError("--out: " + saved.error());
  }
  auto names = writeReport(o, p, records.value());
  if (!names) return reportError(names.error());
  fmt::print("{}: merged {} trials from {} shard folders; wrote {} and {}\n", o.study, records.value().size(),
             folders.size(), (fs::path(o.out) / "trials.csv").string(), fmt::join(names.value(), ", "));
  return 0;
}

/// The resume check of a tracking study: the options that change its results, one per line (--trials may change:
/// more sequences add to the stored ones).
std::string trackingSetupText(const EvaluateOptions& o, const TrackingStudyDefinition& study) {
  return fmt::format("study: tracking\nquick: {}\ncts: {}\npreset: {}\nframes: {}\nseed: {}\n", o.quick,
                     fmt::join(o.cts, " "), study.preset, study.motion.frames, study.seed);
}

/// --study tracking: simulates and tracks the sequences (TrackingStudy) into DIR/frames.json (resumable) and
/// DIR/frames.csv, then writes DIR/report.md and DIR/summary.csv (TrackingReport).
int runTrackingStudy(const EvaluateOptions& o) {
  if (!o.shard.empty() || !o.merge.empty() || !o.detector.empty() || o.pixel_mm != 0.0 || o.method != "siddon" ||
      o.jobs != 1 || o.oneXraySet) {
    return reportError("the tracking study fixes its detectors, runs its sequences one after another and simulates "
                       "every frame: drop --shard, --merge, --detector, --pixel-mm, --method, --jobs and "
                       "--one-xray-set");
  }
  if (o.trials < 0) return reportError(fmt::format("--trials must be positive, got {}", o.trials));
  auto checked = TrackingStudy::define(o.quick, {"ct"});
  if (!checked) return reportError(checked.error());
  if (!o.preset.empty()) checked.value().preset = o.preset;
  if (auto settings = TrackingStudy::trackerOptions(checked.value()); !settings) {
    return reportError("--preset: " + settings.error());
  }
  if (Status ready = prepareOutput(o.out); !ready) return reportError(ready.error());
  auto store = TrackingFrameStore::open(o.out);
  if (!store) return reportError("--out: " + store.error());
  auto cts = loadCts(o);
  if (!cts) return reportError(cts.error());
  std::vector<std::string> labels;
  for (const StudyCt& ct : cts.value()) labels.push_back(ct.label);
  TrackingStudyDefinition study = TrackingStudy::define(o.quick, labels).value();
  if (!o.preset.empty()) study.preset = o.preset;
  for (TrackingCondition& c : study.conditions) {
    if (o.trials > 0) c.sequences = o.trials;
  }
  if (Status same = StudySetupFile::checkOrWrite(o.out, trackingSetupText(o, study), !store.value().records().empty());
      !same) {
    return reportError("--out: " + same.error());
  }
  fmt::print(stderr, "evaluate: study 'tracking'{} on {}: {} conditions, {} frames per sequence; frame 0 preset {}\n",
             o.quick ? " (quick)" : "", fmt::join(labels, ", "), study.conditions.size(), study.motion.frames,
             study.preset);
  TrackingRunOptions run;
  run.cancel = InterruptGuard::cancelFlag();
  run.onMessage = [](const std::string& text) { fmt::print(stderr, "evaluate: {}\n", text); };
  run.onSequence = [&study](const TrackingProgress& progress) {
    const TrackingFrameRecord& first = progress.frames.front();
    const auto condition = std::find_if(study.conditions.begin(), study.conditions.end(),
                                        [&](const TrackingCondition& c) { return c.name == first.condition; });
    const TrackingConditionStats s = TrackingReport::statistics(*condition, progress.frames);
    fmt::print(stderr, "[{}/{}] {} sequence {}: {} frames, median sTRE {:.3f} mm (max {:.3f}), {} failures, {} "
                       "recovered, {:.1f} frames/s\n",
               progress.finished, progress.toRun, first.condition, first.sequence, s.frames, s.medianStre_mm,
               s.maxStre_mm, s.failures, s.recoveries, s.framesPerSecond);
  };
  auto summary = [&] {
    const InterruptGuard interrupt;  // Ctrl-C stops the running sequence (the finished ones stay saved)
    return TrackingStudy::run(study, cts.value(), store.value(), run);
  }();
  if (!summary) return reportError(summary.error());
  std::vector<std::string> notes = TrackingStudy::notes(study);
  notes.insert(notes.begin(), fmt::format("command: `fluoroct evaluate --study tracking{} --out {}{}{}{}`",
                                          o.quick ? " --quick" : "", o.out,
                                          o.trials > 0 ? fmt::format(" --trials {}", o.trials) : "",
                                          o.cts.empty() ? "" : fmt::format(" --ct {}", fmt::join(o.cts, " ")),
                                          o.preset.empty() ? "" : " --preset " + o.preset));
  auto written = TrackingReport::write(study, store.value().records(), notes, o.out);
  if (!written) return reportError(written.error());
  fmt::print("tracking: ran {} sequences, skipped {} already done; wrote {}, {}, {} and {}\n", summary.value().ran,
             summary.value().skipped, (fs::path(o.out) / "frames.json").string(),
             (fs::path(o.out) / "frames.csv").string(), written.value()[0].string(), written.value()[1].string());
  if (summary.value().cancelled) {
    return reportError("cancelled; the finished sequences are saved: re-run the same command to resume");
  }
  return 0;
}

/// --write-trial CONDITION:TRIAL: writes that trial's case into --out (StudyTrialCase) and prints the command that
/// registers it as the study does.
int runWriteTrial(const EvaluateOptions& o, const StudyDefinition& known) {
  const std::size_t colon = o.writeTrial.rfind(':');
  int trial = -1;
  const char* digits = colon == std::string::npos ? nullptr : o.writeTrial.c_str() + colon + 1;
  const char* end = o.writeTrial.c_str() + o.writeTrial.size();
  if (!digits || digits == end || std::from_chars(digits, end, trial).ptr != end) {
    return reportError(fmt::format("--write-trial must be CONDITION:TRIAL, e.g. pelvis/realistic:1 (a condition of "
                                   "the study's report and a 0-based trial), got '{}'",
                                   o.writeTrial));
  }
  const std::string condition = o.writeTrial.substr(0, colon);
  // A condition's name starts with its CT's label: only that CT is loaded (all of them when none matches, so that an
  // unknown condition's message lists every condition).
  auto prepared = prepareStudy(o, known, nullptr, condition.substr(0, condition.find('/')));
  if (!prepared) return reportError(prepared.error());
  const PreparedStudy& p = prepared.value();
  const auto named = std::find_if(p.study.conditions.begin(), p.study.conditions.end(),
                                  [&](const StudyCondition& c) { return c.name == condition; });
  fs::path ctSource;
  if (named != p.study.conditions.end()) {
    for (std::size_t i = 0; i < p.cts.size(); ++i) {
      if (p.cts[i].label == named->ct) ctSource = p.ctSources[i];
    }
  }
  auto files = StudyTrialCase::write(p.study, p.cts, condition, trial, ctSource, o.out);
  if (!files) return reportError("--write-trial: " + files.error());
  const StudyTrialCaseFiles& f = files.value();
  fmt::print("wrote trial {} of {} (start {:.2f} mm mean sTRE from the truth) into {}; register it as the study does:\n"
             "  fluoroct register --ct {} --views {} --init {} --truth {} --preset {} --cut-face-margin-mm {:g} "
             "--seed {} --out RESULT_DIR\n",
             trial, condition, f.initialStre_mm, o.out, f.registrationCt.string(), f.viewFile.string(),
             f.startFile.string(), f.truthFile.string(), p.study.setup.preset, f.cutFaceMargin_mm,
             p.study.setup.seed + static_cast<std::uint32_t>(trial));
  return 0;
}

int runEvaluate(const EvaluateOptions& o) {
  if (o.study == "tracking") {
    if (!o.writeTrial.empty()) return reportError("--write-trial applies to table2, capture, ablation and views");
    return runTrackingStudy(o);
  }
  auto known = checkOptions(o);
  if (!known) return reportError(known.error());
  if (!o.merge.empty() && !o.writeTrial.empty()) return reportError("--write-trial and --merge exclude each other");
  if (!o.merge.empty()) return runMerge(o, known.value());
  if (!o.writeTrial.empty()) return runWriteTrial(o, known.value());
  if (Status ready = prepareOutput(o.out); !ready) return reportError(ready.error());
  auto store = TrialStore::open(fs::path(o.out) / "trials.csv");
  if (!store) return reportError("--out: " + store.error());
  auto prepared = prepareStudy(o, known.value(), &store.value());
  if (!prepared) return reportError(prepared.error());
  const PreparedStudy& p = prepared.value();
  std::size_t total = 0;
  for (const StudyCondition& c : p.study.conditions) total += static_cast<std::size_t>(c.trials);
  std::vector<std::string> labels;
  for (const StudyCt& ct : p.cts) labels.push_back(ct.label);
  const StudySetup& s = p.study.setup;
  fmt::print(stderr, "evaluate: study '{}'{}{} on {}: {} conditions, {} trials, {} job(s); preset {}, detector {}x{} at "
                     "{:g} mm, {} DRRs\n",
             o.study, o.quick ? " (quick)" : "", p.shard ? fmt::format(", shard {}", p.shard->text()) : "",
             fmt::join(labels, ", "), p.study.conditions.size(), total, o.jobs, s.preset, s.detector.cols,
             s.detector.rows, s.detector.pixelSpacing_mm, DrrRendererFactory::methodName(s.method));

  StudyRunOptions run;
  run.jobs = o.jobs;
  run.cancel = InterruptGuard::cancelFlag();
  run.shard = p.shard ? &*p.shard : nullptr;
  run.onMessage = [](const std::string& text) { fmt::print(stderr, "evaluate: {}\n", text); };
  run.onTrial = [](const StudyProgress& progress) {
    const TrialRecord& r = progress.record;
    fmt::print(stderr, "[{}/{}] {} trial {}: initial sTRE {:.2f} mm -> {:.3f} mm (max {:.3f}) {}{} {:.1f} s{}, {} DRRs\n",
               progress.finished, progress.toRun, r.condition, r.trial, r.initialStre_mm, r.error.streMean_mm,
               r.error.streMax_mm,
               r.status == TrialStatus::Ok ? (r.success ? "success" : "FAILURE") : trialStatusName(r.status),
               r.reason.empty() ? "" : " (" + r.reason + ")", r.seconds,
               r.setupSeconds > 0 ? fmt::format(" (+{:.1f} s tables)", r.setupSeconds) : "", r.drrs);
  };
  auto summary = [&] {
    const InterruptGuard interrupt;  // Ctrl-C stops the trials (the finished ones stay saved) until the run returns
    return StudyRunner::run(p.study, p.cts, store.value(), run);
  }();
  if (!summary) return reportError(summary.error());

  auto names = writeReport(o, p, store.value().records());
  if (!names) return reportError(names.error());
  fmt::print("{}{}: ran {} trials ({} failed), skipped {} already done; wrote {} and {}\n", o.study,
             p.shard ? " shard " + p.shard->text() : "", summary.value().ran, summary.value().failed,
             summary.value().skipped, store.value().path().string(), fmt::join(names.value(), ", "));
  if (summary.value().cancelled) {
    return reportError("cancelled; the finished trials are saved: re-run the same command to resume");
  }
  return 0;
}

}  // namespace

void registerEvaluateCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<EvaluateOptions>();
  CLI::App* command = app.add_subcommand(
      "evaluate", "Run an evaluation study (table2, capture, ablation, views, tracking) on simulated X-rays of known "
                  "truth; writes DIR/trials.csv (tracking: DIR/frames.csv; resumable), DIR/report.md and PNG charts");
  command->add_option("--study", options->study,
                      "Study: table2, capture, ablation, views or tracking (simulated cine sequences of a moving bone, "
                      "single-plane and biplane, tracked frame by frame)")
      ->required();
  command->add_option("--out", options->out, "Output folder (re-running with the same folder resumes)")->required();
  command->add_flag("--quick", options->quick,
                    "Small version on the built-in phantom (fast preset, 128x128 detector, 2 trials per condition)");
  command->add_option("--jobs", options->jobs, "Trials run in parallel")->capture_default_str();
  command->add_option("--trials", options->trials,
                      "At most this many trials per condition (a sample of a study; the first N of each condition); "
                      "tracking: this many sequences per condition");
  command->add_option("--ct", options->cts,
                      "CT volume(s) or DICOM folder(s) instead of the defaults (full: the pelvis of $FLUOROCT_DATA_DIR, "
                      "plus its head phantom for table2; quick: the phantom)");
  command->add_option("--preset", options->preset,
                      "Registration preset: clinical, accurate, paper, fast or a preset FILE.json (default: clinical, the product default; --quick: fast)");
  command->add_option("--detector", options->detector,
                      "Detector size in pixels, COLSxROWS (default 800x600; --quick 128x128); the field is COLS x "
                      "--pixel-mm wide, as in `fluoroct views`");
  command->add_option("--pixel-mm", options->pixel_mm, "Detector pixel size in mm (default 0.4; --quick 2.4)");
  command->add_option("--method", options->method,
                      "DRR method: siddon (exact) or transgraph (tables built around each trial's start pose, cached "
                      "in OUT/transgraph-cache)")
      ->capture_default_str();
  command->add_flag("--one-xray-set", options->oneXraySet,
                    "Register every trial of a CT against one X-ray set at the study's true pose, instead of each "
                    "trial against its own (bone pose, foreign objects and noise drawn from the trial's seed)");
  CLI::Option* shard = command->add_option(
      "--shard", options->shard,
      "Run only shard K of N, as K/N (e.g. 2/8), into its own --out; the trials are dealt round robin, so every shard "
      "gets a share of every condition");
  command->add_option("--merge", options->merge,
                      "Merge these shard folders (of one study run with --shard K/N, all K, and the same options as "
                      "given here) into --out instead of running trials")
      ->excludes(shard);
  command->add_option("--write-trial", options->writeTrial,
                      "Write one trial as a case folder into --out instead of running trials: CONDITION:TRIAL, e.g. "
                      "pelvis/realistic:1 (the trial's X-rays as 16-bit PNG, views.json, truth_pose.json, "
                      "start_pose.json and, for coarser slices, ct_registration.nrrd); prints the register command")
      ->excludes(shard);
  command->callback([&action, options] { action = [options] { return runEvaluate(*options); }; });
}

}  // namespace fct::cli
