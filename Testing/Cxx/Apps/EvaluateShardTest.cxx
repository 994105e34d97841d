// fluoroct evaluate --shard / --merge and scripts/study-parallel.sh: the shards of a quick study, merged, give the
// trials (all but the times), report and charts of one unsharded run; a merge of mismatched or incomplete shards
// fails with one error line and writes nothing; bad shard options are refused before anything is written.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "Base/TextFile.h"
#include "Evaluation/TrialStore.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

/// The trials of DIR/trials.csv as CSV text with the two time columns zeroed (all that may differ between runs).
std::string trialsWithoutTimes(const fs::path& dir) {
  auto store = fct::TrialStore::open(dir / "trials.csv");
  EXPECT_TRUE(store.ok()) << store.error();
  if (!store) return {};
  std::vector<fct::TrialRecord> records = store.value().records();
  for (fct::TrialRecord& r : records) r.seconds = r.setupSeconds = 0.0;
  return fct::TrialStore::toCsv(records);
}

/// DIR/report.md without what may differ between runs of the same trials: the "written" date line, the output folder
/// (`out` is replaced by OUT) and the cells of the time columns of every table.
std::string reportWithoutTimes(const fs::path& dir) {
  std::string text = fct::test::readText(dir / "report.md");
  for (std::size_t at; (at = text.find(dir.string())) != std::string::npos;) text.replace(at, dir.string().size(), "OUT");
  std::istringstream lines(text);
  std::string out;
  std::vector<bool> timeColumn;  // of the current table, by cell index
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("- written ", 0) == 0) continue;
    if (line.rfind("|", 0) != 0) {
      timeColumn.clear();
      out += line + "\n";
      continue;
    }
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string cell; std::getline(row, cell, '|');) cells.push_back(cell);
    if (timeColumn.empty()) {
      for (const std::string& cell : cells) {
        timeColumn.push_back(cell.find("time") != std::string::npos || cell == " setup s ");
      }
    }
    for (std::size_t c = 0; c < cells.size(); ++c) out += (c < timeColumn.size() && timeColumn[c] ? "" : cells[c]) + "|";
    out += "\n";
  }
  return out;
}

/// Checks that the study in `merged` has the trials, report and (time-free) charts of the one run in `single`.
void expectSameStudy(const fs::path& merged, const fs::path& single, const std::vector<std::string>& charts) {
  EXPECT_EQ(trialsWithoutTimes(merged), trialsWithoutTimes(single));
  EXPECT_EQ(reportWithoutTimes(merged), reportWithoutTimes(single));
  EXPECT_EQ(fct::test::readText(merged / "setup.txt"), fct::test::readText(single / "setup.txt"));
  for (const std::string& chart : charts) EXPECT_EQ(fct::test::readText(merged / chart), fct::test::readText(single / chart)) << chart;
}

/// The options of a quick views study small enough for a unit test: one trial per view count, a 64x64 detector.
const std::string kTinyViews = "--study views --quick --trials 1 --detector 64x64 --pixel-mm 4.8";

}  // namespace

TEST(EvaluateCommand, ShardsOfAQuickStudyMergeIntoTheTrialsOfOneRun) {
  const fs::path dir = fct::test::scratchDir();
  for (int k = 1; k <= 2; ++k) {
    const auto shard =
        fct::test::runCli(fmt::format("evaluate {} --shard {}/2 --out '{}'", kTinyViews, k, (dir / std::to_string(k)).string()));
    ASSERT_EQ(shard.exitCode, 0) << shard.err;
    EXPECT_NE(shard.out.find(fmt::format("views shard {}/2: ran {} trials", k, k == 1 ? 2 : 1)), std::string::npos)
        << shard.out;
    EXPECT_NE(fct::test::readText(dir / std::to_string(k) / "setup.txt").find(fmt::format("\nshard: {}/2 of 3 trials\n", k)), std::string::npos);
  }
  const auto merge = fct::test::runCli(fmt::format("evaluate {} --merge '{}' '{}' --out '{}'", kTinyViews,
                                                   (dir / "1").string(), (dir / "2").string(), (dir / "merged").string()));
  ASSERT_EQ(merge.exitCode, 0) << merge.err;
  EXPECT_NE(merge.out.find("views: merged 3 trials from 2 shard folders"), std::string::npos) << merge.out;
  const auto single = fct::test::runCli(fmt::format("evaluate {} --out '{}'", kTinyViews, (dir / "single").string()));
  ASSERT_EQ(single.exitCode, 0) << single.err;
  expectSameStudy(dir / "merged", dir / "single", {"views_success.png", "views_stre.png"});

  // A shard folder resumes as its own shard only.
  const auto otherShard =
      fct::test::runCli(fmt::format("evaluate {} --shard 2/2 --out '{}'", kTinyViews, (dir / "1").string()));
  EXPECT_EQ(otherShard.exitCode, 2);
  EXPECT_NE(otherShard.err.find("'shard: 2/2 of 3 trials' now, 'shard: 1/2 of 3 trials' stored"), std::string::npos) << otherShard.err;
}

TEST(EvaluateCommand, MergeOfMismatchedOrIncompleteShardsFailsWithOneLineAndWritesNothing) {
  const fs::path dir = fct::test::scratchDir();
  // Shard 1 of 2 of the quick table2 study (made-up trials: ideal 0, realistic 0, bad 0), in its own folder.
  std::vector<fct::TrialRecord> records;
  for (const char* scenario : {"ideal", "realistic", "bad"}) {
    fct::TrialRecord r;
    r.study = "table2";
    r.ct = "phantom";
    r.condition = fmt::format("phantom/{}", scenario);
    r.views = 3;
    r.error = fct::PoseError{0.1, 0.2, 0.1, 0.1, 0.1};
    records.push_back(r);
  }
  fs::create_directories(dir / "s1");
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "s1" / "trials.csv", fct::TrialStore::toCsv(records)).ok());
  ASSERT_TRUE(fct::TextFile::writeAtomically(
                  dir / "s1" / "setup.txt",
                  "study: table2\nquick: yes\ncts: default\npreset: fast\ndetector: 128x128\npixel_mm: 2.4\nsid_mm: 1000\n"
                  "sad_mm: 700\nmethod: siddon\ntransgraph_spacing_mm: 6\nseed: 1\nxrays: per trial\nshard: 1/2 of 6 trials\n")
                  .ok());
  const auto merge = [&](const std::string& options) {
    return fct::test::runCli(fmt::format("evaluate --study table2 --quick {} --merge '{}' --out '{}'", options,
                                         (dir / "s1").string(), (dir / "out").string()));
  };
  const auto incomplete = merge("");
  EXPECT_EQ(incomplete.exitCode, 2);
  EXPECT_EQ(incomplete.err.rfind("error: --merge: 3 trial(s) of the study are in no shard folder: phantom/ideal trial "
                                 "1; phantom/realistic trial 1; phantom/bad trial 1; ",
                                 0),
            0u)
      << incomplete.err;
  EXPECT_EQ(std::count(incomplete.err.begin(), incomplete.err.end(), '\n'), 1) << incomplete.err;
  const auto mismatched = merge("--preset paper");
  EXPECT_EQ(mismatched.exitCode, 2);
  EXPECT_NE(mismatched.err.find("('preset: paper' for the merge, 'preset: fast' in the shard)"), std::string::npos)
      << mismatched.err;
  const auto duplicated = fct::test::runCli(fmt::format("evaluate --study table2 --quick --trials 1 --merge '{}' '{}' "
                                                        "--out '{}'",
                                                        (dir / "s1").string(), (dir / "s1" / ".").string(),
                                                        (dir / "out").string()));
  EXPECT_EQ(duplicated.exitCode, 2);
  EXPECT_NE(duplicated.err.find("is given twice"), std::string::npos) << duplicated.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "trials.csv"));
  EXPECT_FALSE(fs::exists(dir / "out" / "setup.txt"));
  EXPECT_FALSE(fs::exists(dir / "out" / "report.md"));

  // With --trials 1 this one folder holds the whole study.
  const auto whole = merge("--trials 1");
  ASSERT_EQ(whole.exitCode, 0) << whole.err;
  EXPECT_EQ(fct::TrialStore::open(dir / "out" / "trials.csv").value().records().size(), 3u);
}

TEST(EvaluateCommand, BadShardOptionsAreRefusedBeforeAnythingIsWritten) {
  const fs::path dir = fct::test::scratchDir();
  const auto run = [&](const std::string& options) {
    return fct::test::runCli(fmt::format("evaluate --study views --quick {} --out '{}'", options, (dir / "o").string()));
  };
  const auto notAShard = run("--shard 2");
  EXPECT_EQ(notAShard.exitCode, 2);
  EXPECT_EQ(notAShard.err.rfind("error: --shard: shard '2' is not of the form K/N", 0), 0u) << notAShard.err;
  const auto beyond = run("--shard 4/3");
  EXPECT_EQ(beyond.exitCode, 2);
  EXPECT_EQ(beyond.err.rfind("error: --shard: shard 4/3 does not exist", 0), 0u) << beyond.err;
  const auto both = run(fmt::format("--shard 1/2 --merge '{}'", dir.string()));
  EXPECT_EQ(both.exitCode, 2);
  EXPECT_NE(both.err.find("--shard excludes --merge"), std::string::npos) << both.err;
  EXPECT_FALSE(fs::exists(dir / "o"));
}

TEST(StudyParallelScript, QuickTable2AsThreeShardsGivesTheTrialsReportAndChartsOfOneRun) {
  if (std::system("command -v parallel > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "GNU parallel is not installed (Debian package 'parallel'; scripts/setup.sh installs it)";
  }
  const fs::path dir = fct::test::scratchDir();
  const auto sharded = fct::test::runCommand(fmt::format("FLUOROCT='{}' bash '{}' table2 3 --quick --out '{}'",
                                                         fct::test::cliPath().string(),
                                                         fct::test::scriptPath("study-parallel.sh").string(),
                                                         (dir / "sharded").string()));
  ASSERT_EQ(sharded.exitCode, 0) << sharded.out << sharded.err;
  EXPECT_NE(sharded.out.find("table2: merged 6 trials from 3 shard folders"), std::string::npos) << sharded.out;
  for (int k = 1; k <= 3; ++k) {
    EXPECT_EQ(fct::TrialStore::open(dir / "sharded" / fmt::format("shard-{}-of-3", k) / "trials.csv").value().records().size(),
              2u)
        << "shard " << k;
  }
  const auto single = fct::test::runCli(fmt::format("evaluate --study table2 --quick --out '{}'", (dir / "single").string()));
  ASSERT_EQ(single.exitCode, 0) << single.err;
  expectSameStudy(dir / "sharded", dir / "single", {"table2_stre.png", "table2_success.png"});
}
