// fluoroct evaluate: the four quick studies end to end on the built-in phantom (CSV rows, valid PNG charts, report
// tables), resume (and its refusal when the options differ), bad input, and where a full study takes its CTs from
// (--ct or $FLUOROCT_DATA_DIR only). The quick studies are what CI runs.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <string>

#include "Base/TextFile.h"
#include "Evaluation/StudyCatalog.h"
#include "Evaluation/TrialStore.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

/// Width and height from a PNG's signature and IHDR chunk; (0, 0) if the file is not a PNG.
std::pair<std::uint32_t, std::uint32_t> pngSize(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(24, '\0');
  if (!in.read(head.data(), 24) || head.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || head.compare(12, 4, "IHDR") != 0) {
    return {0, 0};
  }
  const auto be32 = [&](int at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(head[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

/// Runs a quick study into `out` and checks the CSV has one row per trial and every chart is a valid 900x560 PNG.
void runQuickStudy(const std::string& study, const fs::path& out, const std::string& extra = "",
                   fct::DrrMethod method = fct::DrrMethod::Siddon) {
  const auto run = fct::test::runCli(fmt::format("evaluate --study {} --quick --out '{}' {}", study, out.string(), extra));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("[1/"), std::string::npos) << "progress on stderr: " << run.err;
  const auto definition = fct::StudyCatalog::define(study, true, {"phantom"}, method).value();
  int trials = 0;
  for (const fct::StudyCondition& c : definition.conditions) trials += c.trials;
  const auto store = fct::TrialStore::open(out / "trials.csv");
  ASSERT_TRUE(store.ok()) << store.error();
  EXPECT_EQ(static_cast<int>(store.value().records().size()), trials);
  for (const fct::TrialRecord& r : store.value().records()) {
    EXPECT_EQ(r.status, fct::TrialStatus::Ok) << r.condition << ": " << r.reason;
    EXPECT_GT(r.drrs, 0);
  }
  int charts = 0;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().extension() != ".png") continue;
    ++charts;
    EXPECT_EQ(pngSize(entry.path()), (std::pair<std::uint32_t, std::uint32_t>{900, 560})) << entry.path();
  }
  EXPECT_EQ(charts, 2);
  EXPECT_NE(fct::test::readText(out / "report.md").find(fmt::format("# Study `{}` (quick)", study)), std::string::npos);
}

/// Sets FLUOROCT_DATA_DIR (or unsets it, for nullopt) for the CLI runs of its lifetime, then restores it.
class ScopedDataDir {
 public:
  explicit ScopedDataDir(const std::optional<fs::path>& folder) {
    const char* previous = std::getenv("FLUOROCT_DATA_DIR");
    if (previous) m_previous = previous;
    if (folder) {
      ::setenv("FLUOROCT_DATA_DIR", folder->c_str(), 1);
    } else {
      ::unsetenv("FLUOROCT_DATA_DIR");
    }
  }
  ~ScopedDataDir() {
    if (m_previous) {
      ::setenv("FLUOROCT_DATA_DIR", m_previous->c_str(), 1);
    } else {
      ::unsetenv("FLUOROCT_DATA_DIR");
    }
  }
  ScopedDataDir(const ScopedDataDir&) = delete;
  ScopedDataDir& operator=(const ScopedDataDir&) = delete;

 private:
  std::optional<std::string> m_previous;
};

/// The setup.txt of `evaluate --study table2 --quick` (every default spelled out).
const std::string kQuickTable2Setup =
    "study: table2\nquick: yes\ncts: default\npreset: fast\ndetector: 128x128\npixel_mm: 2.4\nsid_mm: 1000\n"
    "sad_mm: 700\nmethod: siddon\ntransgraph_spacing_mm: 6\nseed: 1\nxrays: per trial\n";

}  // namespace

TEST(EvaluateCommand, QuickTable2WritesTrialsChartsAndTheTableBesideThePaper) {
  const auto out = fct::test::scratchDir() / "table2";
  runQuickStudy("table2", out);
  const std::string csv = fct::test::readText(out / "trials.csv");
  EXPECT_EQ(csv.rfind("study,ct,condition,scenario,variant,views,trial,seed,truth_offset_mm,initial_target_mm,"
                      "initial_stre_mm,"
                      "stre_mean_mm,stre_max_mm,mtre_mm,rotation_deg,translation_mm,success,seconds,setup_seconds,drrs,status,"
                      "reason\n",
                      0),
            0u);
  const std::string report = fct::test::readText(out / "report.md");
  EXPECT_NE(report.find("| phantom | realistic | 2.4 mm | 2 |"), std::string::npos) << report;
  EXPECT_NE(report.find("| phantom | ideal | 2 mm (original) | 2 |"), std::string::npos) << report;
  EXPECT_NE(report.find("DRR method `siddon`; detector 128x128 px at 2.4 mm"), std::string::npos) << report;
  EXPECT_NE(fct::test::readText(out / "setup.txt").find("detector: 128x128\npixel_mm: 2.4\n"), std::string::npos);
  EXPECT_NE(report.find("paper: mean (max) sTRE"), std::string::npos);
  EXPECT_NE(report.find("![Success rate by scenario](table2_success.png)"), std::string::npos);
}

TEST(EvaluateCommand, EveryTrialHasItsOwnBonePoseUnlessOneXraySetIsAsked) {
  const auto own = fct::test::scratchDir() / "own";
  runQuickStudy("table2", own);
  const auto ownTrials = fct::TrialStore::open(own / "trials.csv").value().records();
  ASSERT_EQ(ownTrials.size(), 6u);
  std::set<double> offsets;
  for (const fct::TrialRecord& r : ownTrials) {
    EXPECT_GT(r.truthOffset_mm, 0.5) << r.condition << " trial " << r.trial << ": the bone was moved";
    offsets.insert(r.truthOffset_mm);
  }
  EXPECT_EQ(offsets.size(), 2u) << "trial t of every condition has the same pose; the two trials differ";
  EXPECT_NE(fct::test::readText(own / "report.md").find("every trial registers against X-rays of its own"),
            std::string::npos);

  const auto shared = fct::test::scratchDir() / "shared";
  runQuickStudy("table2", shared, "--one-xray-set");
  const fct::TrialStore sharedStore = fct::TrialStore::open(shared / "trials.csv").value();
  for (const fct::TrialRecord& r : sharedStore.records()) {
    EXPECT_EQ(r.truthOffset_mm, 0.0) << r.condition << " trial " << r.trial;
  }
  EXPECT_NE(fct::test::readText(shared / "setup.txt").find("\nxrays: one set\n"), std::string::npos);
  EXPECT_NE(fct::test::readText(shared / "report.md").find("--one-xray-set"), std::string::npos);
}

TEST(EvaluateCommand, QuickCaptureStudyRuns) { runQuickStudy("capture", fct::test::scratchDir() / "capture"); }

TEST(EvaluateCommand, QuickAblationWithTransgraphHasANoTransgraphRow) {
  const auto out = fct::test::scratchDir() / "ablation";
  runQuickStudy("ablation", out, "--method transgraph", fct::DrrMethod::Transgraph);
  const std::string report = fct::test::readText(out / "report.md");
  EXPECT_NE(report.find("| phantom | no-transgraph | 2 |"), std::string::npos) << report;
  EXPECT_EQ(report.find("Transgraph off: no row"), std::string::npos) << report;
  EXPECT_NE(report.find("DRR method `transgraph`"), std::string::npos) << report;
  const auto store = fct::TrialStore::open(out / "trials.csv").value();
  for (const fct::TrialRecord& r : store.records()) {
    if (r.variant == "no-transgraph") {
      EXPECT_EQ(r.setupSeconds, 0.0) << "no tables for the Siddon row";
    }
  }
  EXPECT_TRUE(fs::is_directory(out / "transgraph-cache"));
}

TEST(EvaluateCommand, QuickViewsStudyRunsOnTwoJobs) {
  runQuickStudy("views", fct::test::scratchDir() / "views", "--jobs 2");
}

TEST(EvaluateCommand, ResumeRunsOnlyTheTrialsNotYetInTheCsv) {
  const auto out = fct::test::scratchDir();
  // Five of the six quick table2 trials are already done (made-up numbers), the sixth is missing.
  std::vector<fct::TrialRecord> done;
  for (const char* scenario : {"ideal", "realistic", "bad"}) {
    for (int t = 0; t < 2; ++t) {
      if (std::string(scenario) == "bad" && t == 1) continue;
      fct::TrialRecord r;
      r.study = "table2";
      r.ct = "phantom";
      r.condition = fmt::format("phantom/{}", scenario);
      r.scenario = scenario;
      r.trial = t;
      r.views = 3;
      r.error = fct::PoseError{0.123456, 0.5, 0.2, 0.1, 0.1};
      r.success = true;
      done.push_back(r);
    }
  }
  ASSERT_TRUE(fct::TextFile::writeAtomically(out / "trials.csv", fct::TrialStore::toCsv(done)).ok());
  ASSERT_TRUE(fct::TextFile::writeAtomically(out / "setup.txt", kQuickTable2Setup).ok());
  const auto run = fct::test::runCli(fmt::format("evaluate --study table2 --quick --out '{}'", out.string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("ran 1 trials (0 failed), skipped 5"), std::string::npos) << run.out;
  const auto store = fct::TrialStore::open(out / "trials.csv").value();
  ASSERT_EQ(store.records().size(), 6u);
  EXPECT_EQ(store.records().back().condition, "phantom/bad");
  EXPECT_EQ(store.records().back().trial, 1);
  EXPECT_NEAR(store.records().front().error.streMean_mm, 0.123456, 1e-9);  // done trials are kept, not re-run

  const auto again = fct::test::runCli(fmt::format("evaluate --study table2 --quick --out '{}'", out.string()));
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_NE(again.out.find("ran 0 trials (0 failed), skipped 6"), std::string::npos) << again.out;
}

TEST(EvaluateCommand, ResumeWithOtherOptionsIsRefused) {
  const auto out = fct::test::scratchDir();
  fct::TrialRecord r;
  r.study = "table2";
  r.ct = "phantom";
  r.condition = "phantom/ideal";
  r.views = 3;
  r.error = fct::PoseError{0.1, 0.2, 0.1, 0.1, 0.1};
  const std::string csv = fct::TrialStore::toCsv({r});
  ASSERT_TRUE(fct::TextFile::writeAtomically(out / "trials.csv", csv).ok());
  const auto noSetup = fct::test::runCli(fmt::format("evaluate --study table2 --quick --out '{}'", out.string()));
  EXPECT_EQ(noSetup.exitCode, 2);
  EXPECT_NE(noSetup.err.find("holds trials but no setup.txt"), std::string::npos) << noSetup.err;

  ASSERT_TRUE(fct::TextFile::writeAtomically(out / "setup.txt", kQuickTable2Setup).ok());
  const auto other = fct::test::runCli(
      fmt::format("evaluate --study table2 --quick --detector 96x96 --pixel-mm 3.2 --out '{}'", out.string()));
  EXPECT_EQ(other.exitCode, 2);
  EXPECT_EQ(other.err.rfind("error: ", 0), 0u);
  EXPECT_NE(other.err.find("holds trials run with other options ('detector: 96x96' now, 'detector: 128x128' stored; "
                           "'pixel_mm: 3.2' now, 'pixel_mm: 2.4' stored)"),
            std::string::npos)
      << other.err;
  const auto method = fct::test::runCli(
      fmt::format("evaluate --study table2 --quick --method transgraph --out '{}'", out.string()));
  EXPECT_EQ(method.exitCode, 2);
  EXPECT_NE(method.err.find("'method: transgraph' now, 'method: siddon' stored"), std::string::npos) << method.err;
  EXPECT_EQ(fct::test::readText(out / "trials.csv"), csv);  // nothing ran, nothing rewritten
  EXPECT_EQ(fct::test::readText(out / "setup.txt"), kQuickTable2Setup);
}

TEST(EvaluateCommand, BadOptionsAreRefusedBeforeAnythingIsWritten) {
  const auto dir = fct::test::scratchDir();
  const auto run = [&](const std::string& options) {
    return fct::test::runCli(fmt::format("evaluate --study views --quick {} --out '{}'", options, (dir / "o").string()));
  };
  const auto detector = run("--detector 128by96");
  EXPECT_EQ(detector.exitCode, 2);
  EXPECT_EQ(detector.err.rfind("error: --detector must be COLSxROWS", 0), 0u) << detector.err;
  const auto zero = run("--detector 0x96");
  EXPECT_EQ(zero.exitCode, 2);
  EXPECT_NE(zero.err.find("--detector"), std::string::npos) << zero.err;
  const auto preset = run("--preset no-such-preset");
  EXPECT_EQ(preset.exitCode, 2);
  EXPECT_EQ(preset.err.rfind("error: --preset: ", 0), 0u) << preset.err;
  const auto pixel = run("--pixel-mm=-1");
  EXPECT_EQ(pixel.exitCode, 2);
  EXPECT_NE(pixel.err.find("--pixel-mm"), std::string::npos) << pixel.err;
  const auto method = run("--method raycast");
  EXPECT_EQ(method.exitCode, 2);
  EXPECT_NE(method.err.find("--method must be siddon or transgraph"), std::string::npos) << method.err;
  EXPECT_FALSE(fs::exists(dir / "o"));
}

TEST(EvaluateCommand, BadInputGivesOneErrorLine) {
  const auto dir = fct::test::scratchDir();
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "file", "x").ok());
  const auto unknown = fct::test::runCli(fmt::format("evaluate --study table3 --quick --out '{}'", (dir / "o").string()));
  EXPECT_EQ(unknown.exitCode, 2);
  EXPECT_EQ(unknown.err.rfind("error: unknown study 'table3'; the studies are: table2, capture, ablation, views", 0), 0u)
      << unknown.err;
  EXPECT_FALSE(fs::exists(dir / "o"));

  const auto unwritable =
      fct::test::runCli(fmt::format("evaluate --study views --quick --out '{}'", (dir / "file" / "out").string()));
  EXPECT_EQ(unwritable.exitCode, 2);
  EXPECT_EQ(unwritable.err.rfind("error: cannot create the output folder", 0), 0u) << unwritable.err;

  const auto jobs = fct::test::runCli(fmt::format("evaluate --study views --quick --jobs 0 --out '{}'", (dir / "j").string()));
  EXPECT_EQ(jobs.exitCode, 2);
  EXPECT_NE(jobs.err.find("--jobs"), std::string::npos) << jobs.err;
  const auto tooMany =
      fct::test::runCli(fmt::format("evaluate --study views --quick --jobs 65 --out '{}'", (dir / "j").string()));
  EXPECT_EQ(tooMany.exitCode, 2);
  EXPECT_EQ(tooMany.err.rfind("error: --jobs must be between 1 and 64, got 65", 0), 0u) << tooMany.err;
  EXPECT_FALSE(fs::exists(dir / "j"));

  fs::create_directories(dir / "foreign");
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "foreign" / "trials.csv", "a,b\n1,2\n").ok());
  const auto foreign =
      fct::test::runCli(fmt::format("evaluate --study views --quick --out '{}'", (dir / "foreign").string()));
  EXPECT_EQ(foreign.exitCode, 2);
  EXPECT_EQ(foreign.err.rfind("error: --out: ", 0), 0u) << foreign.err;
  EXPECT_NE(foreign.err.find("use another output folder"), std::string::npos) << foreign.err;
}

TEST(EvaluateCommand, FullStudyWithoutItsCtsFailsNamingBothWaysToGiveThem) {
  const auto dir = fct::test::scratchDir();
  {
    const ScopedDataDir unset(std::nullopt);
    const auto run = fct::test::runCli(fmt::format("evaluate --study capture --out '{}'", (dir / "out").string()));
    EXPECT_EQ(run.exitCode, 2) << run.err;
    EXPECT_EQ(run.err.rfind("error: the full 'capture' study needs CTs: ", 0), 0u) << run.err;
    EXPECT_NE(run.err.find("--ct PATH"), std::string::npos) << run.err;
    EXPECT_NE(run.err.find("FLUOROCT_DATA_DIR"), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  }
  {
    const ScopedDataDir empty(dir / "no-data");
    const auto run = fct::test::runCli(fmt::format("evaluate --study capture --out '{}'", (dir / "out").string()));
    EXPECT_EQ(run.exitCode, 2) << run.err;
    EXPECT_EQ(run.err.rfind("error: the full 'capture' study needs ", 0), 0u) << run.err;
    EXPECT_NE(run.err.find((dir / "no-data" / "ct" / "pelvis_totalseg.nii.gz").string()), std::string::npos) << run.err;
    EXPECT_NE(run.err.find("--ct PATH"), std::string::npos) << run.err;
    EXPECT_NE(run.err.find("FLUOROCT_DATA_DIR"), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "trials.csv"));
  EXPECT_FALSE(fs::exists(dir / "out" / "setup.txt")) << "a run without its CTs leaves no setup behind";
}

TEST(EvaluateCommand, FullStudyTakesItsCtFromTheDataFolderNamedByTheEnvironment) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  const auto out = fct::test::scratchDir() / "views";
  const ScopedDataDir data(fct::test::dataDir());
  const auto run = fct::test::runCli(fmt::format(
      "evaluate --study views --trials 1 --preset fast --detector 160x128 --pixel-mm 2.4 --out '{}'", out.string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("loading CT " + (fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz").string()),
            std::string::npos)
      << run.err;
  const auto store = fct::TrialStore::open(out / "trials.csv");
  ASSERT_TRUE(store.ok()) << store.error();
  ASSERT_EQ(store.value().records().size(), 5u);  // 1 to 5 views, one trial each
  for (const fct::TrialRecord& r : store.value().records()) EXPECT_EQ(r.ct, "pelvis") << r.condition;
}

TEST(EvaluateCommand, WriteTrialWritesACaseThatTheRegisterCommandItPrintsRuns) {
  const auto dir = fct::test::scratchDir();
  const auto written = fct::test::runCli(
      fmt::format("evaluate --study table2 --quick --write-trial phantom/ideal:1 --out '{}'", (dir / "case").string()));
  ASSERT_EQ(written.exitCode, 0) << written.err;
  // The phantom is built in memory, so its CT is written too.
  for (const char* file : {"views.json", "truth_pose.json", "start_pose.json", "ct_registration.nrrd", "ap.png"}) {
    EXPECT_TRUE(fs::exists(dir / "case" / file)) << file;
  }
  EXPECT_FALSE(fs::exists(dir / "case" / "trials.csv")) << "no trial is run";
  const std::size_t at = written.out.find("  fluoroct register ");
  ASSERT_NE(at, std::string::npos) << written.out;
  std::string registerCommand = written.out.substr(at + 11);
  registerCommand = registerCommand.substr(0, registerCommand.find('\n'));
  EXPECT_NE(registerCommand.find("--preset fast --cut-face-margin-mm 5 --seed 2"), std::string::npos)
      << registerCommand;
  registerCommand.replace(registerCommand.find("RESULT_DIR"), 10, "'" + (dir / "result").string() + "'");
  const auto registered = fct::test::runCli(registerCommand);
  ASSERT_EQ(registered.exitCode, 0) << registered.err;
  // The start the case holds is the one the write reported: the same mean sTRE from the truth (on the same CT: the
  // ideal scenario registers on the study's CT).
  const std::size_t start = written.out.find("(start ");
  ASSERT_NE(start, std::string::npos) << written.out;
  const std::string startStre = written.out.substr(start + 7, written.out.find(" mm", start) - start - 7);
  EXPECT_NE(registered.out.find("mean bone-surface distance " + startStre), std::string::npos)
      << startStre << "\n" << registered.out;
}

TEST(EvaluateCommand, WriteTrialLoadsOnlyItsConditionsCt) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  FCT_REQUIRE_DATA("ct/head_phantom_philips_bone");
  const auto dir = fct::test::scratchDir();
  const ScopedDataDir data(fct::test::dataDir());
  const auto run = fct::test::runCli(fmt::format("evaluate --study table2 --detector 160x128 --pixel-mm 2.4 "
                                                 "--write-trial head/ideal:0 --out '{}'",
                                                 (dir / "case").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("loading CT " + (fct::test::dataDir() / "ct/head_phantom_philips_bone").string()),
            std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find("pelvis_totalseg"), std::string::npos) << "the pelvis is not loaded for a head trial\n"
                                                                 << run.err;
  EXPECT_TRUE(fs::exists(dir / "case" / "views.json"));
}

TEST(EvaluateCommand, WriteTrialRefusesABadTrialNameWithOneErrorLine) {
  const auto dir = fct::test::scratchDir();
  const auto run = [&](const std::string& trial) {
    return fct::test::runCli(
        fmt::format("evaluate --study table2 --quick --write-trial '{}' --out '{}'", trial, (dir / "o").string()));
  };
  const auto noTrial = run("phantom/realistic");
  EXPECT_EQ(noTrial.exitCode, 2);
  EXPECT_EQ(noTrial.err.rfind("error: --write-trial must be CONDITION:TRIAL", 0), 0u) << noTrial.err;
  const auto unknown = run("pelvis/realistic:0");
  EXPECT_EQ(unknown.exitCode, 2);
  EXPECT_EQ(unknown.err.rfind("error: --write-trial: study 'table2' has no condition 'pelvis/realistic'; its conditions "
                              "are: phantom/ideal",
                              0),
            0u)
      << unknown.err;
  EXPECT_EQ(std::count(unknown.err.begin(), unknown.err.end(), '\n'), 1) << unknown.err;
  const auto outside = run("phantom/bad:2");
  EXPECT_EQ(outside.exitCode, 2);
  EXPECT_NE(outside.err.find("condition 'phantom/bad' has trials 0 to 1, not 2"), std::string::npos) << outside.err;
  EXPECT_FALSE(fs::exists(dir / "o"));
}
