// StudyRunner and StudyXraySource: per-trial true poses, schedule variants, the registration CT per scenario, and bad
// study input (checked before any simulation or registration).
#include <gtest/gtest.h>

#include <set>

#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyRunner.h"
#include "Evaluation/StudyXraySource.h"
#include "Geometry/RigidPose.h"
#include "InitialPose/SetupPose.h"
#include "Simulation/StandardViews.h"
#include "TestSupport.h"

namespace {

fct::Volume tinyCt(double sliceSpacing_mm) {
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(12, 12, 12), Eigen::Vector3d(1.0, 1.0, sliceSpacing_mm)).value();
  for (int k = 3; k < 9; ++k)
    for (int j = 3; j < 9; ++j)
      for (int i = 3; i < 9; ++i) ct.at(i, j, k) = 1200.0f;
  return ct;
}

/// Cameras of the three standard views around the world origin.
std::vector<fct::Camera> standardCameras() {
  std::vector<fct::Camera> cameras;
  fct::StandardViewOptions options;
  options.count = 3;
  const auto views = fct::StandardViews::build(Eigen::Vector3d::Zero(), options);
  EXPECT_TRUE(views.ok()) << views.error();
  if (!views) return cameras;
  for (const fct::ViewSpec& view : views.value()) cameras.push_back(view.camera);
  return cameras;
}

}  // namespace

TEST(StudyRunner, StartPosesRotateAboutTheBoneCentreWithinTheBinOrComeFromTheSupineSetup) {
  const fct::Volume ct = tinyCt(1.0);
  const fct::BoneSurface bone = fct::BoneSurface::extract(ct).value();
  const Eigen::Isometry3d T_truth = fct::StudyRunner::truthPose(bone);
  const std::vector<fct::Camera> cameras = standardCameras();
  fct::StudyCondition c;
  c.start = fct::StudyStart::Rotation;
  c.rotationLow_deg = 20.0;
  c.rotationHigh_deg = 30.0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    double target_mm = 0.0;
    const Eigen::Isometry3d T_start = fct::StudyRunner::startPose(c, bone, T_truth, cameras, seed, target_mm).value();
    const double angle_deg =
        Eigen::AngleAxisd(T_start.linear() * T_truth.linear().transpose()).angle() * 180.0 / M_PI;
    EXPECT_GE(angle_deg, 20.0 - 1e-9) << "seed " << seed;
    EXPECT_LE(angle_deg, 30.0 + 1e-9) << "seed " << seed;
    // The bone centre stays where it is.
    EXPECT_LT((T_start * bone.centroid_ct_mm() - T_truth * bone.centroid_ct_mm()).norm(), 1e-9) << "seed " << seed;
    EXPECT_TRUE(std::isnan(target_mm));
  }
  c.start = fct::StudyStart::SupineSetup;
  double target_mm = 0.0;
  const Eigen::Isometry3d T_setup = fct::StudyRunner::startPose(c, bone, T_truth, cameras, 7, target_mm).value();
  const Eigen::Isometry3d T_expected = fct::SetupPose::supineAtIsocentre(bone.centroid_ct_mm(), cameras).value();
  EXPECT_TRUE(T_setup.isApprox(T_expected, 1e-12));
  EXPECT_TRUE(T_setup.linear().isIdentity(1e-12)) << "supine: CT axes along the world's";
  c.start = fct::StudyStart::SurfaceDistance;
  c.initialLow_mm = c.initialHigh_mm = 12.0;
  fct::StudyRunner::startPose(c, bone, T_truth, cameras, 7, target_mm).value();
  EXPECT_DOUBLE_EQ(target_mm, 12.0);
}

TEST(StudyRunner, TrialTruthPoseIsSeededAndMovesTheBoneWithinTheSpreadAboutItsCentre) {
  const fct::Volume ct = tinyCt(2.0);
  const fct::BoneSurface bone = fct::BoneSurface::extract(ct).value();
  const Eigen::Isometry3d T_truth = fct::StudyRunner::truthPose(bone);
  const Eigen::Vector3d centre_world_mm = T_truth * bone.centroid_ct_mm();
  std::set<std::uint32_t> xraySeeds;
  double largestMove_mm = 0.0;
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    const Eigen::Isometry3d T_trial = fct::StudyRunner::trialTruthPose(bone, seed);
    EXPECT_TRUE(T_trial.isApprox(fct::StudyRunner::trialTruthPose(bone, seed))) << "seeded";
    EXPECT_FALSE(T_trial.isApprox(fct::StudyRunner::trialTruthPose(bone, seed + 1))) << seed;
    // The move M = T_trial * T_truth^-1 about the bone centre: per-axis bounds on its parameters.
    const Eigen::Isometry3d M = T_trial * T_truth.inverse();
    const fct::PoseParameters move = fct::RigidPose::fromTransform(M, centre_world_mm).value();
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(std::abs(move.rotation_deg[a]), fct::StudyRunner::kTrialSpread_deg + 1e-9) << seed;
      EXPECT_LE(std::abs(move.translation_mm[a]), fct::StudyRunner::kTrialSpread_mm + 1e-9) << seed;
    }
    largestMove_mm = std::max(largestMove_mm, move.translation_mm.cwiseAbs().maxCoeff());
    // View v of a trial uses trialXraySeed + v: no two of 40 trials' 5 views share a noise seed.
    for (std::uint32_t v = 0; v < 5; ++v) xraySeeds.insert(fct::StudyRunner::trialXraySeed(seed) + v);
  }
  EXPECT_GT(largestMove_mm, 0.5 * fct::StudyRunner::kTrialSpread_mm) << "the spread is used";
  EXPECT_EQ(xraySeeds.size(), 200u);
}

TEST(StudyRunner, ScheduleForMeasuresKeepsOrReplacesEveryStageMetric) {
  const fct::RegistrationSchedule base = fct::RegistrationSchedule::builtin("fast").value();
  const fct::RegistrationSchedule both = fct::StudyRunner::scheduleFor(base, fct::StudyMeasures::Both);
  ASSERT_EQ(both.stages.size(), base.stages.size());
  for (std::size_t s = 0; s < base.stages.size(); ++s) EXPECT_EQ(both.stages[s].metric, base.stages[s].metric);
  for (const auto& [measures, metric] : {std::pair{fct::StudyMeasures::NccOnly, fct::SimilarityMetric::Ncc},
                                         std::pair{fct::StudyMeasures::VlncOnly, fct::SimilarityMetric::Vlnc}}) {
    const fct::RegistrationSchedule changed = fct::StudyRunner::scheduleFor(base, measures);
    for (const fct::RegistrationStage& stage : changed.stages) EXPECT_EQ(stage.metric, metric);
    EXPECT_EQ(changed.stages.front().pixels.kind, base.stages.front().pixels.kind);
  }
}

TEST(StudyRunner, BadStudiesFailBeforeAnyTrial) {
  auto study = fct::StudyCatalog::define("table2", true, {"phantom"}).value();
  std::vector<fct::StudyCt> cts{{"other", tinyCt(1.0)}};
  auto store = fct::TrialStore::open(fct::test::scratchDir() / "trials.csv").value();
  const auto unknownCt = fct::StudyRunner::run(study, cts, store);
  ASSERT_FALSE(unknownCt.ok());
  EXPECT_NE(unknownCt.error().find("no CT labelled 'phantom'"), std::string::npos) << unknownCt.error();

  cts.front().label = "phantom";
  fct::StudyRunOptions options;
  options.jobs = 0;
  EXPECT_FALSE(fct::StudyRunner::run(study, cts, store, options).ok());
  options.jobs = fct::StudyRunner::kMaxJobs + 1;
  const auto tooMany = fct::StudyRunner::run(study, cts, store, options);
  ASSERT_FALSE(tooMany.ok());
  EXPECT_NE(tooMany.error().find("parallel jobs must be between 1 and 64, got 65"), std::string::npos) << tooMany.error();
  EXPECT_EQ(tooMany.error().find("--"), std::string::npos) << "no command-line flag in Logic: " << tooMany.error();
  study.conditions.front().viewCount = 6;
  const auto sixViews = fct::StudyRunner::run(study, cts, store);
  ASSERT_FALSE(sixViews.ok());
  EXPECT_NE(sixViews.error().find("6 views"), std::string::npos) << sixViews.error();
  study.conditions.front().viewCount = 3;
  study.conditions.front().start = fct::StudyStart::Rotation;
  study.conditions.front().rotationLow_deg = 30.0;
  study.conditions.front().rotationHigh_deg = 10.0;
  const auto badRotation = fct::StudyRunner::run(study, cts, store);
  ASSERT_FALSE(badRotation.ok());
  EXPECT_NE(badRotation.error().find("start rotation range 30..10 deg"), std::string::npos) << badRotation.error();
  EXPECT_TRUE(store.records().empty());
}

TEST(StudyXraySource, RegistrationCtIsTheOriginalUnlessTheScenarioAsksForCoarserSlices) {
  const fct::Volume fine = tinyCt(1.0);
  const auto same = fct::StudyXraySource::registrationCt(fine, 0.0);
  ASSERT_TRUE(same.ok()) << same.error();
  EXPECT_EQ(same.value().dims(), fine.dims());
  const auto coarse = fct::StudyXraySource::registrationCt(fine, 2.4);
  ASSERT_TRUE(coarse.ok()) << coarse.error();
  EXPECT_DOUBLE_EQ(coarse.value().spacing_mm().z(), 2.4);
  EXPECT_LT(coarse.value().dims().z(), fine.dims().z());

  const fct::Volume thick = tinyCt(3.0);
  EXPECT_EQ(fct::StudyXraySource::effectiveSliceSpacing_mm(thick, 2.4), 0.0);
  EXPECT_EQ(fct::StudyXraySource::registrationCt(thick, 2.4).value().dims(), thick.dims());
  EXPECT_FALSE(fct::StudyXraySource::registrationCt(fine, -1.0).ok());
}

TEST(StudyRunner, NotesSayWhenAScenarioKeepsTheOriginalCt) {
  const auto study = fct::StudyCatalog::define("table2", false, {"pelvis"}).value();
  const std::vector<std::string> notes = fct::StudyRunner::notes(study, {{"pelvis", tinyCt(3.0)}});
  // X-ray model, per-trial X-rays, DRR method, the default preset's trilinear final stage, 'realistic' (2.4 mm <
  // 3 mm); 'bad' (4.2 mm) is resampled.
  ASSERT_EQ(notes.size(), 5u);
  EXPECT_EQ(notes[0].rfind("X-rays: FluoroscopySimulator", 0), 0u);
  EXPECT_EQ(notes[1].rfind("every trial registers against X-rays of its own", 0), 0u) << notes[1];
  EXPECT_EQ(notes[2], "DRRs: siddon method");
  EXPECT_EQ(notes[3], "the preset's stage 'vlnc-rois-1:4' renders its DRRs with the raycast method (a sample every 1 "
                      "voxel), a thick-slice CT's slices read as averages over their thickness, whatever the study's");
  EXPECT_NE(notes[4].find("scenario 'realistic'"), std::string::npos) << notes[4];
  auto oneSet = study;
  oneSet.setup.xraysPerTrial = false;
  EXPECT_EQ(fct::StudyRunner::notes(oneSet, {{"pelvis", tinyCt(3.0)}})[1].rfind("every trial of a CT registers against "
                                                                                 "one X-ray set", 0),
            0u);
}

TEST(StudyRunner, ResolveSliceSpacingsGivesTheSpacingActuallyUsed) {
  auto study = fct::StudyCatalog::define("table2", false, {"pelvis", "missing"}).value();
  fct::StudyRunner::resolveSliceSpacings(study, {{"pelvis", tinyCt(3.0)}});
  ASSERT_EQ(study.conditions.size(), 6u);  // pelvis ideal, realistic, bad; missing ideal, realistic, bad
  EXPECT_DOUBLE_EQ(study.conditions[0].usedSliceSpacing_mm, 3.0);  // ideal: the original
  EXPECT_DOUBLE_EQ(study.conditions[1].usedSliceSpacing_mm, 3.0);  // realistic asks 2.4 mm: the original is coarser
  EXPECT_DOUBLE_EQ(study.conditions[2].usedSliceSpacing_mm, 4.2);  // bad: resampled
  EXPECT_EQ(study.conditions[3].usedSliceSpacing_mm, 0.0);         // no such CT: left unresolved
}
