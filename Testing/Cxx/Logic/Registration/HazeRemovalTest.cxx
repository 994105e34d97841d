// Haze removal in a registration: RegistrationCase::removeHaze on the coarse phantom with a haze added to its X-rays,
// its undoing, its failure modes, and a stage that asks for it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "CoarsePhantomCase.h"
#include "Registration/Registration.h"

namespace {

/// Adds a smooth haze to every view's intensities: `fraction` of the reference level at the left edge, 1.5 times that
/// at the right.
void addHaze(fct::test::KnownTruthCase& c, double referenceIntensity, double fraction) {
  for (fct::RegistrationView& view : c.views) {
    for (int row = 0; row < view.xray.rows; ++row) {
      for (int col = 0; col < view.xray.cols; ++col) {
        view.xray.pixels[static_cast<std::size_t>(row) * view.xray.cols + col] +=
            static_cast<float>(referenceIntensity * fraction * (1.0 + 0.5 * col / view.xray.cols));
      }
    }
  }
}

/// The coarse phantom's three views with a haze of `fraction` (addHaze), prepared.
fct::test::PreparedCase hazyPhantom(double fraction) {
  fct::test::KnownTruthOptions options;
  options.cols = options.rows = 128;
  options.pixelSpacing_mm = 2.4;
  auto simulated = fct::test::simulateCase(fct::test::smallPhantom(), options);
  EXPECT_TRUE(simulated.ok()) << simulated.error();
  addHaze(simulated.value(), options.referenceIntensity, fraction);
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.cutFaceMargin_mm = -1.0;  // the X-rays are DRRs of this CT alone: no anatomy beyond its end faces
  auto registrationCase = fct::RegistrationCase::create(simulated.value().ct, simulated.value().views, caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  return fct::test::PreparedCase{std::move(simulated).value(), std::move(registrationCase).value()};
}

/// The correlation of view v's level-0 X-ray with the DRR at T over its valid pixels.
double correlationWithDrr(const fct::RegistrationCase& rc, std::size_t v, const Eigen::Isometry3d& T) {
  const fct::PyramidLevel& level = rc.prepared(v).pyramid.level(0);
  const fct::FloatImage drr = rc.renderer().render(rc.camera(v), T, 0).value();
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0, n = 0;
  for (const std::int32_t i : level.mask.pixelList()) {
    const double x = level.image.pixels[static_cast<std::size_t>(i)], y = drr.pixels[static_cast<std::size_t>(i)];
    sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y, n += 1;
  }
  return (sxy - sx * sy / n) / std::sqrt((sxx - sx * sx / n) * (syy - sy * sy / n));
}

}  // namespace

TEST(RegistrationCase, HazeRemovalStraightensTheXraysAndIsUndoneExactly) {
  fct::test::PreparedCase p = hazyPhantom(0.08);
  fct::RegistrationCase& rc = p.registrationCase;
  const Eigen::Isometry3d& T = p.simulated.T_truth;
  std::vector<std::vector<float>> prepared;
  std::vector<double> before;
  for (std::size_t v = 0; v < rc.viewCount(); ++v) {
    prepared.push_back(rc.prepared(v).pyramid.level(0).image.pixels);
    before.push_back(correlationWithDrr(rc, v, T));
  }
  auto removed = rc.removeHaze(T, 20.0);
  ASSERT_TRUE(removed.ok()) << removed.error();
  EXPECT_EQ(removed.value().viewsCorrected, 3);
  EXPECT_EQ(removed.value().drrs, 3);
  EXPECT_TRUE(removed.value().viewsKept.empty());
  EXPECT_GT(removed.value().largestHazeFraction, 0.05);
  std::vector<std::vector<float>> corrected;
  for (std::size_t v = 0; v < rc.viewCount(); ++v) {
    const double after = correlationWithDrr(rc, v, T);
    std::printf("view %zu: correlation with the DRR %.5f -> %.5f\n", v, before[v], after);
    EXPECT_LT(1.0 - after, 0.5 * (1.0 - before[v])) << "the haze bends the X-ray's line integrals away from the DRR's";
    corrected.push_back(rc.prepared(v).pyramid.level(0).image.pixels);
  }
  // A second removal starts again from the X-rays as prepared: the same images.
  ASSERT_TRUE(rc.removeHaze(T, 20.0).ok());
  for (std::size_t v = 0; v < rc.viewCount(); ++v) EXPECT_EQ(rc.prepared(v).pyramid.level(0).image.pixels, corrected[v]);
  ASSERT_TRUE(rc.restorePreparedXrays().ok());
  for (std::size_t v = 0; v < rc.viewCount(); ++v) EXPECT_EQ(rc.prepared(v).pyramid.level(0).image.pixels, prepared[v]);
}

TEST(RegistrationCase, HazeRemovalAtAPoseFarOffKeepsTheXraysAndSaysWhy) {
  fct::test::PreparedCase p = hazyPhantom(0.08);
  fct::RegistrationCase& rc = p.registrationCase;
  const std::vector<float> prepared = rc.prepared(0).pyramid.level(0).image.pixels;
  Eigen::Isometry3d away = p.simulated.T_truth;  // the CT out of every view: its DRRs are empty
  away.translation() += Eigen::Vector3d(0.0, 0.0, 2000.0);
  auto removed = rc.removeHaze(away, 20.0);
  ASSERT_TRUE(removed.ok()) << removed.error();
  EXPECT_EQ(removed.value().viewsCorrected, 0);
  ASSERT_EQ(removed.value().viewsKept.size(), 3u);
  EXPECT_NE(removed.value().viewsKept[0].find("view 'ap'"), std::string::npos) << removed.value().viewsKept[0];
  EXPECT_EQ(rc.prepared(0).pyramid.level(0).image.pixels, prepared);
  for (const double bad : {0.0, -5.0, std::nan("")}) {
    auto refused = rc.removeHaze(p.simulated.T_truth, bad);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().find("positive number of mm"), std::string::npos) << refused.error();
  }
  EXPECT_EQ(rc.prepared(0).pyramid.level(0).image.pixels, prepared);
}

TEST(Registration, AStageWithHazeRemovalReportsItAndTheNextRunComparesThePreparedXrays) {
  fct::test::PreparedCase p = hazyPhantom(0.02);
  fct::RegistrationCase& rc = p.registrationCase;
  const std::vector<float> prepared = rc.prepared(1).pyramid.level(0).image.pixels;
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin("fast").value();
  options.schedule.stages.back().hazeSigma_mm = 20.0;
  const Eigen::Isometry3d start = fct::test::startPose(rc, p.simulated.T_truth, 5.0, 3);
  auto result = fct::Registration::run(rc, start, options);
  ASSERT_TRUE(result.ok()) << result.error();
  const fct::StageReport& last = result.value().stages.back();
  EXPECT_EQ(last.hazeViewsCorrected, 3);
  EXPECT_NE(fct::stageStartNote(last).find("haze removed from 3 views"), std::string::npos) << fct::stageStartNote(last);
  EXPECT_NE(fct::stageStartNote(last).find("beam hardening up to"), std::string::npos) << fct::stageStartNote(last);
  EXPECT_EQ(result.value().stages.front().hazeViewsCorrected, 0) << "only the stage that asks for it";
  const double error = rc.bone()->meanDistance_mm(result.value().T_world_from_ct, p.simulated.T_truth);
  std::printf("from 5 mm with haze removal: %.3f mm\n", error);
  EXPECT_LT(error, 0.5);
  EXPECT_NE(rc.prepared(1).pyramid.level(0).image.pixels, prepared) << "the corrected X-rays stay until the next run";

  options.schedule.stages.back().hazeSigma_mm = 0.0;
  ASSERT_TRUE(fct::Registration::run(rc, start, options).ok());
  EXPECT_EQ(rc.prepared(1).pyramid.level(0).image.pixels, prepared);
}
