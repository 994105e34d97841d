// StudyReport: condition statistics and the report's tables (table2 beside the paper, capture range).
#include <gtest/gtest.h>

#include <cmath>

#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyReport.h"

namespace {

fct::TrialRecord trial(const std::string& study, const std::string& condition, int index, double stre_mm,
                       double seconds, fct::TrialStatus status = fct::TrialStatus::Ok) {
  fct::TrialRecord r;
  r.study = study;
  r.condition = condition;
  r.trial = index;
  r.error = fct::PoseError{stre_mm, 2 * stre_mm, stre_mm, 0.1, 0.2};
  r.success = stre_mm < 2.0 && status == fct::TrialStatus::Ok;
  r.seconds = seconds;
  r.drrs = 1000;
  r.status = status;
  return r;
}

}  // namespace

TEST(StudyReport, StatisticsSeparateSuccessfulFailedAndCancelledTrials) {
  const std::vector<fct::TrialRecord> records{trial("t", "c", 0, 0.2, 3.0), trial("t", "c", 1, 0.4, 1.0),
                                              trial("t", "c", 2, 5.0, 2.0), trial("t", "c", 3, NAN, 0.0, fct::TrialStatus::Failed),
                                              trial("t", "c", 4, 0.1, 9.0, fct::TrialStatus::Cancelled)};
  const fct::ConditionStats s = fct::StudyReport::statistics(records);
  EXPECT_EQ(s.trials, 4);
  EXPECT_EQ(s.successes, 2);
  EXPECT_DOUBLE_EQ(s.successRate, 0.5);
  EXPECT_NEAR(s.streMean_mm, 0.3, 1e-12);
  EXPECT_NEAR(s.streMax_mm, 0.8, 1e-12);
  EXPECT_NEAR(s.streMeanAll_mm, (0.2 + 0.4 + 5.0) / 3, 1e-12);
  EXPECT_DOUBLE_EQ(s.medianSeconds, 2.0);
  EXPECT_DOUBLE_EQ(s.meanDrrs, 1000.0);
}

TEST(StudyReport, EmptyConditionHasNoNumbers) {
  const fct::ConditionStats s = fct::StudyReport::statistics({});
  EXPECT_EQ(s.trials, 0);
  EXPECT_TRUE(std::isnan(s.streMean_mm));
  EXPECT_TRUE(std::isnan(s.medianSeconds));
}

TEST(StudyReport, Table2ReportPutsThePaperBesideEachScenario) {
  const auto study = fct::StudyCatalog::define("table2", true, {"phantom"}).value();
  const std::string text = fct::StudyReport::markdown(study,
                                                      {trial("table2", "phantom/ideal", 0, 0.25, 2.0),
                                                       trial("table2", "phantom/bad", 0, NAN, 1.0, fct::TrialStatus::Failed)},
                                                      {"X-rays: test"});
  EXPECT_NE(text.find("| phantom | ideal | original | 1 | 100 % (1/1, ≥ 5 %) | 0.25 |"), std::string::npos) << text;
  EXPECT_NE(text.find("| phantom | bad | 4.2 mm | 1 | 0 % (0/1, ≥ 0 %) |"), std::string::npos) << text;
  EXPECT_NE(text.find("| 0.5 (0.7) |\n"), std::string::npos) << "the paper's bad row beside ours\n" << text;
  EXPECT_NE(text.find("| — |\n"), std::string::npos) << "no simulated ideal row in the paper\n" << text;
  EXPECT_NE(text.find("- X-rays: test"), std::string::npos);
  EXPECT_NE(text.find("## Failed trials"), std::string::npos);
}

TEST(StudyReport, CaptureReportGivesCumulativeFailureAndTheRange) {
  const auto study = fct::StudyCatalog::define("capture", true, {"phantom"}).value();
  std::vector<fct::TrialRecord> records;
  for (int t = 0; t < 2; ++t) {
    records.push_back(trial("capture", "phantom/both/00-10mm", t, 0.2, 1.0));
    records.push_back(trial("capture", "phantom/both/10-20mm", t, t == 0 ? 0.2 : 8.0, 1.0));
    records.push_back(trial("capture", "phantom/ncc-only/00-10mm", t, 0.2, 1.0));
    records.push_back(trial("capture", "phantom/ncc-only/10-20mm", t, 0.3, 1.0));
  }
  const std::string text = fct::StudyReport::markdown(study, records, {});
  EXPECT_NE(text.find("| 10–20 | 2 | 50 % (1/2, ≥ 3 %) | 25 % |"), std::string::npos) << text;
  EXPECT_NE(text.find("| phantom | both | 10 |"), std::string::npos) << text;
  EXPECT_NE(text.find("| phantom | ncc-only | ≥ 20 (every bin tested) |"), std::string::npos)
      << "no bin failed, so the range is only a lower bound\n" << text;
}

TEST(StudyReport, PaperFiguresAreStatedPlainlyWithTheirSource) {
  for (const char* name : {"table2", "capture"}) {
    const auto study = fct::StudyCatalog::define(name, true, {"phantom"}).value();
    const std::string text = fct::StudyReport::markdown(study, {}, {});
    EXPECT_NE(text.find("The paper reports"), std::string::npos) << name << "\n" << text;
    EXPECT_NE(text.find("(Knaan & Joskowicz, MICCAI 2003)"), std::string::npos) << name << "\n" << text;
    for (const char* history : {"issue", "quoted", "#5"}) {
      EXPECT_EQ(text.find(history), std::string::npos) << name << ": the report narrates ('" << history << "')\n" << text;
    }
  }
}
