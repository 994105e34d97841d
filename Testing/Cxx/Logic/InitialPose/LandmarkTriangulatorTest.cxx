#include <gtest/gtest.h>

#include <limits>

#include "InitialPose/LandmarkTriangulator.h"
#include "LandmarkTestScene.h"

using fct::LandmarkClick;
using fct::LandmarkTriangulator;
namespace t = fct::test;

TEST(LandmarkTriangulator, RecoversExactPointFromTwoAndThreeViews) {
  const auto views = t::threeViews();
  const Eigen::Vector3d p_world_mm(14.0, -22.0, 31.0);
  std::vector<LandmarkClick> clicks;
  for (const auto& [view, camera] : views) clicks.push_back({view, camera, camera.project(p_world_mm)});
  auto all = LandmarkTriangulator::triangulate("P", clicks);
  ASSERT_TRUE(all.ok()) << all.error();
  EXPECT_LT((all.value() - p_world_mm).norm(), 1e-9);
  clicks.pop_back();
  auto two = LandmarkTriangulator::triangulate("P", clicks);
  ASSERT_TRUE(two.ok()) << two.error();
  EXPECT_LT((two.value() - p_world_mm).norm(), 1e-9);
}

TEST(LandmarkTriangulator, JacobianMatchesFiniteDifferences) {
  const auto camera = t::cArmView(30.0, 10.0, 1100.0);
  const Eigen::Vector3d p(5.0, 12.0, -8.0);
  Eigen::Matrix<double, 2, 3> J;
  const Eigen::Vector2d uv = LandmarkTriangulator::projectWithJacobian(camera, p, &J);
  EXPECT_LT((uv - camera.project(p)).norm(), 1e-9);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d h = Eigen::Vector3d::Zero();
    h[k] = 1e-4;
    const Eigen::Vector2d numeric = (camera.project(p + h) - camera.project(p - h)) / 2e-4;
    EXPECT_LT((numeric - J.col(k)).norm(), 1e-5) << "column " << k;
  }
}

TEST(LandmarkTriangulator, RejectsSingleViewParallelRaysNanAndPointBehindSource) {
  const auto views = t::threeViews();
  const auto& ap = views.at("AP");
  const Eigen::Vector3d p(0.0, 0.0, 0.0);
  auto r = LandmarkTriangulator::triangulate("tip", {{"AP", ap, ap.project(p)}});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("'tip' is clicked only in view 'AP'"), std::string::npos) << r.error();

  const auto apAgain = t::cArmView(5.5, 12.0, 1000.0);  // 0.5 deg apart
  r = LandmarkTriangulator::triangulate("tip", {{"AP", ap, ap.project(p)}, {"AP2", apAgain, apAgain.project(p)}});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("nearly the same direction"), std::string::npos) << r.error();

  r = LandmarkTriangulator::triangulate(
      "tip", {{"AP", ap, Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 3.0)},
              {"LAT", views.at("LAT"), Eigen::Vector2d(1, 2)}});
  EXPECT_FALSE(r.ok());

  // A point behind the AP source (the lines still meet there).
  const Eigen::Vector3d behind = ap.sourcePosition_world_mm() - 300.0 * ap.T_world_from_camera().linear().col(2);
  const auto& lat = views.at("LAT");
  r = LandmarkTriangulator::triangulate("tip", {{"AP", ap, ap.project(behind)}, {"LAT", lat, lat.project(behind)}});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("behind the X-ray source of view 'AP'"), std::string::npos) << r.error();
}
