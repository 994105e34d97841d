// Registration: accuracy on known-truth cases (built-in phantom, clinical pelvis), the ablation switches, cancelling,
// and bad input. The X-rays are DRRs of the same renderer at a truth pose plus noise (RegistrationTestCase.h).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <numeric>
#include <string>

#include "Drr/TrilinearRayCaster.h"
#include "IO/Volume/VolumeFileIO.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationObjective.h"
#include "RegistrationTestCase.h"
#include "Similarity/NccSimilarity.h"
#include "Simulation/CtSliceDegrader.h"
#include "Simulation/PhantomBuilder.h"
#include "TestSupport.h"

namespace {

struct Prepared {
  fct::test::KnownTruthCase simulated;
  fct::RegistrationCase registrationCase;
};

Prepared preparePhantom(const fct::RegistrationCaseOptions& caseOptions = {},
                        const fct::test::KnownTruthOptions& truthOptions = {}) {
  auto simulated = fct::test::simulateCase(fct::test::smallPhantom(), truthOptions);
  EXPECT_TRUE(simulated.ok()) << simulated.error();
  auto registrationCase = fct::RegistrationCase::create(simulated.value().ct, simulated.value().views, caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  return Prepared{std::move(simulated).value(), std::move(registrationCase).value()};
}

/// A coarse 128x128 detector at 2.4 mm for the tests that only check that something runs.
fct::test::KnownTruthOptions coarseDetector() {
  fct::test::KnownTruthOptions options;
  options.cols = options.rows = 128;
  options.pixelSpacing_mm = 2.4;
  return options;
}

fct::RegistrationOptions fastOptions(std::uint32_t seed = 1, const std::string& preset = "fast") {
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin(preset).value();
  options.seed = seed;
  return options;
}

double errorOf(const Prepared& p, const Eigen::Isometry3d& T) {
  return p.registrationCase.bone()->meanDistance_mm(T, p.simulated.T_truth);
}

/// Runs `starts` registrations from 10 mm with `preset` and returns how many end within 0.5 mm; prints every error.
int successes(Prepared& p, int starts, std::uint32_t firstSeed, const std::string& preset = "fast") {
  int within = 0;
  for (int s = 0; s < starts; ++s) {
    const Eigen::Isometry3d start = fct::test::startPose(p.registrationCase, p.simulated.T_truth, 10.0, firstSeed + s);
    EXPECT_NEAR(errorOf(p, start), 10.0, 0.01);
    auto result = fct::Registration::run(p.registrationCase, start, fastOptions(firstSeed + s, preset));
    EXPECT_TRUE(result.ok()) << result.error();
    if (!result) continue;
    const double error = errorOf(p, result.value().T_world_from_ct);
    std::printf("start %2d: error %.3f mm, %ld DRRs, %.2f s\n", s, error, result.value().totalDrrs,
                result.value().totalSeconds);
    if (error < 0.5) ++within;
  }
  return within;
}

}  // namespace

TEST(Registration, FastPresetRecoversPhantomPoseFrom10mmIn19Of20Starts) {
  Prepared p = preparePhantom();
  EXPECT_GE(successes(p, 20, 1000), 19);
}

TEST(Registration, DefaultPresetRecoversPhantomPoseFrom10mmIn19Of20Starts) {
  Prepared p = preparePhantom();
  EXPECT_GE(successes(p, 20, 1000, fct::RegistrationSchedule::kDefaultPreset), 19);
}

TEST(Registration, FastPresetRecoversPelvisPoseFrom10mm) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  auto ct = fct::VolumeFileIO::read(fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz");
  ASSERT_TRUE(ct.ok()) << ct.error();
  auto simulated = fct::test::simulateCase(std::move(ct).value());
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  // The pelvis fills the lateral view up to the image border; the field-of-view detector sees no collimator edge there
  // and keeps the whole image (FieldOfViewDetectorTest).
  auto registrationCase = fct::RegistrationCase::create(simulated.value().ct, simulated.value().views);
  ASSERT_TRUE(registrationCase.ok()) << registrationCase.error();
  Prepared p{std::move(simulated).value(), std::move(registrationCase).value()};
  // Fewer starts than the phantom to bound the CI time (see README); the same criterion per start.
  constexpr int kStarts = 5;
  EXPECT_GE(successes(p, kStarts, 2000), kStarts - 1);
}

TEST(Registration, ResultReportsEveryStageAndNeverEndsWorseThanItStarted) {
  Prepared p = preparePhantom();
  const Eigen::Isometry3d start = fct::test::startPose(p.registrationCase, p.simulated.T_truth, 5.0, 7);
  auto result = fct::Registration::run(p.registrationCase, start, fastOptions());
  ASSERT_TRUE(result.ok()) << result.error();
  const auto& r = result.value();
  EXPECT_FALSE(r.cancelled);
  ASSERT_EQ(r.stages.size(), r.schedule.stages.size());
  long drrs = 0;
  for (const auto& stage : r.stages) {
    EXPECT_GE(stage.similarity, stage.startSimilarity) << stage.name;
    EXPECT_GT(stage.drrs, 0) << stage.name;
    EXPECT_EQ(stage.drrs % 3, 0) << "one DRR per view per evaluation";
    ASSERT_EQ(stage.keptFraction.size(), 3u);
    drrs += stage.drrs;
  }
  EXPECT_EQ(drrs, r.totalDrrs);
  EXPECT_EQ(r.stages[0].metric, fct::SimilarityMetric::Ncc);
  EXPECT_EQ(r.stages[1].metric, fct::SimilarityMetric::Vlnc);
  EXPECT_NEAR(r.stages[1].keptFraction[0], 0.15, 0.05) << "dynamic ROIs keep the preset's fraction";
  EXPECT_TRUE(r.T_initial.isApprox(start));
  EXPECT_LT(errorOf(p, r.T_world_from_ct), errorOf(p, start));
}

TEST(Registration, EachAblationSwitchStillRuns) {
  Prepared p = preparePhantom({}, coarseDetector());
  const Eigen::Isometry3d start = fct::test::startPose(p.registrationCase, p.simulated.T_truth, 3.0, 5);
  std::vector<std::pair<std::string, fct::RegistrationAblation>> switches(5);
  switches[0].first = "no-rois";
  switches[0].second.noDynamicRois = true;
  switches[1].first = "no-pyramid";
  switches[1].second.noPyramid = true;
  switches[2].first = "ncc-only";
  switches[2].second.nccOnly = true;
  switches[3].first = "local-only";
  switches[3].second.localOnly = true;
  switches[4].first = "cmaes";
  switches[4].second.cmaesForGenetic = true;
  for (const auto& [name, ablation] : switches) {
    SCOPED_TRACE(name);
    fct::RegistrationOptions options = fastOptions();
    // Bounded budgets keep the test quick; each switch only has to run and improve on the start.
    for (auto& stage : options.schedule.stages) stage.maxEvaluations = std::min(stage.maxEvaluations, 80);
    options.ablation = ablation;
    auto result = fct::Registration::run(p.registrationCase, start, options);
    ASSERT_TRUE(result.ok()) << result.error();
    EXPECT_NE(result.value().schedule.name.find(name), std::string::npos) << result.value().schedule.name;
    for (const auto& stage : result.value().schedule.stages) {
      if (ablation.noPyramid) {
        EXPECT_EQ(stage.level, 0);
      }
      if (ablation.nccOnly) {
        EXPECT_EQ(stage.metric, fct::SimilarityMetric::Ncc);
      }
      if (ablation.localOnly) {
        EXPECT_EQ(stage.search, fct::SearchStrategy::Local);
      }
      if (ablation.noDynamicRois) {
        EXPECT_EQ(stage.pixels.kind, fct::PixelSetKind::WholeImage);
      }
      if (ablation.cmaesForGenetic) {
        EXPECT_NE(stage.search, fct::SearchStrategy::Genetic);
      }
    }
    if (ablation.noDynamicRois) {
      EXPECT_GT(result.value().stages[1].keptFraction[0], 0.5);
    }
    if (ablation.cmaesForGenetic) {
      EXPECT_EQ(result.value().stages[0].search, fct::SearchStrategy::CmaEs);
    }
    EXPECT_LT(errorOf(p, result.value().T_world_from_ct), errorOf(p, start));
  }
}

TEST(RegistrationObjective, WholeImageSetKeepsAtMostMaxPixelsOnARegularGrid) {
  Prepared p = preparePhantom({}, coarseDetector());
  fct::RegistrationStage stage = fastOptions().schedule.stages.front();
  stage.level = 1;  // 64x64 pixels
  stage.pixels.maxPixels = 0;
  auto all = fct::RegistrationObjective::create(p.registrationCase, stage);
  stage.pixels.maxPixels = 1500;
  auto capped = fct::RegistrationObjective::create(p.registrationCase, stage);
  ASSERT_TRUE(all.ok() && capped.ok()) << all.error() << capped.error();
  for (std::size_t v = 0; v < 3; ++v) {
    const std::size_t n = all.value().renderedPixelCounts()[v];
    const std::size_t kept = capped.value().renderedPixelCounts()[v];
    EXPECT_GT(n, 1500u) << "the cap must bite";
    EXPECT_LE(kept, 1500u);
    EXPECT_GE(kept, n / 9) << "the smallest stride that fits (2 here)";
  }
  const double similarity = capped.value().similarity(p.simulated.T_truth).value();
  EXPECT_GT(similarity, 0.9) << "the subsampled NCC still sees the match";
}

TEST(Registration, OtherDrrMethodsRegisterToo) {
  // The DRR method is only an option of the case: the trilinear ray caster registers as well as Siddon.
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.drr.method = fct::DrrMethod::RayCast;
  Prepared p = preparePhantom(caseOptions, coarseDetector());
  EXPECT_EQ(p.registrationCase.renderer().methodName(), "raycast");
  const Eigen::Isometry3d start = fct::test::startPose(p.registrationCase, p.simulated.T_truth, 3.0, 9);
  auto result = fct::Registration::run(p.registrationCase, start, fastOptions());
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().drrMethod, "raycast");
  EXPECT_LT(errorOf(p, result.value().T_world_from_ct), 1.0);
}

TEST(Registration, CancelMidStageReturnsBestPoseSoFarMarkedCancelled) {
  Prepared p = preparePhantom();
  const Eigen::Isometry3d start = fct::test::startPose(p.registrationCase, p.simulated.T_truth, 10.0, 3);
  std::atomic<bool> cancel{false};
  int reports = 0;
  double best = -2.0;
  auto onProgress = [&](const fct::RegistrationProgress& progress) {
    ++reports;
    EXPECT_EQ(progress.stageCount, 4);
    EXPECT_GE(progress.bestSimilarity, best);
    best = progress.bestSimilarity;
    if (progress.stageIndex == 0 && progress.iteration == 60) cancel = true;
  };
  auto result = fct::Registration::run(p.registrationCase, start, fastOptions(), onProgress, &cancel);
  ASSERT_TRUE(result.ok()) << result.error();
  const auto& r = result.value();
  EXPECT_TRUE(r.cancelled);
  ASSERT_EQ(r.stages.size(), 1u) << "stopped in the first stage";
  EXPECT_TRUE(r.stages[0].cancelled);
  EXPECT_EQ(r.stages[0].evaluations, 60);
  EXPECT_EQ(reports, 60);
  EXPECT_GE(r.stages[0].similarity, r.stages[0].startSimilarity);
  EXPECT_LE(errorOf(p, r.T_world_from_ct), 10.0 + 1e-9) << "best so far, not worse than the start";
}

TEST(Registration, CancelBeforeStartKeepsInitialPose) {
  Prepared p = preparePhantom();
  const Eigen::Isometry3d start = fct::test::startPose(p.registrationCase, p.simulated.T_truth, 4.0, 3);
  std::atomic<bool> cancel{true};
  auto result = fct::Registration::run(p.registrationCase, start, fastOptions(), {}, &cancel);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().cancelled);
  EXPECT_TRUE(result.value().stages.empty());
  EXPECT_TRUE(result.value().T_world_from_ct.isApprox(start));
}

TEST(Registration, FailsClearlyWhenDrrAndXrayDoNotOverlap) {
  Prepared p = preparePhantom();
  Eigen::Isometry3d far = p.simulated.T_truth;
  far.translation() += Eigen::Vector3d(0.0, 0.0, 900.0);
  auto result = fct::Registration::run(p.registrationCase, far, fastOptions());
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("do not overlap"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("view '"), std::string::npos) << result.error();
}

TEST(Registration, FailsClearlyOnAPixelSetThatKeepsNothing) {
  Prepared p = preparePhantom();
  fct::RegistrationOptions options = fastOptions();
  options.schedule.stages[1].pixels.windowSize = 64;  // no complete valid 64x64 window in the 48x48 level
  auto result = fct::Registration::run(p.registrationCase, p.simulated.T_truth, options);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("stage '" + options.schedule.stages[1].name + "'"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("window"), std::string::npos) << result.error();

  options = fastOptions();
  options.schedule.stages[0].level = 5;
  result = fct::Registration::run(p.registrationCase, p.simulated.T_truth, options);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("level 5"), std::string::npos) << result.error();
}

TEST(RegistrationCase, FailsClearlyOnAConstantXrayAndAMismatchedDetector) {
  auto simulated = fct::test::simulateCase(fct::test::smallPhantom());
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  auto views = simulated.value().views;
  std::fill(views[1].xray.pixels.begin(), views[1].xray.pixels.end(), 1234.0f);
  auto constant = fct::RegistrationCase::create(simulated.value().ct, views);
  ASSERT_FALSE(constant.ok());
  EXPECT_NE(constant.error().find("view 'lateral'"), std::string::npos) << constant.error();
  EXPECT_TRUE(constant.error().find("constant") != std::string::npos ||
              constant.error().find("blank") != std::string::npos)
      << constant.error();

  views = simulated.value().views;
  views[2].xray.cols = 100;
  views[2].xray.pixels.resize(100 * 256);
  auto mismatched = fct::RegistrationCase::create(simulated.value().ct, views);
  ASSERT_FALSE(mismatched.ok());
  EXPECT_NE(mismatched.error().find("view 'oblique45'"), std::string::npos) << mismatched.error();

  auto none = fct::RegistrationCase::create(simulated.value().ct, {});
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().find("at least one"), std::string::npos) << none.error();
}

TEST(RegistrationCase, ReportsEachPreparationStepAndStopsWhenCancelled) {
  auto simulated = fct::test::simulateCase(fct::test::smallPhantom());
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  std::vector<std::string> stages;
  std::atomic<bool> cancel{false};
  const fct::ProgressMonitor monitor(
      [&](const fct::ProgressUpdate& update) {
        stages.push_back(update.stage);
        if (update.stage == "views") cancel.store(true);  // the user cancels once the views are under way
      },
      &cancel);
  auto prepared = fct::RegistrationCase::create(simulated.value().ct, simulated.value().views, {}, monitor);
  ASSERT_FALSE(prepared.ok());
  EXPECT_NE(prepared.error().find("cancelled"), std::string::npos) << prepared.error();
  EXPECT_EQ(stages, (std::vector<std::string>{"CT", "views"})) << "stopped at the next step";

  stages.clear();
  const fct::ProgressMonitor watching([&](const fct::ProgressUpdate& update) { stages.push_back(update.stage); },
                                      nullptr);
  ASSERT_TRUE(fct::RegistrationCase::create(simulated.value().ct, simulated.value().views, {}, watching).ok());
  EXPECT_EQ(stages.size(), simulated.value().views.size() + 2) << "the CT, each view and the bone surface";
}

TEST(RegistrationCase, RotatesAboutTheBoneCentroidWithScalesFromItsRadius) {
  Prepared p = preparePhantom();
  const auto& bone = *p.registrationCase.bone();
  EXPECT_TRUE(p.registrationCase.rotationCentre_ct_mm().isApprox(bone.centroid_ct_mm()));
  EXPECT_DOUBLE_EQ(p.registrationCase.boneRadius_mm(), bone.radius_mm());
  EXPECT_NEAR(p.registrationCase.scales()[0] * bone.radius_mm() * M_PI / 180.0, 1.0, 1e-9);
  EXPECT_EQ(p.registrationCase.scales()[3], 1.0);
  // Identity round trip: parameters of the truth give back the truth.
  const auto params = fct::RigidPose::fromTransform(p.simulated.T_truth, p.registrationCase.rotationCentre_ct_mm());
  ASSERT_TRUE(params.ok());
  EXPECT_TRUE(p.registrationCase.poseTransform(params.value().asVector()).isApprox(p.simulated.T_truth, 1e-12));
  // ROI selections: the requested fraction, repeatable.
  auto a = p.registrationCase.rois(0, 2, 7, 0.12);
  auto b = p.registrationCase.rois(0, 2, 7, 0.12);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.value().pixels, b.value().pixels);
  EXPECT_NEAR(a.value().keptFraction, 0.12, 0.04);
}

TEST(Registration, CtPyramidCoarsensTheCtOnlyWherePixelsSpanSeveralVoxels) {
  Prepared p = preparePhantom();  // 2 mm voxels; 192 px at 1.6 mm, source-isocentre 700 mm of 1000 mm
  fct::RegistrationCase& rc = p.registrationCase;
  const Eigen::Isometry3d& T = p.simulated.T_truth;
  // Level 0: a 1.6 mm pixel is 1.12 mm at the bone (< 1 voxel). Level 2: 6.4 mm -> 4.48 mm, two 2 mm voxels.
  EXPECT_EQ(rc.ctBlockSize(0, 0, T), Eigen::Vector3i(1, 1, 1));
  EXPECT_EQ(rc.ctBlockSize(0, 2, T), Eigen::Vector3i(2, 2, 2));
  EXPECT_EQ(rc.levelRenderer(0, 0, T).value(), &rc.renderer());
  const fct::DrrRenderer* coarse = rc.levelRenderer(0, 2, T).value();
  ASSERT_NE(coarse, &rc.renderer());
  EXPECT_EQ(coarse->volume().values().spacing_mm(), Eigen::Vector3d(4.0, 4.0, 4.0));
  EXPECT_EQ(rc.levelRenderer(1, 2, T).value(), coarse) << "views share a coarse CT of the same block";
  EXPECT_FALSE(rc.levelRenderer(0, rc.levelCount(), T).ok());
  // Every second column and row of level 2: each pixel stands for 8.96 mm at the bone, four 2 mm voxels.
  EXPECT_EQ(rc.ctBlockSize(0, 2, T, 2), Eigen::Vector3i(4, 4, 4));
  EXPECT_EQ(rc.levelRenderer(0, 2, T, 2).value()->volume().values().spacing_mm(), Eigen::Vector3d(8.0, 8.0, 8.0));

  // The coarse DRR is the full CT's DRR blurred by about one pixel: nearly the same image.
  const fct::FloatImage full = rc.renderer().render(rc.camera(0), T, 2).value();
  const fct::FloatImage blurred = coarse->render(rc.camera(0), T, 2).value();
  fct::PixelIndexList everyPixel(full.pixels.size());
  std::iota(everyPixel.begin(), everyPixel.end(), 0);
  EXPECT_GT(fct::NccSimilarity::create(full, everyPixel).value().evaluate(blurred).value(), 0.995);
  const double fullSum = std::accumulate(full.pixels.begin(), full.pixels.end(), 0.0);
  const double blurredSum = std::accumulate(blurred.pixels.begin(), blurred.pixels.end(), 0.0);
  EXPECT_NEAR(blurredSum / fullSum, 1.0, 0.02) << "the total attenuation seen is kept";
}

TEST(Registration, AStageNamingItsDrrMethodRendersWithItAtItsStep) {
  Prepared p = preparePhantom();  // Siddon case, 2 mm voxels
  fct::RegistrationCase& rc = p.registrationCase;
  const Eigen::Isometry3d& T = p.simulated.T_truth;
  EXPECT_EQ(rc.methodRenderer(fct::DrrMethod::Siddon).value(), &rc.renderer());
  const fct::DrrRenderer* oneVoxel = rc.methodRenderer(fct::DrrMethod::RayCast, 1.0).value();
  ASSERT_EQ(oneVoxel->methodName(), "raycast");
  EXPECT_EQ(dynamic_cast<const fct::TrilinearRayCaster&>(*oneVoxel).step_mm(), 2.0);
  EXPECT_EQ(rc.methodRenderer(fct::DrrMethod::RayCast, 1.0).value(), oneVoxel) << "made once, then kept";
  const fct::DrrRenderer* caseStep = rc.methodRenderer(fct::DrrMethod::RayCast).value();
  EXPECT_EQ(dynamic_cast<const fct::TrilinearRayCaster&>(*caseStep).step_mm(), 1.0) << "half the smallest spacing";
  // At level 2 the CT is coarsened to 4 mm voxels; the step in voxels follows them.
  const fct::DrrRenderer* coarse = rc.levelRenderer(0, 2, T, 1, fct::DrrMethod::RayCast, 1.0).value();
  EXPECT_EQ(coarse->volume().values().spacing_mm(), Eigen::Vector3d(4.0, 4.0, 4.0));
  EXPECT_EQ(dynamic_cast<const fct::TrilinearRayCaster&>(*coarse).step_mm(), 4.0);
  for (const double badStep : {-1.0, 11.0, std::nan("")}) {
    auto bad = rc.methodRenderer(fct::DrrMethod::RayCast, badStep);
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().find("step"), std::string::npos) << bad.error();
  }
  EXPECT_FALSE(rc.methodRenderer(fct::DrrMethod::Transgraph).ok());
  // The phantom's voxels are cubes: its slices are read as samples even where a stage asks for slab averages.
  EXPECT_EQ(rc.methodRenderer(fct::DrrMethod::RayCast, 1.0, fct::CtSliceModel::SlabAverages).value(), oneVoxel);
  // Made of 5 mm slices, they are slab averages, rendered deconvolved: another renderer, kept too.
  auto thickCt = fct::CtSliceDegrader::degrade(p.simulated.ct, 5.0);
  ASSERT_TRUE(thickCt.ok()) << thickCt.error();
  auto thickCase = fct::RegistrationCase::create(thickCt.value(), p.simulated.views);
  ASSERT_TRUE(thickCase.ok()) << thickCase.error();
  fct::RegistrationCase& thick = thickCase.value();
  const fct::DrrRenderer* slabs = thick.methodRenderer(fct::DrrMethod::RayCast, 1.0, fct::CtSliceModel::SlabAverages).value();
  EXPECT_NE(slabs, thick.methodRenderer(fct::DrrMethod::RayCast, 1.0).value());
  EXPECT_EQ(thick.methodRenderer(fct::DrrMethod::RayCast, 1.0, fct::CtSliceModel::SlabAverages).value(), slabs);
  const fct::DrrVolume deconvolved = thick.renderer().volume().sliceAveragesDeconvolved();
  EXPECT_EQ(slabs->volume().values().voxels(), deconvolved.values().voxels());
  const Eigen::Vector3i block = thick.ctBlockSize(0, 2, T);
  ASSERT_GT(block.maxCoeff(), 1);
  EXPECT_EQ(thick.levelRenderer(0, 2, T, 1, fct::DrrMethod::RayCast, 1.0, fct::CtSliceModel::SlabAverages)
                .value()
                ->volume()
                .values()
                .voxels(),
            deconvolved.coarsened(block).value().values().voxels())
      << "a coarse level averages the deconvolved slices";

  // The objective of such a stage renders every view with it, and still sees the match at the truth.
  fct::RegistrationStage stage = fastOptions().schedule.stages.back();
  stage.drrMethod = fct::DrrMethod::RayCast;
  stage.drrStep_voxels = 1.0;
  auto objective = fct::RegistrationObjective::create(rc, stage, true, T);
  ASSERT_TRUE(objective.ok()) << objective.error();
  EXPECT_EQ(objective.value().drrMethodName(), "raycast");
  Eigen::Isometry3d off = T;
  off.translation() += Eigen::Vector3d(3.0, 0.0, 0.0);
  EXPECT_GT(objective.value().similarity(T).value(), objective.value().similarity(off).value());
}

TEST(Registration, WithoutTheCtPyramidTheSameStartConvergesAsWell) {
  Prepared p = preparePhantom();
  const Eigen::Isometry3d start = fct::test::startPose(p.registrationCase, p.simulated.T_truth, 10.0, 77);
  fct::RegistrationOptions options = fastOptions(77);
  auto pyramid = fct::Registration::run(p.registrationCase, start, options);
  options.ablation.noCtPyramid = true;
  auto fullCt = fct::Registration::run(p.registrationCase, start, options);
  ASSERT_TRUE(pyramid.ok()) << pyramid.error();
  ASSERT_TRUE(fullCt.ok()) << fullCt.error();
  std::printf("CT pyramid %.3f mm in %.2f s; full CT %.3f mm in %.2f s\n", errorOf(p, pyramid.value().T_world_from_ct),
              pyramid.value().totalSeconds, errorOf(p, fullCt.value().T_world_from_ct), fullCt.value().totalSeconds);
  EXPECT_LT(errorOf(p, pyramid.value().T_world_from_ct), 0.5);
  EXPECT_LT(errorOf(p, fullCt.value().T_world_from_ct), 0.5);
  EXPECT_NE(fullCt.value().schedule.name.find("no-ct-pyramid"), std::string::npos) << fullCt.value().schedule.name;
  EXPECT_NE(pyramid.value().T_world_from_ct.matrix(), fullCt.value().T_world_from_ct.matrix())
      << "the switch changes the coarse levels' DRRs";
}

/// The one-view local stage of the depth-scale test: VLNC on ROIs at 1:4 with trilinear DRRs, BOBYQA with a tracking
/// frame's budget.
fct::RegistrationOptions oneViewLocalOptions(double depthScale) {
  fct::RegistrationStage stage;
  stage.name = "one-view-local";
  stage.metric = fct::SimilarityMetric::Vlnc;
  stage.level = 1;
  stage.pixels.kind = fct::PixelSetKind::Rois;
  stage.pixels.targetFraction = 0.2;
  stage.search = fct::SearchStrategy::Local;
  stage.maxEvaluations = stage.simplex.maxEvaluations = 80;
  stage.simplex.method = fct::LocalSearchMethod::Bobyqa;
  stage.simplex.initialStep = 0.5;
  stage.simplex.tolerance = 0.05;
  stage.simplex.restarts = 0;
  stage.depthScale = depthScale;
  stage.drrMethod = fct::DrrMethod::RayCast;  // a smooth similarity, as the tracker's frames have
  stage.drrStep_voxels = 1.0;
  fct::RegistrationOptions options;
  options.schedule.name = "one-view";
  options.schedule.stages = {stage};
  return options;
}

TEST(Registration, OneViewLocalSearchWithADepthScaleMovesTheDepthThatEqualUnitsLeave) {
  fct::test::KnownTruthOptions geometry;  // the studies' C-arm: one view sees depth only by a weak magnification
  geometry.sourceToIsocentre_mm = 1000.0;
  geometry.sourceToDetector_mm = 1500.0;
  auto simulated = fct::test::simulateCase(fct::test::smallPhantom(), geometry);
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.cutFaceMargin_mm = -1.0;  // the X-ray is a DRR of this CT alone: no anatomy beyond its end faces
  auto oneView = fct::RegistrationCase::create(simulated.value().ct, {simulated.value().views[0]}, caseOptions);
  ASSERT_TRUE(oneView.ok()) << oneView.error();
  fct::RegistrationCase& rc = oneView.value();
  const Eigen::Isometry3d& T_truth = simulated.value().T_truth;
  const Eigen::Vector3d centre_world_mm = T_truth * rc.rotationCentre_ct_mm();
  const Eigen::Vector3d ray = (centre_world_mm - rc.camera(0).sourcePosition_world_mm()).normalized();
  Eigen::Isometry3d start = T_truth;
  start.pretranslate(6.0 * ray);
  auto depthError_mm = [&](const Eigen::Isometry3d& T) {
    return (T * rc.rotationCentre_ct_mm() - centre_world_mm).dot(ray);
  };

  auto equalUnits = fct::Registration::run(rc, start, oneViewLocalOptions(1.0));
  auto scaled = fct::Registration::run(rc, start, oneViewLocalOptions(10.0));
  ASSERT_TRUE(equalUnits.ok()) << equalUnits.error();
  ASSERT_TRUE(scaled.ok()) << scaled.error();
  const double equalError = depthError_mm(equalUnits.value().T_world_from_ct);
  const double scaledError = depthError_mm(scaled.value().T_world_from_ct);
  std::printf("depth error from 6 mm along the ray: equal units %.2f mm (%d evaluations), depth scale 10 %.2f mm "
              "(%d)\n", equalError, equalUnits.value().stages[0].evaluations, scaledError,
              scaled.value().stages[0].evaluations);
  EXPECT_LT(std::abs(scaledError), 1.0);
  EXPECT_GT(std::abs(equalError), 3.0) << "equal units should stop before they move the depth";

  // With three views the scale is ignored: the same search, evaluation for evaluation.
  Prepared p = preparePhantom();
  auto threeEqual = fct::Registration::run(p.registrationCase, start, oneViewLocalOptions(1.0));
  auto threeScaled = fct::Registration::run(p.registrationCase, start, oneViewLocalOptions(10.0));
  ASSERT_TRUE(threeEqual.ok() && threeScaled.ok());
  EXPECT_EQ(threeEqual.value().T_world_from_ct.matrix(), threeScaled.value().T_world_from_ct.matrix());
}

TEST(Registration, ShiftPrealignmentMovesAFarStartOnceAndTheRunEndsAtTheTruth) {
  Prepared p = preparePhantom();
  fct::RegistrationOptions options = fastOptions(3, fct::RegistrationSchedule::kDefaultPreset);
  options.schedule.stages.front().shiftPrealign = true;
  options.schedule.stages.front().rotationSweep = {};
  for (const Eigen::Vector3d& offset_mm : {Eigen::Vector3d(60.0, -55.0, 50.0), Eigen::Vector3d(-70.0, 40.0, -55.0)}) {
    const Eigen::Isometry3d start = Eigen::Translation3d(offset_mm) * p.simulated.T_truth;
    auto result = fct::Registration::run(p.registrationCase, start, options);
    ASSERT_TRUE(result.ok()) << result.error();
    const auto& stages = result.value().stages;
    EXPECT_LT((stages.front().prealignShift_world_mm + offset_mm).norm(), 0.2 * offset_mm.norm())
        << "moved by " << stages.front().prealignShift_world_mm.transpose();
    for (std::size_t s = 1; s < stages.size(); ++s) {
      EXPECT_TRUE(stages[s].prealignShift_world_mm.isZero()) << "only the first stage pre-aligns";
    }
    EXPECT_LT(errorOf(p, result.value().T_world_from_ct), 0.5);
  }
}
