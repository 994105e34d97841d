#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "Base/SeededRandom.h"
#include "InitialPose/LandmarkPoseEstimator.h"
#include "LandmarkTestScene.h"

using fct::LandmarkPoseEstimator;
using fct::Landmarks;
namespace t = fct::test;

namespace {

/// Rotation error (deg) and error at the bone centre (mm) of an estimate.
std::pair<double, double> errors(const Eigen::Isometry3d& T) {
  const Eigen::Isometry3d truth = t::truePose();
  const double rotation_deg = Eigen::AngleAxisd(truth.linear().transpose() * T.linear()).angle() * 180.0 / M_PI;
  return {rotation_deg, (T * t::boneCentre_ct_mm() - truth * t::boneCentre_ct_mm()).norm()};
}

/// Mean distance (mm) between estimate and truth over the landmarks and over points of a 60 mm sphere (the "bone").
std::pair<double, double> meanErrors(const Eigen::Isometry3d& T) {
  const Eigen::Isometry3d truth = t::truePose();
  double landmarks = 0.0;
  for (const auto& lm : t::ctLandmarks()) landmarks += (T * lm.p_ct_mm - truth * lm.p_ct_mm).norm();
  double bone = 0.0;
  int count = 0;
  for (int i = 0; i < 12; ++i) {
    for (int j = 1; j < 6; ++j) {
      const double phi = 2.0 * M_PI * i / 12.0, theta = M_PI * j / 6.0;
      const Eigen::Vector3d p = t::boneCentre_ct_mm() + 60.0 * Eigen::Vector3d(std::sin(theta) * std::cos(phi),
                                                                                 std::sin(theta) * std::sin(phi),
                                                                                 std::cos(theta));
      bone += (T * p - truth * p).norm();
      ++count;
    }
  }
  return {landmarks / t::ctLandmarks().size(), bone / count};
}

Landmarks noisyLandmarks(const std::map<std::string, fct::Camera>& views, std::uint32_t seed) {
  Landmarks landmarks = t::exactLandmarks(views);
  fct::SeededRandom random(seed);
  for (auto& [view, clicks] : landmarks.imageByView) {
    for (auto& click : clicks) click.uv_px += Eigen::Vector2d(random.normal(), random.normal());
  }
  return landmarks;
}

std::map<std::string, fct::Camera> only(const std::vector<std::string>& names) {
  const auto all = t::threeViews();
  std::map<std::string, fct::Camera> views;
  for (const auto& name : names) views.emplace(name, all.at(name));
  return views;
}

}  // namespace

TEST(LandmarkPoseEstimator, ExactClicksInOneViewGiveExactPose) {
  for (const char* view : {"AP", "OBL", "LAT"}) {
    const auto views = only({view});
    const auto result = LandmarkPoseEstimator::fromReprojection(t::exactLandmarks(views), views);
    ASSERT_TRUE(result.ok()) << result.error();
    EXPECT_EQ(result.value().method, "pnp");
    const auto [rotation_deg, centre_mm] = errors(result.value().T_world_from_ct);
    EXPECT_LT(rotation_deg, 1e-6) << view;
    EXPECT_LT(centre_mm, 1e-6) << view;
    EXPECT_LT(result.value().rmsReprojection_px, 1e-6);
    EXPECT_TRUE(std::isnan(result.value().rms3d_mm));
  }
}

TEST(LandmarkPoseEstimator, ExactClicksOfFourLandmarksInOneViewGiveExactPose) {
  const auto views = only({"OBL"});
  Landmarks landmarks = t::exactLandmarks(views);
  landmarks.ct.resize(4);
  landmarks.imageByView["OBL"].resize(4);
  const auto result = LandmarkPoseEstimator::fromReprojection(landmarks, views);
  ASSERT_TRUE(result.ok()) << result.error();
  const auto [rotation_deg, centre_mm] = errors(result.value().T_world_from_ct);
  EXPECT_LT(rotation_deg, 1e-6);
  EXPECT_LT(centre_mm, 1e-6);
}

TEST(LandmarkPoseEstimator, ExactClicksInSeveralViewsGiveExactPoseByBothMethods) {
  const auto views = t::threeViews();
  const Landmarks landmarks = t::exactLandmarks(views);
  for (const auto& result : {LandmarkPoseEstimator::fromReprojection(landmarks, views),
                             LandmarkPoseEstimator::fromTriangulation(landmarks, views)}) {
    ASSERT_TRUE(result.ok()) << result.error();
    const auto [rotation_deg, centre_mm] = errors(result.value().T_world_from_ct);
    EXPECT_LT(rotation_deg, 1e-6) << result.value().method;
    EXPECT_LT(centre_mm, 1e-6) << result.value().method;
    EXPECT_LT(result.value().rms3d_mm, 1e-6);
    ASSERT_EQ(result.value().residuals.size(), 8u);
    EXPECT_EQ(result.value().residuals[0].name, "ASIS_L");
    EXPECT_EQ(result.value().residuals[0].reprojection_px.size(), 3u);
  }
}

TEST(LandmarkPoseEstimator, NoisyClicksGiveLessThanTwoMillimetres) {
  const std::vector<std::vector<std::string>> viewSets = {{"AP", "LAT"}, {"AP", "OBL", "LAT"}};
  for (const auto& names : viewSets) {
    const auto views = only(names);
    for (std::uint32_t seed = 1; seed <= 5; ++seed) {
      const Landmarks landmarks = noisyLandmarks(views, seed);
      for (const auto& result : {LandmarkPoseEstimator::fromReprojection(landmarks, views),
                                 LandmarkPoseEstimator::fromTriangulation(landmarks, views)}) {
        ASSERT_TRUE(result.ok()) << result.error();
        const auto [atLandmarks_mm, atBone_mm] = meanErrors(result.value().T_world_from_ct);
        EXPECT_LT(atLandmarks_mm, 2.0) << result.value().method << " seed " << seed << " views " << names.size();
        EXPECT_LT(atBone_mm, 2.0) << result.value().method << " seed " << seed << " views " << names.size();
        // The residuals reflect the 1 px noise: neither zero nor large.
        EXPECT_GT(result.value().rmsReprojection_px, 0.2);
        EXPECT_LT(result.value().rmsReprojection_px, 3.0);
      }
    }
  }
}

TEST(LandmarkPoseEstimator, JointReprojectionUsesLandmarksClickedInDifferentViews) {
  // Four landmarks in AP, the other four only in LAT: no triangulation possible, PnP start + joint refinement.
  const auto views = only({"AP", "LAT"});
  Landmarks landmarks = t::exactLandmarks(views);
  auto& ap = landmarks.imageByView["AP"];
  auto& lat = landmarks.imageByView["LAT"];
  ap.erase(ap.begin() + 4, ap.end());
  lat.erase(lat.begin(), lat.begin() + 4);
  const auto result = LandmarkPoseEstimator::fromReprojection(landmarks, views);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().method, "joint-reprojection");
  const auto [rotation_deg, centre_mm] = errors(result.value().T_world_from_ct);
  EXPECT_LT(rotation_deg, 1e-6);
  EXPECT_LT(centre_mm, 1e-6);
  EXPECT_FALSE(LandmarkPoseEstimator::fromTriangulation(landmarks, views).ok());
}

TEST(LandmarkPoseEstimator, RejectsTooFewLandmarks) {
  const auto views = t::threeViews();
  Landmarks landmarks = t::exactLandmarks(views);
  landmarks.ct.resize(3);
  for (auto& [view, clicks] : landmarks.imageByView) clicks.resize(3);
  const auto result = LandmarkPoseEstimator::fromReprojection(landmarks, views);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("only 3 landmarks"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("at least 4"), std::string::npos) << result.error();
  EXPECT_FALSE(LandmarkPoseEstimator::fromTriangulation(landmarks, views).ok());
}

TEST(LandmarkPoseEstimator, RejectsCollinearLandmarks) {
  const auto views = t::threeViews();
  Landmarks landmarks;
  for (int i = 0; i < 5; ++i) {
    landmarks.ct.push_back({fmt::format("L{}", i), t::boneCentre_ct_mm() + Eigen::Vector3d(10.0 * i, 5.0 * i, 0.0)});
  }
  for (const auto& [view, camera] : views) {
    for (const auto& lm : landmarks.ct) {
      landmarks.imageByView[view].push_back({lm.name, camera.project(t::truePose() * lm.p_ct_mm)});
    }
  }
  for (const auto& result : {LandmarkPoseEstimator::fromReprojection(landmarks, views),
                             LandmarkPoseEstimator::fromTriangulation(landmarks, views)}) {
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("collinear"), std::string::npos) << result.error();
  }
}

TEST(LandmarkPoseEstimator, RejectsLandmarkNamedInOnlyOnePlace) {
  const auto views = t::threeViews();
  {
    Landmarks landmarks = t::exactLandmarks(views);
    landmarks.ct.push_back({"EXTRA", t::boneCentre_ct_mm()});
    const auto result = LandmarkPoseEstimator::fromReprojection(landmarks, views);
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("'EXTRA' has a CT point but is clicked in no view"), std::string::npos)
        << result.error();
  }
  {
    Landmarks landmarks = t::exactLandmarks(views);
    landmarks.imageByView["LAT"].push_back({"STRAY", Eigen::Vector2d(100, 100)});
    const auto result = LandmarkPoseEstimator::fromTriangulation(landmarks, views);
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("'STRAY' is clicked in view 'LAT' but has no CT point"), std::string::npos)
        << result.error();
  }
  {
    Landmarks landmarks = t::exactLandmarks(views);
    auto& ap = landmarks.imageByView["AP"];
    auto& obl = landmarks.imageByView["OBL"];
    ap.erase(ap.begin());
    obl.erase(obl.begin());  // ASIS_L now only in LAT
    EXPECT_TRUE(LandmarkPoseEstimator::fromReprojection(landmarks, views).ok());
    const auto result = LandmarkPoseEstimator::fromTriangulation(landmarks, views);
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("'ASIS_L' is clicked only in view 'LAT'"), std::string::npos) << result.error();
  }
}

TEST(LandmarkPoseEstimator, RejectsSolutionBehindTheSource) {
  // The bone placed 300 mm behind the AP source: the clicks are consistent, but no real view can see it.
  const auto views = only({"AP", "LAT"});
  const auto& ap = views.at("AP");
  Eigen::Isometry3d behind = t::truePose();
  behind.pretranslate(ap.sourcePosition_world_mm() - 300.0 * ap.T_world_from_camera().linear().col(2) -
                      behind * t::boneCentre_ct_mm());
  const Landmarks landmarks = t::exactLandmarks(views, behind);
  for (const auto& result : {LandmarkPoseEstimator::fromReprojection(landmarks, views),
                             LandmarkPoseEstimator::fromTriangulation(landmarks, views)}) {
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("behind the X-ray source of view 'AP'"), std::string::npos) << result.error();
  }
}

TEST(LandmarkPoseEstimator, RejectsUnknownViewDuplicatesAndNan) {
  const auto views = t::threeViews();
  {
    Landmarks landmarks = t::exactLandmarks(views);
    landmarks.imageByView["CRANIAL"] = landmarks.imageByView["AP"];
    const auto result = LandmarkPoseEstimator::fromReprojection(landmarks, views);
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("view 'CRANIAL' but there is no such view (views: AP, LAT, OBL)"),
              std::string::npos)
        << result.error();
  }
  {
    Landmarks landmarks = t::exactLandmarks(views);
    landmarks.ct.push_back(landmarks.ct.front());
    EXPECT_NE(LandmarkPoseEstimator::fromReprojection(landmarks, views).error().find("defined twice"),
              std::string::npos);
  }
  {
    Landmarks landmarks = t::exactLandmarks(views);
    landmarks.imageByView["OBL"][2].uv_px.x() = std::numeric_limits<double>::quiet_NaN();
    const auto result = LandmarkPoseEstimator::fromTriangulation(landmarks, views);
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().find("NaN"), std::string::npos) << result.error();
  }
  {
    Landmarks landmarks = t::exactLandmarks(views);
    landmarks.ct[1].p_ct_mm.z() = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(LandmarkPoseEstimator::fromReprojection(landmarks, views).ok());
  }
}
