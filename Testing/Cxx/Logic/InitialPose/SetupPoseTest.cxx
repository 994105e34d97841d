// SetupPose: the C-arm isocentre from the views' principal rays and the supine setup pose.
#include <gtest/gtest.h>

#include "InitialPose/SetupPose.h"
#include "Simulation/StandardViews.h"

namespace {

std::vector<fct::Camera> standardCameras(const Eigen::Vector3d& isocentre_world_mm, int count) {
  fct::StandardViewOptions options;
  options.count = count;
  const auto views = fct::StandardViews::build(isocentre_world_mm, options);
  std::vector<fct::Camera> cameras;
  for (const fct::ViewSpec& view : views.value()) {
    cameras.push_back(view.camera);
  }
  return cameras;
}

}  // namespace

TEST(SetupPose, FindsTheIsocentreOfStandardViews) {
  const Eigen::Vector3d isocentre(12.0, -30.0, 250.0);
  auto found = fct::SetupPose::isocentre_world_mm(standardCameras(isocentre, 3));
  ASSERT_TRUE(found.ok()) << found.error();
  EXPECT_LT((found.value() - isocentre).norm(), 1e-6);
}

TEST(SetupPose, SupinePoseMovesTheCentreToTheIsocentreWithoutRotation) {
  const Eigen::Vector3d isocentre(5.0, 6.0, -7.0);
  const Eigen::Vector3d centre_ct_mm(100.0, 80.0, 60.0);
  auto pose = fct::SetupPose::supineAtIsocentre(centre_ct_mm, standardCameras(isocentre, 2));
  ASSERT_TRUE(pose.ok()) << pose.error();
  EXPECT_TRUE(pose.value().linear().isIdentity(1e-12));
  EXPECT_LT((pose.value() * centre_ct_mm - isocentre).norm(), 1e-6);
}

TEST(SetupPose, OneViewUsesItsPrincipalRayAtTheTypicalIsocentreDistance) {
  const std::vector<fct::Camera> cameras = standardCameras(Eigen::Vector3d::Zero(), 1);
  auto found = fct::SetupPose::isocentre_world_mm(cameras);
  ASSERT_TRUE(found.ok()) << found.error();
  const double distance_mm = (found.value() - cameras.front().sourcePosition_world_mm()).norm();
  EXPECT_NEAR(distance_mm, fct::SetupPose::kSingleViewIsocentreFraction * 1500.0, 1e-6);
  const Eigen::Vector2d uv_px = cameras.front().project(found.value());
  EXPECT_LT((uv_px - cameras.front().intrinsics().principalPoint_px).norm(), 1e-6);
}

TEST(SetupPose, FailsClearlyWithoutViewsOrWithANonFiniteCentre) {
  auto none = fct::SetupPose::isocentre_world_mm({});
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().find("at least one"), std::string::npos);
  auto nan = fct::SetupPose::supineAtIsocentre(Eigen::Vector3d(std::nan(""), 0, 0), standardCameras(Eigen::Vector3d::Zero(), 2));
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().find("not finite"), std::string::npos);
}
