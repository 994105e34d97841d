// ProjectionShiftAligner: a start translated far from the truth is brought back near it by the 2D shifts of its DRRs,
// in three views and (within the plane it sees) in one, also when matched on halved images and when the CT is longer
// than the field; a start at the truth stays; bad arguments fail.
#include <gtest/gtest.h>

#include <algorithm>

#include "Registration/ProjectionShiftAligner.h"
#include "CoarsePhantomCase.h"

namespace {

using Prepared = fct::test::PreparedCase;

Prepared prepare(std::size_t viewCount) { return fct::test::prepareCoarsePhantom(viewCount); }

/// The bone centre's distance (world mm) between two poses.
double centreDistance_mm(const Prepared& p, const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Vector3d centre_ct_mm = p.registrationCase.rotationCentre_ct_mm();
  return (a * centre_ct_mm - b * centre_ct_mm).norm();
}

}  // namespace

TEST(ProjectionShiftAligner, BringsAStartTranslated60mmBackWithinAFewMmInThreeViews) {
  Prepared p = prepare(3);
  const Eigen::Vector3d offset_mm(35.0, -30.0, 38.0);
  const Eigen::Isometry3d start = Eigen::Translation3d(offset_mm) * p.simulated.T_truth;
  ASSERT_NEAR(centreDistance_mm(p, start, p.simulated.T_truth), offset_mm.norm(), 1e-9);
  auto aligned = fct::ProjectionShiftAligner::align(p.registrationCase, start, 2);
  ASSERT_TRUE(aligned.ok()) << aligned.error();
  ASSERT_EQ(aligned.value().shift_px.size(), 3u);
  for (double peak : aligned.value().peakCorrelation) EXPECT_GT(peak, 0.8);
  EXPECT_LT(centreDistance_mm(p, aligned.value().T_world_from_ct, p.simulated.T_truth), 3.0)
      << "moved by " << aligned.value().translation_world_mm.transpose();
  EXPECT_TRUE(aligned.value().T_world_from_ct.linear().isApprox(start.linear(), 1e-12)) << "rotation untouched";
}

TEST(ProjectionShiftAligner, OneViewCorrectsTheShiftAcrossItsRayAndKeepsTheDepth) {
  Prepared p = prepare(1);
  const fct::Camera& camera = p.registrationCase.camera(0);
  const Eigen::Vector3d centre_world_mm = p.simulated.T_truth * p.registrationCase.rotationCentre_ct_mm();
  const Eigen::Vector3d ray = (centre_world_mm - camera.sourcePosition_world_mm()).normalized();
  const Eigen::Vector3d across = ray.unitOrthogonal();
  const Eigen::Isometry3d start = Eigen::Translation3d(30.0 * across) * p.simulated.T_truth;
  auto aligned = fct::ProjectionShiftAligner::align(p.registrationCase, start, 2);
  ASSERT_TRUE(aligned.ok()) << aligned.error();
  EXPECT_LT(centreDistance_mm(p, aligned.value().T_world_from_ct, p.simulated.T_truth), 3.0);
  EXPECT_LT(std::abs(aligned.value().translation_world_mm.dot(ray)), 3.0) << "depth barely moved";
}

TEST(ProjectionShiftAligner, AStartAtTheTruthStaysWithinAFractionOfAPixel) {
  Prepared p = prepare(3);
  auto aligned = fct::ProjectionShiftAligner::align(p.registrationCase, p.simulated.T_truth, 2);
  ASSERT_TRUE(aligned.ok()) << aligned.error();
  // A level-2 pixel is 9.6 mm on the detector, about 6.7 mm at the bone.
  EXPECT_LT(aligned.value().translation_world_mm.norm(), 2.0);
}

TEST(ProjectionShiftAligner, AMatchOnAHalvedImageBringsTheStartWithinAFewMm) {
  Prepared p = prepare(3);
  const Eigen::Isometry3d start = Eigen::Translation3d(35.0, -30.0, 38.0) * p.simulated.T_truth;
  auto aligned = fct::ProjectionShiftAligner::align(p.registrationCase, start, 1, 0.5, 0.2, 1);
  ASSERT_TRUE(aligned.ok()) << aligned.error();
  for (double peak : aligned.value().peakCorrelation) EXPECT_GT(peak, 0.8);
  // Matched at 32x32 (the level-1 image halved): a pixel is 9.6 mm on the detector, about 6.7 mm at the bone.
  EXPECT_LT(centreDistance_mm(p, aligned.value().T_world_from_ct, p.simulated.T_truth), 4.0)
      << "moved by " << aligned.value().translation_world_mm.transpose();
}

TEST(ProjectionShiftAligner, FindsAShiftAlongACtLongerThanTheField) {
  // A 115 mm detector (about 80 mm at the bone) inside the phantom's 160 x 160 x 120 mm body: every view's DRR fills
  // its whole image at every shift, so only the content that a shift brings into the field can tell where it lines up.
  fct::test::KnownTruthOptions options;
  options.cols = options.rows = 96;
  options.pixelSpacing_mm = 1.2;
  Prepared p = fct::test::preparePhantom(options, 3);
  for (std::size_t v = 0; v < p.registrationCase.viewCount(); ++v) {
    auto drr = p.registrationCase.levelRenderer(v, 1, p.simulated.T_truth, 1)
                   .value()
                   ->render(p.registrationCase.camera(v), p.simulated.T_truth, 1);
    ASSERT_TRUE(drr.ok()) << drr.error();
    EXPECT_GT(*std::min_element(drr.value().pixels.begin(), drr.value().pixels.end()), 0.0f) << "view " << v;
  }
  const Eigen::Vector3d alongTheBody_mm(0.0, 0.0, 30.0);
  const Eigen::Isometry3d start = Eigen::Translation3d(alongTheBody_mm) * p.simulated.T_truth;
  auto aligned = fct::ProjectionShiftAligner::align(p.registrationCase, start, 1);
  ASSERT_TRUE(aligned.ok()) << aligned.error();
  EXPECT_LT(centreDistance_mm(p, aligned.value().T_world_from_ct, p.simulated.T_truth), 4.0)
      << "moved by " << aligned.value().translation_world_mm.transpose();
}

TEST(ProjectionShiftAligner, RejectsABadLevelOrRange) {
  Prepared p = prepare(1);
  auto level = fct::ProjectionShiftAligner::align(p.registrationCase, p.simulated.T_truth, 9);
  ASSERT_FALSE(level.ok());
  EXPECT_NE(level.error().find("level 9"), std::string::npos) << level.error();
  for (double fraction : {0.0, 1.5, std::nan("")}) {
    auto range = fct::ProjectionShiftAligner::align(p.registrationCase, p.simulated.T_truth, 2, fraction);
    ASSERT_FALSE(range.ok()) << fraction;
    EXPECT_NE(range.error().find("fraction of the image"), std::string::npos) << range.error();
  }
  for (int halvings : {-1, 4}) {
    auto coarse = fct::ProjectionShiftAligner::align(p.registrationCase, p.simulated.T_truth, 1, 0.5, 0.2, halvings);
    ASSERT_FALSE(coarse.ok()) << halvings;
    EXPECT_NE(coarse.error().find("0 to 3 halvings"), std::string::npos) << coarse.error();
  }
}
