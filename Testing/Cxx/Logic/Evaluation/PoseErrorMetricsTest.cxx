// PoseErrorMetrics: identities (identical poses, pure translation, pure rotation about the bone centre), the capture
// range rule, and a CT without bone.
#include <gtest/gtest.h>

#include <cmath>

#include "Evaluation/PoseErrorMetrics.h"
#include "Geometry/RigidPose.h"

namespace {

/// A 40 mm soft-tissue cube holding an off-centre bone block (1000 HU), 2 mm voxels.
fct::Volume boneBlock() {
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(20, 20, 20), Eigen::Vector3d(2.0, 2.0, 2.0),
                                       Eigen::Vector3d(-10.0, 5.0, 30.0))
                       .value();
  for (int k = 4; k < 16; ++k)
    for (int j = 6; j < 12; ++j)
      for (int i = 3; i < 17; ++i) ct.at(i, j, k) = 1000.0f;
  return ct;
}

Eigen::Isometry3d somePose() {
  fct::PoseParameters p;
  p.rotation_deg = Eigen::Vector3d(10.0, -20.0, 5.0);
  p.translation_mm = Eigen::Vector3d(3.0, 4.0, -7.0);
  return fct::RigidPose::toTransform(p, Eigen::Vector3d(1.0, 2.0, 3.0));
}

}  // namespace

TEST(PoseErrorMetrics, IdenticalPosesGiveZeroErrors) {
  const auto metrics = fct::PoseErrorMetrics::create(boneBlock());
  ASSERT_TRUE(metrics.ok()) << metrics.error();
  const fct::PoseError e = metrics.value().measure(somePose(), somePose());
  EXPECT_EQ(e.streMean_mm, 0.0);
  EXPECT_EQ(e.streMax_mm, 0.0);
  EXPECT_EQ(e.mtre_mm, 0.0);
  EXPECT_NEAR(e.rotation_deg, 0.0, 1e-6);
  EXPECT_EQ(e.translation_mm, 0.0);
  EXPECT_TRUE(fct::PoseErrorMetrics::isSuccess(e));
  EXPECT_EQ(metrics.value().regionPoints_ct_mm().size(), 1000u);
}

TEST(PoseErrorMetrics, PureTranslationGivesItsLengthForEveryDistance) {
  const auto metrics = fct::PoseErrorMetrics::create(boneBlock()).value();
  const Eigen::Vector3d shift_mm = Eigen::Vector3d(1.0, -2.0, 2.0) * 1.5;  // 4.5 mm
  Eigen::Isometry3d T_estimate = somePose();
  T_estimate.pretranslate(shift_mm);
  const fct::PoseError e = metrics.measure(T_estimate, somePose());
  EXPECT_NEAR(e.streMean_mm, 4.5, 1e-9);
  EXPECT_NEAR(e.streMax_mm, 4.5, 1e-9);
  EXPECT_NEAR(e.mtre_mm, 4.5, 1e-9);
  EXPECT_NEAR(e.translation_mm, 4.5, 1e-9);
  EXPECT_NEAR(e.rotation_deg, 0.0, 1e-6);
  EXPECT_FALSE(fct::PoseErrorMetrics::isSuccess(e));
}

TEST(PoseErrorMetrics, RotationAboutTheBoneCentreGivesItsAngleAndNoCentreMotion) {
  const auto metrics = fct::PoseErrorMetrics::create(boneBlock()).value();
  const Eigen::Vector3d centre_ct_mm = metrics.surface().centroid_ct_mm();
  fct::PoseParameters turn;
  turn.rotation_deg = Eigen::Vector3d(0.0, 0.0, 3.0);
  const Eigen::Isometry3d T_estimate = fct::RigidPose::toTransform(turn, centre_ct_mm);
  const fct::PoseError e = metrics.measure(T_estimate, Eigen::Isometry3d::Identity());
  EXPECT_NEAR(e.rotation_deg, 3.0, 1e-9);
  EXPECT_NEAR(e.translation_mm, 0.0, 1e-9);
  EXPECT_GT(e.streMax_mm, e.streMean_mm);
  EXPECT_GT(e.streMean_mm, 0.0);
}

TEST(PoseErrorMetrics, CaptureRangeEndsAtTheFirstBinBelow95Percent) {
  using Bin = fct::InitialDistanceBin;
  EXPECT_EQ(fct::PoseErrorMetrics::captureRange_mm({Bin{0, 10, 20, 20}, Bin{10, 20, 20, 19}, Bin{20, 30, 20, 18},
                                                    Bin{30, 40, 20, 20}}),
            20.0);  // 18/20 = 90 % ends the range, the later 100 % bin does not count
  EXPECT_EQ(fct::PoseErrorMetrics::captureRange_mm({Bin{0, 10, 10, 9}}), 0.0);
  EXPECT_EQ(fct::PoseErrorMetrics::captureRange_mm({Bin{0, 10, 4, 4}, Bin{10, 20, 0, 0}, Bin{20, 30, 4, 4}}), 10.0);
  EXPECT_EQ(fct::PoseErrorMetrics::captureRange_mm({}), 0.0);
}

TEST(PoseErrorMetrics, CtWithoutBoneIsRejectedWithItsValueRange) {
  const fct::Volume water = fct::Volume::create(Eigen::Vector3i(8, 8, 8), Eigen::Vector3d(1, 1, 1)).value();
  const auto metrics = fct::PoseErrorMetrics::create(water);
  ASSERT_FALSE(metrics.ok());
  EXPECT_NE(metrics.error().find("bone threshold"), std::string::npos) << metrics.error();
}

TEST(PoseErrorMetrics, DepthShiftAlongTheViewingRayIsAllOutOfPlane) {
  const auto metrics = fct::PoseErrorMetrics::create(boneBlock()).value();
  const Eigen::Vector3d centre_world_mm = somePose() * metrics.surface().centroid_ct_mm();
  const Eigen::Vector3d source_world_mm = centre_world_mm + Eigen::Vector3d(100.0, -600.0, 200.0);
  const Eigen::Vector3d ray = (centre_world_mm - source_world_mm).normalized();
  Eigen::Isometry3d T_estimate = somePose();
  T_estimate.pretranslate(3.0 * ray);
  const fct::ViewPlaneError e = metrics.measureInView(T_estimate, somePose(), source_world_mm);
  EXPECT_NEAR(e.outOfPlaneMean_mm, 3.0, 1e-9);
  EXPECT_NEAR(e.inPlaneMean_mm, 0.0, 1e-9);
}

TEST(PoseErrorMetrics, DetectorParallelShiftIsAllInPlaneAndRotationSplitsBetweenBoth) {
  const auto metrics = fct::PoseErrorMetrics::create(boneBlock()).value();
  const Eigen::Vector3d centre_world_mm = somePose() * metrics.surface().centroid_ct_mm();
  const Eigen::Vector3d source_world_mm = centre_world_mm - Eigen::Vector3d(0.0, 0.0, 700.0);  // looking along +z
  Eigen::Isometry3d shifted = somePose();
  shifted.pretranslate(Eigen::Vector3d(1.2, -1.6, 0.0));  // 2 mm across the ray
  const fct::ViewPlaneError across = metrics.measureInView(shifted, somePose(), source_world_mm);
  EXPECT_NEAR(across.inPlaneMean_mm, 2.0, 1e-9);
  EXPECT_NEAR(across.outOfPlaneMean_mm, 0.0, 1e-9);

  // A rotation about the ray's own axis through the centre moves the points only across the ray.
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  turned.translation() = centre_world_mm - turned.linear() * centre_world_mm;
  const fct::ViewPlaneError spun = metrics.measureInView(turned * somePose(), somePose(), source_world_mm);
  EXPECT_GT(spun.inPlaneMean_mm, 0.1);
  EXPECT_NEAR(spun.outOfPlaneMean_mm, 0.0, 1e-9);
  // The in-plane part never exceeds the whole sTRE.
  const fct::PoseError whole = metrics.measure(turned * somePose(), somePose());
  EXPECT_LE(spun.inPlaneMean_mm, whole.streMean_mm + 1e-9);
}
