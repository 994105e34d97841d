// The tracking study's parts: the frame store (round trip, resume by whole sequences, a malformed file), the report's
// figures from known frames, the catalog's conditions, and the run's refusals of bad conditions.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "Base/TextFile.h"
#include "Evaluation/TrackingFrameStore.h"
#include "Evaluation/TrackingReport.h"
#include "Evaluation/TrackingStudy.h"
#include "TestSupport.h"

namespace {

/// Frame `frame` of a 4-frame sequence of condition "ct/single-96" with the given error and time.
fct::TrackingFrameRecord frameRecord(int sequence, int frame, double stre_mm, double seconds,
                                     const char* status = "tracked") {
  fct::TrackingFrameRecord r;
  r.condition = "ct/single-96";
  r.ct = "ct";
  r.views = 1;
  r.sequence = sequence;
  r.frames = 4;
  r.frame = frame;
  r.seed = 1 + sequence;
  r.status = status;
  r.similarity = 0.9;
  r.seconds = seconds;
  r.cpuSeconds = 2 * seconds;
  r.drrs = 40;
  r.streMean_mm = stre_mm;
  r.streMax_mm = 2 * stre_mm;
  r.inPlane_mm = 0.5 * stre_mm;
  r.outOfPlane_mm = 0.8 * stre_mm;
  return r;
}

std::vector<fct::TrackingFrameRecord> sequenceRecords(int sequence) {
  return {frameRecord(sequence, 0, 0.2, 3.0), frameRecord(sequence, 1, 0.3, 0.1),
          frameRecord(sequence, 2, 2.0, 0.2, "recovered"), frameRecord(sequence, 3, 0.4, 0.1, "lost")};
}

fct::TrackingCondition singlePlane() {
  fct::TrackingCondition c;
  c.name = "ct/single-96";
  c.ct = "ct";
  c.viewCount = 1;
  c.detector_px = 96;
  return c;
}

}  // namespace

TEST(TrackingFrameStore, SequencesRoundTripAndOnlyCompleteUncancelledOnesAreDone) {
  const auto dir = fct::test::scratchDir() / "tracking-store";
  std::filesystem::create_directories(dir);
  auto store = fct::TrackingFrameStore::open(dir).value();
  EXPECT_FALSE(store.isDone("ct/single-96", 0));
  std::vector<fct::TrackingFrameRecord> first = sequenceRecords(0);
  first[1].inPlane_mm = std::numeric_limits<double>::quiet_NaN();
  first[1].reason = "a, \"quoted\" reason";
  ASSERT_TRUE(store.addSequence(first).ok());
  std::vector<fct::TrackingFrameRecord> cut = sequenceRecords(1);
  cut.resize(2);
  cut.back().cancelled = true;
  ASSERT_TRUE(store.addSequence(cut).ok());

  const auto reopened = fct::TrackingFrameStore::open(dir);
  ASSERT_TRUE(reopened.ok()) << reopened.error();
  ASSERT_EQ(reopened.value().records().size(), 6u);
  EXPECT_TRUE(reopened.value().isDone("ct/single-96", 0));
  EXPECT_FALSE(reopened.value().isDone("ct/single-96", 1)) << "a cancelled sequence runs again";
  const fct::TrackingFrameRecord& back = reopened.value().records()[1];
  EXPECT_TRUE(std::isnan(back.inPlane_mm));
  EXPECT_EQ(back.reason, first[1].reason);
  EXPECT_EQ(back.status, "tracked");
  EXPECT_DOUBLE_EQ(back.streMean_mm, 0.3);

  // Storing the sequence again replaces its frames.
  ASSERT_TRUE(store.addSequence(sequenceRecords(1)).ok());
  EXPECT_EQ(store.records().size(), 8u);
  EXPECT_TRUE(fct::TrackingFrameStore::open(dir).value().isDone("ct/single-96", 1));
  const std::string csv = fct::TextFile::read(dir / "frames.csv").value();
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 9);
}

TEST(TrackingFrameStore, MalformedFileIsRefusedNamingIt) {
  const auto dir = fct::test::scratchDir() / "tracking-store-bad";
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "frames.json", R"({"frames": [{"condition": "x"}]})").ok());
  const auto store = fct::TrackingFrameStore::open(dir);
  ASSERT_FALSE(store.ok());
  EXPECT_NE(store.error().find("frames.json"), std::string::npos) << store.error();
}

TEST(TrackingReport, FiguresOfKnownFrames) {
  std::vector<fct::TrackingFrameRecord> records = sequenceRecords(0);
  fct::TrackingFrameRecord other = frameRecord(0, 0, 9.0, 1.0);
  other.condition = "elsewhere";
  records.push_back(other);
  const fct::TrackingConditionStats s = fct::TrackingReport::statistics(singlePlane(), records);
  EXPECT_EQ(s.sequences, 1);
  EXPECT_EQ(s.frames, 4);
  EXPECT_NEAR(s.medianStre_mm, 0.35, 1e-12);  // of 0.2, 0.3, 0.4, 2.0
  EXPECT_NEAR(s.maxStre_mm, 2.0, 1e-12);
  EXPECT_NEAR(s.medianInPlane_mm, 0.175, 1e-12);
  EXPECT_NEAR(s.medianOutOfPlane_mm, 0.28, 1e-12);
  EXPECT_EQ(s.failures, 2) << "the 2 mm frame and the lost one";
  EXPECT_EQ(s.lost, 1);
  EXPECT_EQ(s.recoveries, 1);
  EXPECT_NEAR(s.framesPerSecond, 3.0 / 0.4, 1e-9) << "frame 0's registration is not a tracked frame";
  EXPECT_NEAR(s.cpuPerFrame_s, 0.8 / 3.0, 1e-9);
  EXPECT_NEAR(s.firstFrameSeconds, 3.0, 1e-12);

  fct::TrackingStudyDefinition study;
  study.conditions = {singlePlane()};
  const std::string report = fct::TrackingReport::markdown(study, records, {"a note"});
  EXPECT_NE(report.find("| ct/single-96 | single-plane | 96x96"), std::string::npos) << report;
  EXPECT_NE(report.find("NOT met"), std::string::npos);
  EXPECT_NE(report.find("- a note"), std::string::npos);
}

TEST(TrackingStudy, CatalogHasSinglePlaneAndBiplanePerCtWithAJerk) {
  const auto study = fct::TrackingStudy::define(false, {"pelvis", "head"});
  ASSERT_TRUE(study.ok()) << study.error();
  ASSERT_EQ(study.value().conditions.size(), 4u);
  EXPECT_EQ(study.value().conditions[0].name, "pelvis/single-512");
  EXPECT_EQ(study.value().conditions[0].viewCount, 1);
  EXPECT_EQ(study.value().conditions[1].name, "pelvis/biplane-256");
  EXPECT_EQ(study.value().conditions[1].viewCount, 2);
  EXPECT_GE(study.value().motion.jerkFrame, 1);
  EXPECT_LT(study.value().motion.jerkFrame, study.value().motion.frames);
  EXPECT_DOUBLE_EQ(study.value().motion.maxTranslation_mm, 15.0);
  EXPECT_DOUBLE_EQ(study.value().motion.maxRotation_deg, 10.0);
  EXPECT_FALSE(fct::TrackingStudy::define(true, {}).ok());
}

TEST(TrackingStudy, BadConditionsAreRefusedBeforeAnySequence) {
  const auto dir = fct::test::scratchDir() / "tracking-refused";
  std::filesystem::create_directories(dir);
  auto store = fct::TrackingFrameStore::open(dir).value();
  const std::vector<fct::StudyCt> cts{{"ct", fct::Volume::create(Eigen::Vector3i(4, 4, 4), Eigen::Vector3d::Ones(),
                                                                 Eigen::Vector3d::Zero()).value()}};
  const auto refused = [&](fct::TrackingStudyDefinition study, const char* word) {
    const auto run = fct::TrackingStudy::run(study, cts, store);
    ASSERT_FALSE(run.ok());
    EXPECT_NE(run.error().find(word), std::string::npos) << run.error();
  };
  fct::TrackingStudyDefinition study = fct::TrackingStudy::define(true, {"ct"}).value();
  fct::TrackingStudyDefinition bad = study;
  bad.conditions[0].ct = "missing";
  refused(bad, "no CT labelled 'missing'");
  bad = study;
  bad.conditions[0].viewCount = 3;
  refused(bad, "3 views");
  bad = study;
  bad.conditions[0].sequences = 0;
  refused(bad, "sequences");
  bad = study;
  bad.motion.frames = 0;
  refused(bad, "bone motion");
  bad = study;
  bad.preset = "nosuchpreset";
  refused(bad, "nosuchpreset");
  EXPECT_TRUE(store.records().empty());
}
