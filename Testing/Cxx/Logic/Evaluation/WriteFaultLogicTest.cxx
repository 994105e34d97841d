// The writers of Logic under a file-size limit (as on a full disk): the Transgraph cache file, the study's
// trials.csv and its report (charts and report.md) fail with a message naming the file and the cause, and the previous file stays.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "Drr/TransgraphCache.h"
#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyReport.h"
#include "Evaluation/TrialStore.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

fct::TrialRecord trial(int index) {
  fct::TrialRecord r;
  r.study = "table2";
  r.ct = "phantom";
  r.condition = "phantom/ideal";
  r.scenario = "ideal";
  r.trial = index;
  r.views = 3;
  r.error = fct::PoseError{0.1 + index, 0.5, 0.2, 0.1, 0.1};
  r.success = true;
  return r;
}

/// Checks a failed write's message and that `path` still holds `previous` with no temporary file beside it.
void expectRefusedAndKept(const fct::Status& status, const fs::path& path, const std::string& previous) {
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find(path.filename().string()), std::string::npos) << status.error();
  EXPECT_NE(status.error().find("File too large"), std::string::npos) << status.error();
  EXPECT_EQ(fct::test::readText(path), previous);
  for (const std::string& name : fct::test::folderEntries(path.parent_path())) {
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
  }
}

}  // namespace

TEST(WriteFault, FileSizeLimitKeepsThePreviousTransgraphCacheFile) {
  const fs::path file = fct::TransgraphCache::fileFor(fct::test::scratchDir(), 42);
  fct::TransgraphLayout layout;
  layout.counts = {2, 2, 2, 2};
  ASSERT_TRUE(fct::TransgraphCache::save(file, 42, layout, std::vector<float>(16, 1.0f)).ok());
  const std::string previous = fct::test::readText(file);
  layout.counts = {8, 8, 4, 4};
  fct::Status status = fct::Ok{};
  {
    const fct::test::FileSizeLimit limit(static_cast<long>(previous.size()));
    status = fct::TransgraphCache::save(file, 42, layout, std::vector<float>(layout.rayCount(), 2.0f));
  }
  expectRefusedAndKept(status, file, previous);
  layout.counts = {2, 2, 2, 2};
  EXPECT_TRUE(fct::TransgraphCache::load(file, 42, layout).ok()) << "the kept file still loads";
}

TEST(WriteFault, FileSizeLimitKeepsThePreviousTrialsCsvAndReport) {
  const fs::path dir = fct::test::scratchDir();
  auto store = fct::TrialStore::open(dir / "trials.csv");
  ASSERT_TRUE(store.ok()) << store.error();
  ASSERT_TRUE(store.value().add(trial(0)).ok());
  const auto study = fct::StudyCatalog::define("table2", true, {"phantom"}, fct::DrrMethod::Siddon);
  ASSERT_TRUE(study.ok()) << study.error();
  ASSERT_TRUE(fct::StudyReport::write(study.value(), store.value().records(), {}, dir).ok());
  const std::string previousCsv = fct::test::readText(dir / "trials.csv");
  std::map<std::string, std::string> previousReport;  // report.md and the charts
  for (const std::string& name : fct::test::folderEntries(dir)) {
    if (name != "trials.csv") previousReport[name] = fct::test::readText(dir / name);
  }
  ASSERT_GE(previousReport.size(), 2u);

  fct::Status added = fct::Ok{};
  fct::Status reported = fct::Ok{};
  {
    const fct::test::FileSizeLimit limit(static_cast<long>(previousCsv.size()) + 10);
    added = store.value().add(trial(1));
    auto written = fct::StudyReport::write(study.value(), store.value().records(), {std::string(4000, 'n')}, dir);
    reported = written ? fct::Status(fct::Ok{}) : fct::Status(fct::fail(written.error()));
  }
  expectRefusedAndKept(added, dir / "trials.csv", previousCsv);
  ASSERT_FALSE(reported.ok());
  EXPECT_NE(reported.error().find("File too large"), std::string::npos) << reported.error();
  for (const auto& [name, text] : previousReport) EXPECT_EQ(fct::test::readText(dir / name), text) << name;
  EXPECT_EQ(fct::test::folderEntries(dir).size(), previousReport.size() + 1) << "no temporary file is left";
  EXPECT_EQ(store.value().records().size(), 2u) << "the record is kept in memory for the next save";
  ASSERT_TRUE(store.value().add(trial(1)).ok()) << "without the limit the next save goes through";
  EXPECT_EQ(fct::TrialStore::open(dir / "trials.csv").value().records().size(), 2u);
}
