// fluoroct evaluate: the four quick studies end to end on the built-in phantom (CSV rows, valid PNG charts, report
// tables), resume, and bad input. The quick studies are what CI runs; each takes 15-60 s on 2 cores.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "StudyCatalog.h"
#include "TestSupport.h"
#include "TextFile.h"
#include "TrialStore.h"

namespace {

namespace fs = std::filesystem;

std::string readText(const fs::path& path) {
  auto text = fct::TextFile::read(path);
  EXPECT_TRUE(text.ok()) << text.error();
  return text.ok() ? text.value() : std::string();
}

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
void runQuickStudy(const std::string& study, const fs::path& out, const std::string& extra = "") {
  const auto run = fct::test::runCli(fmt::format("evaluate --study {} --quick --out '{}' {}", study, out.string(), extra));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("[1/"), std::string::npos) << "progress on stderr: " << run.err;
  const auto definition = fct::StudyCatalog::define(study, true, {"phantom"}).value();
  int trials = 0;
  for (const fct::StudyCondition& c : definition.conditions) trials += c.trials;
  const auto store = fct::TrialStore::open(out / "trials.csv");
  ASSERT_TRUE(store.ok()) << store.error();
  EXPECT_EQ(static_cast<int>(store.value().records().size()), trials);
  for (const fct::TrialRecord& r : store.value().records()) {
    EXPECT_EQ(r.status, "ok") << r.condition << ": " << r.reason;
    EXPECT_GT(r.drrs, 0);
  }
  int charts = 0;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().extension() != ".png") continue;
    ++charts;
    EXPECT_EQ(pngSize(entry.path()), (std::pair<std::uint32_t, std::uint32_t>{900, 560})) << entry.path();
  }
  EXPECT_EQ(charts, 2);
  EXPECT_NE(readText(out / "report.md").find(fmt::format("# Study `{}` (quick)", study)), std::string::npos);
}

}  // namespace

TEST(EvaluateCommand, QuickTable2WritesTrialsChartsAndTheTableBesideThePaper) {
  const auto out = fct::test::scratchDir() / "table2";
  runQuickStudy("table2", out);
  const std::string csv = readText(out / "trials.csv");
  EXPECT_EQ(csv.rfind("study,ct,condition,scenario,variant,views,trial,seed,initial_target_mm,initial_stre_mm,"
                      "stre_mean_mm,stre_max_mm,mtre_mm,rotation_deg,translation_mm,success,seconds,drrs,status,reason\n",
                      0),
            0u);
  const std::string report = readText(out / "report.md");
  EXPECT_NE(report.find("| phantom | realistic | 2.4 mm | 2 |"), std::string::npos) << report;
  EXPECT_NE(report.find("paper mean sTRE"), std::string::npos);
  EXPECT_NE(report.find("![Success rate by scenario](table2_success.png)"), std::string::npos);
}

TEST(EvaluateCommand, QuickCaptureStudyRuns) { runQuickStudy("capture", fct::test::scratchDir() / "capture"); }

TEST(EvaluateCommand, QuickAblationStudyRunsAndReportsTheTransgraphGap) {
  const auto out = fct::test::scratchDir() / "ablation";
  runQuickStudy("ablation", out);
  EXPECT_NE(readText(out / "report.md").find("Transgraph off: not measured"), std::string::npos);
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
}

TEST(EvaluateCommand, FullStudyWithoutTheSharedDataIsSkippedWithAMessage) {
  const auto dir = fct::test::scratchDir();
  const char* previous = std::getenv("FLUOROCT_DATA_DIR");
  const std::string saved = previous ? previous : "";
  ::setenv("FLUOROCT_DATA_DIR", (dir / "no-data").c_str(), 1);
  const auto run = fct::test::runCli(fmt::format("evaluate --study capture --out '{}'", (dir / "out").string()));
  if (previous) {
    ::setenv("FLUOROCT_DATA_DIR", saved.c_str(), 1);
  } else {
    ::unsetenv("FLUOROCT_DATA_DIR");
  }
  EXPECT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("evaluate: skipped: the full 'capture' study needs"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("pelvis_totalseg.nii.gz"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "trials.csv"));
}
