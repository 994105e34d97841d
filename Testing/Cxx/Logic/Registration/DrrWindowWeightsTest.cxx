// VLNC window weights from a DRR: RegistrationCase::weighWindowsWithDrr on the coarse phantom, their dropping, and a
// stage that asks for them.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "CoarsePhantomCase.h"
#include "Registration/Registration.h"

namespace {

/// The coarse phantom's three views at 128 x 128, prepared, with noise in its X-rays.
fct::test::PreparedCase noisyPhantom() {
  fct::test::KnownTruthOptions options;
  options.cols = options.rows = 128;
  options.pixelSpacing_mm = 2.4;
  options.noisePhotons = 2000.0;
  auto simulated = fct::test::simulateCase(fct::test::smallPhantom(), options);
  EXPECT_TRUE(simulated.ok()) << simulated.error();
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.cutFaceMargin_mm = -1.0;  // the X-rays are DRRs of this CT alone: no anatomy beyond its end faces
  auto registrationCase = fct::RegistrationCase::create(simulated.value().ct, simulated.value().views, caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  return fct::test::PreparedCase{std::move(simulated).value(), std::move(registrationCase).value()};
}

}  // namespace

TEST(RegistrationCase, WeighWindowsWithDrrKeepsEachViewsDrrPyramidUntilRestoredAndSharesTheHazeRemovalsDrrs) {
  fct::test::PreparedCase p = noisyPhantom();
  fct::RegistrationCase& rc = p.registrationCase;
  const Eigen::Isometry3d& T = p.simulated.T_truth;
  for (std::size_t v = 0; v < rc.viewCount(); ++v) EXPECT_EQ(rc.windowWeightImage(v, 0), nullptr) << "none by default";
  auto weighed = rc.weighWindowsWithDrr(T);
  ASSERT_TRUE(weighed.ok()) << weighed.error();
  EXPECT_EQ(weighed.value(), 3) << "one DRR per view";
  for (std::size_t v = 0; v < rc.viewCount(); ++v) {
    const fct::FloatImage drr = rc.renderer().render(rc.camera(v), T, 0).value();
    const fct::FloatImage* level0 = rc.windowWeightImage(v, 0);
    ASSERT_NE(level0, nullptr);
    EXPECT_EQ(level0->pixels, drr.pixels) << "level 0 is the DRR at the pose";
    EXPECT_NE(level0->pixels, rc.prepared(v).pyramid.level(0).image.pixels) << "not the X-ray";
    for (int level = 1; level < rc.levelCount(); ++level) {
      const fct::FloatImage* image = rc.windowWeightImage(v, level);
      ASSERT_NE(image, nullptr);
      EXPECT_EQ(image->cols, rc.prepared(v).pyramid.level(level).image.cols);
      EXPECT_EQ(image->rows, rc.prepared(v).pyramid.level(level).image.rows);
    }
  }
  EXPECT_EQ(rc.windowWeightImage(3, 0), nullptr) << "no such view";
  EXPECT_EQ(rc.windowWeightImage(0, rc.levelCount()), nullptr) << "no such level";
  EXPECT_EQ(rc.windowWeightImage(0, -1), nullptr);
  ASSERT_TRUE(rc.restorePreparedXrays().ok());
  for (std::size_t v = 0; v < rc.viewCount(); ++v) EXPECT_EQ(rc.windowWeightImage(v, 0), nullptr);

  // A haze removal at a pose renders its DRRs; window weights at the same pose then reuse them, at another render.
  auto removed = rc.removeHaze(T, 20.0);
  ASSERT_TRUE(removed.ok()) << removed.error();
  EXPECT_EQ(removed.value().drrs, 0) << "the weights' DRRs at the same pose";
  Eigen::Isometry3d moved = T;
  moved.translation() += Eigen::Vector3d(1.0, 0.0, 0.0);
  auto atMoved = rc.removeHaze(moved, 20.0);
  ASSERT_TRUE(atMoved.ok()) << atMoved.error();
  EXPECT_EQ(atMoved.value().drrs, 3);
  auto shared = rc.weighWindowsWithDrr(moved);
  ASSERT_TRUE(shared.ok()) << shared.error();
  EXPECT_EQ(shared.value(), 0) << "the haze removal's DRRs at the same pose";
  EXPECT_EQ(rc.windowWeightImage(1, 0)->pixels, rc.renderer().render(rc.camera(1), moved, 0).value().pixels);
}

TEST(Registration, AStageWithDrrWindowWeightsRendersThemAtItsStartAndTheNextRunDropsThem) {
  fct::test::PreparedCase p = noisyPhantom();
  fct::RegistrationCase& rc = p.registrationCase;
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin("fast").value();
  options.schedule.stages.back().vlncWeights = fct::VlncWeightSource::Drr;
  const Eigen::Isometry3d start = fct::test::startPose(rc, p.simulated.T_truth, 5.0, 3);
  auto result = fct::Registration::run(rc, start, options);
  ASSERT_TRUE(result.ok()) << result.error();
  const double error = rc.bone()->meanDistance_mm(result.value().T_world_from_ct, p.simulated.T_truth);
  std::printf("from 5 mm with DRR window weights in the last stage: %.3f mm\n", error);
  EXPECT_LT(error, 0.5);
  ASSERT_NE(rc.windowWeightImage(0, options.schedule.stages.back().level), nullptr) << "rendered at the stage's start";

  options.schedule.stages.back().vlncWeights = fct::VlncWeightSource::Xray;
  ASSERT_TRUE(fct::Registration::run(rc, start, options).ok());
  EXPECT_EQ(rc.windowWeightImage(0, 0), nullptr) << "a run starts from the X-rays' own weights";
}
