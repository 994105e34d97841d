#include <gtest/gtest.h>

#include "Evaluation/PoseOffset.h"
#include "Image/BoneSurface.h"

namespace {

/// A CT with a 40 x 20 x 30 mm block of bone (1000 HU) off the volume centre, in air.
fct::BoneSurface blockBone() {
  fct::Volume ct = fct::Volume::create({60, 50, 50}, {1.0, 1.0, 1.0}, {-30, -25, -25}, Eigen::Matrix3d::Identity(),
                                       -1000.0f)
                       .value();
  for (int k = 10; k < 40; ++k)
    for (int j = 20; j < 40; ++j)
      for (int i = 15; i < 55; ++i) ct.at(i, j, k) = 1000.0f;
  return fct::BoneSurface::extract(ct).value();
}

}  // namespace

TEST(PoseOffset, ZeroOffsetIsIdentityAndRotationKeepsTheBoneCentre) {
  const fct::BoneSurface bone = blockBone();
  Eigen::Isometry3d T_reference = Eigen::Isometry3d::Identity();
  T_reference.translation() = Eigen::Vector3d(5, -7, 100);
  EXPECT_NEAR((fct::PoseOffset::apply(bone, T_reference, {}).matrix() - T_reference.matrix()).norm(), 0.0, 1e-12);
  const Eigen::Isometry3d turned = fct::PoseOffset::apply(bone, T_reference, {{10.0, -20.0, 30.0}, {0, 0, 0}});
  EXPECT_NEAR((turned * bone.centroid_ct_mm() - T_reference * bone.centroid_ct_mm()).norm(), 0.0, 1e-9);
  const Eigen::Isometry3d moved = fct::PoseOffset::apply(bone, T_reference, {{0, 0, 0}, {3.0, 0.0, 4.0}});
  EXPECT_NEAR(bone.meanDistance_mm(moved, T_reference), 5.0, 1e-9);
}

TEST(PoseOffset, RandomOffsetHasTheRequestedSurfaceDistanceAndIsSeeded) {
  const fct::BoneSurface bone = blockBone();
  const Eigen::Isometry3d T_reference = Eigen::Isometry3d::Identity();
  const auto a = fct::PoseOffset::randomAtSurfaceDistance(bone, T_reference, 10.0, 3);
  const auto b = fct::PoseOffset::randomAtSurfaceDistance(bone, T_reference, 10.0, 3);
  const auto c = fct::PoseOffset::randomAtSurfaceDistance(bone, T_reference, 10.0, 4);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_NEAR(bone.meanDistance_mm(a.value(), T_reference), 10.0, 1e-3);
  EXPECT_NEAR(bone.meanDistance_mm(c.value(), T_reference), 10.0, 1e-3);
  EXPECT_EQ(a.value().matrix(), b.value().matrix());
  EXPECT_GT((a.value().matrix() - c.value().matrix()).norm(), 1e-3);
}

TEST(PoseOffset, RejectsBadDistances) {
  const fct::BoneSurface bone = blockBone();
  for (const double bad : {-1.0, std::nan(""), 1e4}) {
    const auto result = fct::PoseOffset::randomAtSurfaceDistance(bone, Eigen::Isometry3d::Identity(), bad, 1);
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("between 0 and 500 mm"), std::string::npos) << result.error();
  }
}
