#include <gtest/gtest.h>

#include "Geometry/RigidPose.h"

TEST(RigidPose, ParametersRoundTrip) {
  const Eigen::Vector3d centre(12.0, -40.0, 100.0);
  fct::PoseParameters p{{10.0, -25.0, 33.0}, {1.5, -2.0, 7.0}};
  const Eigen::Isometry3d T = fct::RigidPose::toTransform(p, centre);
  const auto back = fct::RigidPose::fromTransform(T, centre);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_NEAR((back.value().asVector() - p.asVector()).norm(), 0.0, 1e-9);
}

TEST(RigidPose, RotationTurnsAboutCentreAndTranslationMovesIt) {
  const Eigen::Vector3d centre(5.0, 6.0, 7.0);
  const fct::PoseParameters p{{0.0, 0.0, 90.0}, {1.0, 2.0, 3.0}};
  const Eigen::Isometry3d T = fct::RigidPose::toTransform(p, centre);
  EXPECT_NEAR((T * centre - (centre + Eigen::Vector3d(1, 2, 3))).norm(), 0.0, 1e-12);
  // A point 10 mm along +x from the centre goes to 10 mm along +y (rotation about z by 90 degrees).
  EXPECT_NEAR((T * (centre + Eigen::Vector3d(10, 0, 0)) - (centre + Eigen::Vector3d(1, 12, 3))).norm(), 0.0, 1e-12);
}

TEST(RigidPose, RejectsNonRotation) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M(0, 0) = 2.0;
  const auto result = fct::RigidPose::validated(M, "T_world_from_ct");
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("not a rotation"), std::string::npos);
  M = Eigen::Matrix4d::Identity();
  M(1, 3) = std::nan("");
  EXPECT_FALSE(fct::RigidPose::validated(M).ok());
}
