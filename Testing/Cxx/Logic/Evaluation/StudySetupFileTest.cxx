// StudySetupFile: the setup text of a study, written on the first run, accepted on a resume with the same options and
// refused, naming each difference, with other options or without a setup file; a shard's line, the one line a merge
// ignores.
#include <gtest/gtest.h>

#include "Base/TextFile.h"
#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudySetupFile.h"
#include "Evaluation/StudyShard.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using fct::StudySetupFile;

fct::StudyDefinition quickTable2() {
  return fct::StudyCatalog::define("table2", true, {"phantom"}, fct::DrrMethod::Siddon).value();
}

}  // namespace

TEST(StudySetupFile, TextSpellsOutEveryOptionThatChangesResults) {
  EXPECT_EQ(StudySetupFile::text(quickTable2(), {}),
            "study: table2\nquick: yes\ncts: default\npreset: fast\ndetector: 128x128\npixel_mm: 2.4\nsid_mm: 1000\n"
            "sad_mm: 700\nmethod: siddon\ntransgraph_spacing_mm: 6\nseed: 1\nxrays: per trial\n");
  const std::string text = StudySetupFile::text(quickTable2(), {"a.nrrd", "b.nii.gz"});
  EXPECT_NE(text.find("\ncts: a.nrrd b.nii.gz\n"), std::string::npos) << text;
}

TEST(StudySetupFile, APresetFileCountsByItsText) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path preset = dir / "mine.json";
  ASSERT_TRUE(fct::TextFile::writeAtomically(preset, "{\"name\": \"mine\"}").ok());
  fct::StudyDefinition study = quickTable2();
  study.setup.preset = preset.string();
  const std::string before = StudySetupFile::text(study, {});
  EXPECT_NE(before.find("preset: " + preset.string() + " (file, 16 bytes, FNV-1a "), std::string::npos) << before;
  ASSERT_TRUE(fct::TextFile::writeAtomically(preset, "{\"name\": \"MINE\"}").ok());
  EXPECT_NE(StudySetupFile::text(study, {}), before) << "same size, other text: another preset";
}

TEST(StudySetupFile, FirstRunWritesTheFileAndAResumeWithTheSameOptionsIsAccepted) {
  const fs::path dir = fct::test::scratchDir();
  const std::string text = StudySetupFile::text(quickTable2(), {});
  const fct::Status first = StudySetupFile::checkOrWrite(dir, text, false);
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_EQ(fct::test::readText(dir / "setup.txt"), text);
  const fct::Status resume = StudySetupFile::checkOrWrite(dir, text, true);
  EXPECT_TRUE(resume.ok()) << resume.error();
  EXPECT_EQ(fct::test::readText(dir / "setup.txt"), text);
}

TEST(StudySetupFile, AResumeWithOtherOptionsIsRefusedNamingEachDifference) {
  const fs::path dir = fct::test::scratchDir();
  fct::StudyDefinition study = quickTable2();
  const std::string stored = StudySetupFile::text(study, {});
  ASSERT_TRUE(StudySetupFile::checkOrWrite(dir, stored, false).ok());
  study.setup.detector.cols = 96;
  study.setup.seed = 5;
  const fct::Status other = StudySetupFile::checkOrWrite(dir, StudySetupFile::text(study, {}), true);
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.error().find(dir.string() + " holds trials run with other options ('detector: 96x128' now, "
                                              "'detector: 128x128' stored; 'seed: 5' now, 'seed: 1' stored)"),
            std::string::npos)
      << other.error();
  EXPECT_EQ(fct::test::readText(dir / "setup.txt"), stored) << "nothing written";

  const fct::Status shorter = StudySetupFile::checkOrWrite(dir, "study: table2\n", true);
  ASSERT_FALSE(shorter.ok());
  EXPECT_NE(shorter.error().find("'(none)' now, 'seed: 1' stored"), std::string::npos) << shorter.error();
}

TEST(StudySetupFile, TrialsWithoutASetupFileAreRefusedAndAnUnwritableFolderFails) {
  const fs::path dir = fct::test::scratchDir();
  const std::string text = StudySetupFile::text(quickTable2(), {});
  const fct::Status missing = StudySetupFile::checkOrWrite(dir, text, true);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("holds trials but no setup.txt"), std::string::npos) << missing.error();
  EXPECT_FALSE(fs::exists(dir / "setup.txt"));

  const fct::Status unwritable = StudySetupFile::checkOrWrite(dir / "no" / "such" / "folder", text, false);
  ASSERT_FALSE(unwritable.ok());
  EXPECT_NE(unwritable.error().find("setup.txt"), std::string::npos) << unwritable.error();
}

TEST(StudySetupFile, AShardRecordsItsLineAndAMergeIgnoresOnlyThatLine) {
  const fs::path dir = fct::test::scratchDir();
  const fct::StudyDefinition study = quickTable2();
  const std::string whole = StudySetupFile::text(study, {});
  const fct::StudyShard second = fct::StudyShard::create(study, 2, 3).value();
  EXPECT_EQ(StudySetupFile::text(study, {}, &second), whole + "shard: 2/3 of 6 trials\n");
  const fct::StudyShard oneOfOne = fct::StudyShard::create(study, 1, 1).value();
  EXPECT_EQ(StudySetupFile::text(study, {}, &oneOfOne), whole) << "shard 1/1 is the whole study";

  ASSERT_TRUE(StudySetupFile::checkOrWrite(dir, StudySetupFile::text(study, {}, &second), false).ok());
  const fct::Status same = StudySetupFile::checkShard(dir, whole);
  EXPECT_TRUE(same.ok()) << same.error();
  fct::StudyDefinition other = study;
  other.setup.preset = "paper";
  const fct::Status differs = StudySetupFile::checkShard(dir, StudySetupFile::text(other, {}));
  ASSERT_FALSE(differs.ok());
  EXPECT_NE(differs.error().find("('preset: paper' for the merge, 'preset: fast' in the shard)"), std::string::npos)
      << differs.error();
  const fct::Status missing = StudySetupFile::checkShard(dir / "none", whole);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("has no setup.txt"), std::string::npos) << missing.error();
}
