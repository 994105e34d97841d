#include <gtest/gtest.h>

#include "Geometry/Camera.h"

namespace {

fct::Camera obliqueCamera() {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  fct::CameraIntrinsics in;
  in.cols = 640;
  in.rows = 480;
  in.pixelSpacing_mm = {0.3, 0.32};
  in.sourceToDetector_mm = 1100.0;
  in.principalPoint_px = {330.5, 230.25};
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(10, -20, 30) - 700.0 * R.col(2);
  return fct::Camera::create(in, T).value();
}

}  // namespace

TEST(Camera, PrincipalRayProjectsToPrincipalPoint) {
  const fct::Camera camera = obliqueCamera();
  const Eigen::Vector3d p = camera.sourcePosition_world_mm() + 500.0 * camera.T_world_from_camera().linear().col(2);
  bool inFront = false;
  const Eigen::Vector2d uv = camera.project(p, &inFront);
  EXPECT_TRUE(inFront);
  EXPECT_NEAR(uv.x(), 330.5, 1e-9);
  EXPECT_NEAR(uv.y(), 230.25, 1e-9);
}

TEST(Camera, BackProjectedRayReprojectsToSamePixel) {
  const fct::Camera camera = obliqueCamera();
  const Eigen::Vector2d uv(17.25, 401.5);
  const fct::Ray ray = camera.backProject(uv);
  EXPECT_NEAR(ray.direction_world.norm(), 1.0, 1e-12);
  const Eigen::Vector2d back = camera.project(ray.origin_world_mm + 812.0 * ray.direction_world);
  EXPECT_NEAR((back - uv).norm(), 0.0, 1e-9);
  EXPECT_NEAR((camera.project(camera.detectorPoint_world_mm(uv)) - uv).norm(), 0.0, 1e-9);
}

TEST(Camera, ProjectionMatrixRoundTrip) {
  const fct::Camera camera = obliqueCamera();
  const auto P = camera.P_px_from_world();
  const auto decoded = fct::Camera::fromProjectionMatrix(-3.7 * P, 640, 480, {0.3, 0.32});
  ASSERT_TRUE(decoded.ok()) << decoded.error();
  EXPECT_NEAR(decoded.value().intrinsics().sourceToDetector_mm, 1100.0, 1e-6);
  EXPECT_NEAR((decoded.value().intrinsics().principalPoint_px - Eigen::Vector2d(330.5, 230.25)).norm(), 0.0, 1e-6);
  EXPECT_NEAR((decoded.value().T_world_from_camera().matrix() - camera.T_world_from_camera().matrix()).norm(), 0.0, 1e-6);
}

TEST(Camera, DownsampledCameraMapsBlockCentres) {
  const fct::Camera camera = obliqueCamera();
  const fct::Camera level2 = camera.downsampled(2);
  EXPECT_EQ(level2.intrinsics().cols, 160);
  EXPECT_EQ(level2.intrinsics().rows, 120);
  // Level-2 pixel (u', v') covers fine pixels 4u'..4u'+3, whose centre is fine pixel 4u'+1.5.
  const Eigen::Vector3d p = camera.detectorPoint_world_mm({101.5, 57.5});
  const Eigen::Vector2d uvCoarse = level2.project(p);
  EXPECT_NEAR(uvCoarse.x(), 25.0, 1e-9);
  EXPECT_NEAR(uvCoarse.y(), 14.0, 1e-9);
}

TEST(Camera, RejectsBadInput) {
  fct::CameraIntrinsics in;
  in.cols = 0;
  in.rows = 100;
  EXPECT_FALSE(fct::Camera::create(in, Eigen::Isometry3d::Identity()).ok());
  in.cols = 100;
  in.pixelSpacing_mm = {0.0, 1.0};
  EXPECT_NE(fct::Camera::create(in, Eigen::Isometry3d::Identity()).error().find("pixel spacing"), std::string::npos);
  in.pixelSpacing_mm = {1.0, 1.0};
  Eigen::Isometry3d mirrored = Eigen::Isometry3d::Identity();
  mirrored.linear().diagonal() << 1, 1, -1;
  EXPECT_NE(fct::Camera::create(in, mirrored).error().find("not a rotation"), std::string::npos);
  Eigen::Isometry3d nan = Eigen::Isometry3d::Identity();
  nan.translation().x() = std::nan("");
  EXPECT_FALSE(fct::Camera::create(in, nan).ok());
  EXPECT_FALSE(fct::Camera::fromProjectionMatrix(Eigen::Matrix<double, 3, 4>::Zero(), 10, 10, {1, 1}).ok());
}
