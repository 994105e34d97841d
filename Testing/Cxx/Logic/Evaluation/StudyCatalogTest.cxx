// StudyCatalog: every built-in study defines uniquely named conditions over the given CTs; unknown names are listed.
#include <gtest/gtest.h>

#include <set>

#include "Evaluation/StudyCatalog.h"

TEST(StudyCatalog, EveryStudyDefinesUniqueConditionsPerCt) {
  for (const std::string& name : fct::StudyCatalog::names()) {
    for (bool quick : {false, true}) {
      const auto study = fct::StudyCatalog::define(name, quick, {"pelvis", "head"});
      ASSERT_TRUE(study.ok()) << study.error();
      std::set<std::string> names, cts;
      for (const fct::StudyCondition& c : study.value().conditions) {
        EXPECT_TRUE(names.insert(c.name).second) << name << ": " << c.name;
        cts.insert(c.ct);
        EXPECT_GE(c.trials, 2);
        EXPECT_LE(c.initialLow_mm, c.initialHigh_mm);
      }
      EXPECT_EQ(cts.size(), 2u) << name;
      EXPECT_EQ(study.value().setup.preset, quick ? "fast" : fct::RegistrationSchedule::kDefaultPreset);
    }
  }
}

TEST(StudyCatalog, Table2CrossesTheThreeScenariosWithTheCts) {
  const auto study = fct::StudyCatalog::define("table2", false, {"pelvis", "head"}).value();
  ASSERT_EQ(study.conditions.size(), 6u);
  EXPECT_EQ(study.conditions[1].name, "pelvis/realistic");
  EXPECT_DOUBLE_EQ(study.conditions[1].sliceSpacing_mm, 2.4);
  EXPECT_DOUBLE_EQ(study.conditions[2].sliceSpacing_mm, 4.2);
  EXPECT_DOUBLE_EQ(study.conditions[0].sliceSpacing_mm, 0.0);
  EXPECT_EQ(study.conditions[0].viewCount, 3);
  EXPECT_DOUBLE_EQ(study.conditions[0].initialHigh_mm, 10.0);
}

TEST(StudyCatalog, CaptureBinsCoverZeroToAHundredMillimetresThirtyDegreesAndTheSetupStart) {
  const auto study = fct::StudyCatalog::define("capture", false, {"pelvis"}).value();
  ASSERT_EQ(study.conditions.size(), 34u);  // 3 measure sets x 10 distance bins, 3 rotation bins, the setup start
  EXPECT_DOUBLE_EQ(study.conditions.front().initialLow_mm, 0.0);
  EXPECT_DOUBLE_EQ(study.conditions[9].initialHigh_mm, 100.0);
  for (int b = 0; b < 3; ++b) {
    const fct::StudyCondition& c = study.conditions[30 + static_cast<std::size_t>(b)];
    EXPECT_EQ(c.start, fct::StudyStart::Rotation) << c.name;
    EXPECT_DOUBLE_EQ(c.rotationLow_deg, 10.0 * b) << c.name;
    EXPECT_DOUBLE_EQ(c.rotationHigh_deg, 10.0 * (b + 1)) << c.name;
    EXPECT_EQ(c.measures, fct::StudyMeasures::Both) << c.name;
  }
  EXPECT_EQ(study.conditions.back().start, fct::StudyStart::SupineSetup);
  EXPECT_EQ(study.conditions.back().name, "pelvis/both/supine-setup");
}

TEST(StudyCatalog, AblationWithSiddonReportsTheTransgraphGapInsteadOfARow) {
  const auto study = fct::StudyCatalog::define("ablation", true, {"phantom"}).value();
  for (const fct::StudyCondition& c : study.conditions) EXPECT_EQ(c.variant.find("transgraph"), std::string::npos);
  ASSERT_EQ(study.gaps.size(), 1u);
  EXPECT_NE(study.gaps[0].find("transgraph DRR method"), std::string::npos) << study.gaps[0];
  EXPECT_EQ(study.gaps[0].find("--"), std::string::npos) << "no command-line flag in Logic: " << study.gaps[0];
}

TEST(StudyCatalog, AblationWithTransgraphHasANoTransgraphRowAndNoGap) {
  const auto study = fct::StudyCatalog::define("ablation", true, {"phantom"}, fct::DrrMethod::Transgraph).value();
  EXPECT_EQ(study.setup.method, fct::DrrMethod::Transgraph);
  EXPECT_TRUE(study.gaps.empty());
  ASSERT_EQ(study.conditions.size(), 7u);
  EXPECT_EQ(study.conditions[0].variant, "full");
  EXPECT_FALSE(study.conditions[0].ablation.noTransgraph);
  EXPECT_EQ(study.conditions[1].variant, "no-transgraph");
  EXPECT_TRUE(study.conditions[1].ablation.noTransgraph);
}

TEST(StudyCatalog, UnknownStudyOrNoCtIsRejected) {
  const auto unknown = fct::StudyCatalog::define("table3", false, {"pelvis"});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("table2, capture, ablation, views"), std::string::npos) << unknown.error();
  EXPECT_FALSE(fct::StudyCatalog::define("table2", false, {}).ok());
}
