// StudyMerge: shard folders of the quick table2 study (made-up trials) merge into study order and into a folder that
// reads like one run; other setups, duplicate, missing and foreign trials are refused with the trials listed, and a
// folder whose finished trials the merge would replace is left as it is.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "Base/TextFile.h"
#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyMerge.h"
#include "Evaluation/StudySetupFile.h"
#include "Evaluation/StudyShard.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

fct::StudyDefinition quickTable2() { return fct::StudyCatalog::define("table2", true, {"phantom"}).value(); }

fct::TrialRecord trial(const std::string& condition, int t, fct::TrialStatus status = fct::TrialStatus::Ok) {
  fct::TrialRecord r;
  r.study = "table2";
  r.ct = "phantom";
  r.condition = condition;
  r.views = 3;
  r.trial = t;
  r.seed = 1 + t;
  r.error = fct::PoseError{0.1 + t, 0.2, 0.1, 0.1, 0.1};
  r.success = true;
  r.seconds = 0.5 + t;
  r.status = status;
  return r;
}

/// Writes a shard folder `dir` of `study` (shard k of n: its setup file) holding `records`, in the given order.
void writeShard(const fs::path& dir, const fct::StudyDefinition& study, int k, int n,
                const std::vector<fct::TrialRecord>& records) {
  fs::create_directories(dir);
  const fct::StudyShard shard = fct::StudyShard::create(study, k, n).value();
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "setup.txt", fct::StudySetupFile::text(study, {}, &shard)).ok());
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "trials.csv", fct::TrialStore::toCsv(records)).ok());
}

/// The three shard folders of the quick table2 study under `root`, each holding its trials in reverse order.
std::vector<fs::path> threeShards(const fs::path& root, const fct::StudyDefinition& study) {
  std::vector<fs::path> folders;
  for (int k = 1; k <= 3; ++k) {
    const fct::StudyShard shard = fct::StudyShard::create(study, k, 3).value();
    std::vector<fct::TrialRecord> records;
    for (const fct::StudyCondition& c : study.conditions) {
      for (int t = 0; t < c.trials; ++t) {
        if (shard.holds(c.name, t)) records.insert(records.begin(), trial(c.name, t));
      }
    }
    folders.push_back(root / ("shard-" + std::to_string(k)));
    writeShard(folders.back(), study, k, 3, records);
  }
  return folders;
}

}  // namespace

TEST(StudyMerge, ShardFoldersMergeInStudyOrderIntoAFolderThatReadsLikeOneRun) {
  const fs::path root = fct::test::scratchDir();
  const fct::StudyDefinition study = quickTable2();
  const std::string setup = fct::StudySetupFile::text(study, {});
  const std::vector<fs::path> folders = threeShards(root, study);
  // A trial cancelled in one shard and finished in another is not a duplicate.
  std::vector<fct::TrialRecord> third = fct::TrialStore::open(folders[2] / "trials.csv").value().records();
  third.push_back(trial("phantom/ideal", 0, fct::TrialStatus::Cancelled));
  writeShard(folders[2], study, 3, 3, third);

  const auto merged = fct::StudyMerge::collect(study, setup, folders);
  ASSERT_TRUE(merged.ok()) << merged.error();
  std::vector<fct::TrialRecord> expected;
  for (const fct::StudyCondition& c : study.conditions) {
    for (int t = 0; t < c.trials; ++t) expected.push_back(trial(c.name, t));
  }
  EXPECT_EQ(fct::TrialStore::toCsv(merged.value()), fct::TrialStore::toCsv(expected));

  const fs::path out = root / "merged";
  fs::create_directories(out);
  const fct::Status written = fct::StudyMerge::write(out, setup, merged.value());
  ASSERT_TRUE(written.ok()) << written.error();
  EXPECT_EQ(fct::test::readText(out / "trials.csv"), fct::TrialStore::toCsv(expected));
  EXPECT_EQ(fct::test::readText(out / "setup.txt"), setup);
  const fct::Status again = fct::StudyMerge::write(out, setup, merged.value());
  EXPECT_TRUE(again.ok()) << "a merge may be repeated into its own folder: " << again.error();
}

TEST(StudyMerge, MissingAndDuplicateTrialsAreRefusedListingThem) {
  const fs::path root = fct::test::scratchDir();
  const fct::StudyDefinition study = quickTable2();
  const std::string setup = fct::StudySetupFile::text(study, {});
  const std::vector<fs::path> folders = threeShards(root, study);

  const auto twoOfThree = fct::StudyMerge::collect(study, setup, {folders[0], folders[1]});
  ASSERT_FALSE(twoOfThree.ok());
  EXPECT_NE(twoOfThree.error().find("2 trial(s) of the study are in no shard folder: phantom/realistic trial 0; "
                                    "phantom/bad trial 1"),
            std::string::npos)
      << twoOfThree.error();

  writeShard(folders[2], study, 3, 3, {trial("phantom/realistic", 0), trial("phantom/bad", 1, fct::TrialStatus::Cancelled)});
  const auto cancelled = fct::StudyMerge::collect(study, setup, folders);
  ASSERT_FALSE(cancelled.ok());
  EXPECT_NE(cancelled.error().find("phantom/bad trial 1 (cancelled in " + folders[2].string() + ")"),
            std::string::npos)
      << cancelled.error();

  writeShard(folders[2], study, 3, 3,
             {trial("phantom/realistic", 0), trial("phantom/bad", 1), trial("phantom/ideal", 0), trial("phantom/ideal", 1)});
  const auto duplicates = fct::StudyMerge::collect(study, setup, folders);
  ASSERT_FALSE(duplicates.ok());
  EXPECT_NE(duplicates.error().find(fmt::format("2 trial(s) are finished in more than one shard folder: phantom/ideal "
                                                "trials 0 ({}, {}), 1 ({}, {})",
                                                folders[0].string(), folders[2].string(), folders[1].string(),
                                                folders[2].string())),
            std::string::npos)
      << duplicates.error();
}

TEST(StudyMerge, ShardsOfOtherSetupsOrStudiesAreRefusedNamingTheDifference) {
  const fs::path root = fct::test::scratchDir();
  const fct::StudyDefinition study = quickTable2();
  const std::vector<fs::path> folders = threeShards(root, study);
  fct::StudyDefinition other = study;
  other.setup.detector.cols = 96;
  const auto otherSetup = fct::StudyMerge::collect(other, fct::StudySetupFile::text(other, {}), folders);
  ASSERT_FALSE(otherSetup.ok());
  EXPECT_NE(otherSetup.error().find("shard folder " + folders[0].string() + " was run with other options than this "
                                    "merge ('detector: 96x128' for the merge, 'detector: 128x128' in the shard)"),
            std::string::npos)
      << otherSetup.error();

  const std::string setup = fct::StudySetupFile::text(study, {});
  writeShard(folders[1], study, 2, 3, {trial("phantom/ideal", 1), trial("phantom/huge", 0)});
  const auto foreign = fct::StudyMerge::collect(study, setup, folders);
  ASSERT_FALSE(foreign.ok());
  EXPECT_NE(foreign.error().find("holds trial 0 of condition 'phantom/huge'"), std::string::npos) << foreign.error();

  const auto twice = fct::StudyMerge::collect(study, setup, {folders[0], folders[0]});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().find("is given twice"), std::string::npos) << twice.error();
  const auto absent = fct::StudyMerge::collect(study, setup, {root / "no-such-shard"});
  ASSERT_FALSE(absent.ok());
  EXPECT_NE(absent.error().find("does not exist"), std::string::npos) << absent.error();
  fs::create_directories(root / "bare");
  const auto bare = fct::StudyMerge::collect(study, setup, {root / "bare"});
  ASSERT_FALSE(bare.ok());
  EXPECT_NE(bare.error().find("has no setup.txt"), std::string::npos) << bare.error();
  EXPECT_FALSE(fct::StudyMerge::collect(study, setup, {}).ok());
}

TEST(StudyMerge, AFolderWhoseFinishedTrialsTheMergeWouldReplaceIsLeftAsItIs) {
  const fs::path out = fct::test::scratchDir();
  const fct::StudyDefinition study = quickTable2();
  const std::string setup = fct::StudySetupFile::text(study, {});
  fct::TrialRecord mine = trial("phantom/ideal", 0);
  mine.seconds = 9.0;  // the same key, another run
  const std::string csv = fct::TrialStore::toCsv({mine, trial("phantom/ideal", 1)});
  ASSERT_TRUE(fct::TextFile::writeAtomically(out / "trials.csv", csv).ok());
  ASSERT_TRUE(fct::TextFile::writeAtomically(out / "setup.txt", setup).ok());
  const fct::Status replaced = fct::StudyMerge::write(out, setup, {trial("phantom/ideal", 0), trial("phantom/ideal", 1)});
  ASSERT_FALSE(replaced.ok());
  EXPECT_NE(replaced.error().find("holds 1 finished trial(s) that the shards do not hold as they are (phantom/ideal "
                                  "trial 0)"),
            std::string::npos)
      << replaced.error();
  fct::StudyDefinition other = study;
  other.setup.seed = 7;
  EXPECT_FALSE(fct::StudyMerge::write(out, fct::StudySetupFile::text(other, {}), {mine}).ok());
  EXPECT_EQ(fct::test::readText(out / "trials.csv"), csv);
  EXPECT_EQ(fct::test::readText(out / "setup.txt"), setup);
}
