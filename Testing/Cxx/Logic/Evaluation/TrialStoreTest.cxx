// TrialStore: CSV round trip (quoting, NaN, status names), resume keys (ok/failed done, cancelled not), replacement,
// bad files.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "Base/TextFile.h"
#include "Evaluation/TrialStore.h"
#include "TestSupport.h"

namespace {

fct::TrialRecord record(const std::string& condition, int trial, fct::TrialStatus status) {
  fct::TrialRecord r;
  r.study = "table2";
  r.ct = "phantom";
  r.condition = condition;
  r.scenario = "ideal";
  r.variant = "full";
  r.views = 3;
  r.trial = trial;
  r.seed = 1 + trial;
  r.truthOffset_mm = 7.25;
  r.initialTarget_mm = 10.0;
  r.initialStre_mm = 10.0004;
  r.error = fct::PoseError{0.25, 0.5, 0.3, 0.2, 0.1};
  r.success = true;
  r.seconds = 2.5;
  r.drrs = 2900;
  r.status = status;
  return r;
}

}  // namespace

TEST(TrialStore, RoundTripsRecordsThroughCsvWithQuotesAndNaN) {
  fct::TrialRecord failed = record("phantom/bad", 1, fct::TrialStatus::Failed);
  failed.reason = "view 'ap': the DRR is empty, \"no overlap\"";
  failed.error.streMean_mm = std::nan("");
  failed.success = false;
  const std::string csv = fct::TrialStore::toCsv({record("phantom/ideal", 0, fct::TrialStatus::Ok), failed});
  const auto back = fct::TrialStore::fromCsv(csv, "test");
  ASSERT_TRUE(back.ok()) << back.error();
  ASSERT_EQ(back.value().size(), 2u);
  EXPECT_EQ(back.value()[0].condition, "phantom/ideal");
  EXPECT_NEAR(back.value()[0].error.streMax_mm, 0.5, 1e-9);
  EXPECT_EQ(back.value()[0].drrs, 2900);
  EXPECT_NEAR(back.value()[0].truthOffset_mm, 7.25, 1e-9);
  EXPECT_TRUE(back.value()[0].success);
  EXPECT_EQ(back.value()[1].reason, failed.reason);
  EXPECT_TRUE(std::isnan(back.value()[1].error.streMean_mm));
  EXPECT_FALSE(back.value()[1].success);
  EXPECT_EQ(fct::TrialStore::toCsv(back.value()), csv);
}

TEST(TrialStore, ReopenedStoreKnowsFinishedTrialsButNotCancelledOnes) {
  const auto path = fct::test::scratchDir() / "trials.csv";
  {
    auto store = fct::TrialStore::open(path);
    ASSERT_TRUE(store.ok()) << store.error();
    EXPECT_TRUE(store.value().records().empty());
    ASSERT_TRUE(store.value().add(record("phantom/ideal", 0, fct::TrialStatus::Ok)).ok());
    ASSERT_TRUE(store.value().add(record("phantom/ideal", 1, fct::TrialStatus::Failed)).ok());
    ASSERT_TRUE(store.value().add(record("phantom/ideal", 2, fct::TrialStatus::Cancelled)).ok());
  }
  auto reopened = fct::TrialStore::open(path);
  ASSERT_TRUE(reopened.ok()) << reopened.error();
  EXPECT_TRUE(reopened.value().isDone("table2", "phantom/ideal", 0));
  EXPECT_TRUE(reopened.value().isDone("table2", "phantom/ideal", 1));
  EXPECT_FALSE(reopened.value().isDone("table2", "phantom/ideal", 2));
  EXPECT_FALSE(reopened.value().isDone("capture", "phantom/ideal", 0));
  // Re-running the cancelled trial replaces its row.
  ASSERT_TRUE(reopened.value().add(record("phantom/ideal", 2, fct::TrialStatus::Ok)).ok());
  EXPECT_EQ(reopened.value().records().size(), 3u);
  EXPECT_TRUE(reopened.value().isDone("table2", "phantom/ideal", 2));
}

TEST(TrialStore, ForeignOrDamagedFilesAreRejectedNamingTheProblem) {
  const auto dir = fct::test::scratchDir();
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "other.csv", "a,b,c\n1,2,3\n").ok());
  const auto foreign = fct::TrialStore::open(dir / "other.csv");
  ASSERT_FALSE(foreign.ok());
  EXPECT_NE(foreign.error().find("header"), std::string::npos) << foreign.error();
  EXPECT_NE(foreign.error().find("use another output folder"), std::string::npos) << foreign.error();
  EXPECT_EQ(foreign.error().find("--"), std::string::npos) << "no command-line flag in Logic: " << foreign.error();

  std::string csv = fct::TrialStore::toCsv({record("phantom/ideal", 0, fct::TrialStatus::Ok)});
  csv += "table2,phantom,phantom/ideal,ideal,full,3,1,2,ten\n";
  const auto damaged = fct::TrialStore::fromCsv(csv, "trials.csv");
  ASSERT_FALSE(damaged.ok());
  EXPECT_NE(damaged.error().find("line 3"), std::string::npos) << damaged.error();
}

TEST(TrialStore, UnwritableFileFailsTheAdd) {
  const auto dir = fct::test::scratchDir();
  auto store = fct::TrialStore::open(dir / "missing-folder" / "trials.csv");
  ASSERT_TRUE(store.ok());
  const fct::Status added = store.value().add(record("phantom/ideal", 0, fct::TrialStatus::Ok));
  EXPECT_FALSE(added.ok());
  EXPECT_EQ(store.value().records().size(), 1u);
}

TEST(TrialStore, StatusIsWrittenAsItsNameAndReadBack) {
  for (const fct::TrialStatus status : {fct::TrialStatus::Ok, fct::TrialStatus::Failed, fct::TrialStatus::Cancelled}) {
    const std::string name(fct::trialStatusName(status));
    const auto parsed = fct::parseTrialStatus(name);
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    EXPECT_EQ(parsed.value(), status) << name;
  }
  EXPECT_EQ(fct::trialStatusName(fct::TrialStatus::Cancelled), "cancelled");
  const std::string csv = fct::TrialStore::toCsv({record("phantom/ideal", 0, fct::TrialStatus::Failed)});
  EXPECT_NE(csv.find(",failed,"), std::string::npos) << csv;
  const auto back = fct::TrialStore::fromCsv(csv, "trials.csv");
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back.value()[0].status, fct::TrialStatus::Failed);
}

TEST(TrialStore, UnknownStatusInAResumedFileIsAnErrorNamingLineAndText) {
  std::string csv = fct::TrialStore::toCsv({record("phantom/ideal", 0, fct::TrialStatus::Ok),
                                            record("phantom/ideal", 1, fct::TrialStatus::Ok)});
  const std::size_t at = csv.rfind(",ok,");
  ASSERT_NE(at, std::string::npos);
  csv.replace(at, 4, ",OK-ish,");
  const auto path = fct::test::scratchDir() / "trials.csv";
  ASSERT_TRUE(fct::TextFile::writeAtomically(path, csv).ok());
  const auto store = fct::TrialStore::open(path);
  ASSERT_FALSE(store.ok());
  EXPECT_NE(store.error().find("line 3"), std::string::npos) << store.error();
  EXPECT_NE(store.error().find("unknown trial status 'OK-ish'"), std::string::npos) << store.error();
  EXPECT_NE(store.error().find("ok, failed or cancelled"), std::string::npos) << store.error();
  EXPECT_FALSE(fct::parseTrialStatus("").ok());
  EXPECT_FALSE(fct::parseTrialStatus("Ok").ok());
}
