#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "Drr/DrrRendererFactory.h"
#include "Evaluation/ContourOverlay.h"
#include "Simulation/DrrXraySimulator.h"
#include "Simulation/PhantomBuilder.h"
#include "Simulation/StandardViews.h"
#include "TestSupport.h"

namespace {

struct Scene {
  fct::Volume ct;
  std::vector<fct::ViewSpec> views;
  fct::XrayImage xray;  ///< simulated X-ray of views[0] at the identity pose
};

Scene makeScene() {
  fct::PhantomOptions phantom;
  phantom.dims = Eigen::Vector3i(64, 64, 48);
  phantom.spacing_mm = 2.5;
  Scene scene{fct::PhantomBuilder::build(phantom).value(), {}, {}};
  fct::StandardViewOptions options;
  options.count = 2;
  options.cols = 240;
  options.rows = 180;
  options.pixelSpacing_mm = 1.3;
  scene.views = fct::StandardViews::build(Eigen::Vector3d::Zero(), options).value();
  auto drrVolume = fct::DrrVolume::create(scene.ct);
  auto renderer = fct::DrrRendererFactory::create(std::make_shared<const fct::DrrVolume>(std::move(drrVolume).value()));
  const fct::FloatImage drr = renderer.value()->render(scene.views[0].camera, Eigen::Isometry3d::Identity()).value();
  const fct::FloatImage intensity = fct::DrrXraySimulator::intensityFromDrr(drr, 60000.0, 0.0, 1).value();
  scene.xray.cols = intensity.cols;
  scene.xray.rows = intensity.rows;
  scene.xray.pixels = intensity.pixels;
  return scene;
}

/// Fraction of contour pixels within `radius` px of a pixel whose gradient magnitude (of -ln I, the DRR) is in the
/// top `strongFraction` of the image's gradients (the phantom's bone and body edges cover about a fifth of the image).
double fractionNearStrongEdges(const fct::XrayImage& xray, const std::vector<fct::PixelContour>& contours, int radius,
                               double strongFraction) {
  const int cols = xray.cols, rows = xray.rows;
  std::vector<float> gradient(xray.pixels.size(), 0.0f);
  const auto p = [&](int c, int r) { return -std::log(xray.at(c, r)); };
  for (int r = 1; r + 1 < rows; ++r)
    for (int c = 1; c + 1 < cols; ++c)
      gradient[static_cast<std::size_t>(r) * cols + c] =
          static_cast<float>(std::hypot(p(c + 1, r) - p(c - 1, r), p(c, r + 1) - p(c, r - 1)));
  std::vector<float> sorted = gradient;
  const auto cut = sorted.begin() + static_cast<std::ptrdiff_t>((1.0 - strongFraction) * static_cast<double>(sorted.size()));
  std::nth_element(sorted.begin(), cut, sorted.end());
  const float strong = *cut;
  std::size_t total = 0, near = 0;
  for (const auto& contour : contours) {
    for (const Eigen::Vector2i& q : contour) {
      ++total;
      bool found = false;
      for (int dr = -radius; dr <= radius && !found; ++dr)
        for (int dc = -radius; dc <= radius && !found; ++dc) {
          const int c = q.x() + dc, r = q.y() + dr;
          found = c >= 0 && r >= 0 && c < cols && r < rows && gradient[static_cast<std::size_t>(r) * cols + c] >= strong;
        }
      if (found) ++near;
    }
  }
  return total ? static_cast<double>(near) / static_cast<double>(total) : 0.0;
}

}  // namespace

TEST(ContourOverlay, OutlinesAtTheTruePoseLieOnTheDrrsBoneEdges) {
  const Scene scene = makeScene();
  auto overlay = fct::ContourOverlay::create(scene.ct);
  ASSERT_TRUE(overlay.ok()) << overlay.error();
  auto atTruth = overlay.value().contours(scene.views[0].camera, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(atTruth.ok()) << atTruth.error();
  ASSERT_FALSE(atTruth.value().empty());
  const double truthFraction = fractionNearStrongEdges(scene.xray, atTruth.value(), 2, 0.2);
  EXPECT_GT(truthFraction, 0.9);
  // Outlines of a displaced bone fall off the edges: the measure above can fail.
  const Eigen::Isometry3d moved(Eigen::Translation3d(6.0, 0.0, 4.0));
  auto displaced = overlay.value().contours(scene.views[0].camera, moved);
  ASSERT_TRUE(displaced.ok()) << displaced.error();
  EXPECT_LT(fractionNearStrongEdges(scene.xray, displaced.value(), 2, 0.2), truthFraction - 0.15);
}

TEST(ContourOverlay, DrawsBothPosesInTheirColoursAndWritesAPng) {
  const Scene scene = makeScene();
  auto overlay = fct::ContourOverlay::create(scene.ct);
  ASSERT_TRUE(overlay.ok()) << overlay.error();
  const Eigen::Isometry3d initial(Eigen::Translation3d(8.0, 0.0, -6.0));
  auto image = overlay.value().render(scene.xray, scene.views[0].camera, initial, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(image.ok()) << image.error();
  ASSERT_EQ(image.value().cols, scene.xray.cols);
  ASSERT_EQ(image.value().pixels.size(), 3u * scene.xray.pixels.size());
  std::size_t reddish = 0, greenish = 0;
  for (int r = 0; r < image.value().rows; ++r)
    for (int c = 0; c < image.value().cols; ++c) {
      const auto rgb = image.value().at(c, r);
      if (rgb[0] > 200 && rgb[1] < 120) ++reddish;
      if (rgb[1] > 200 && rgb[0] < 120) ++greenish;
    }
  EXPECT_GT(reddish, 200u);
  EXPECT_GT(greenish, 200u);

  const auto path = fct::test::scratchDir() / "overlay.png";
  const fct::Status written =
      overlay.value().writeOverlayPng(scene.xray, scene.views[0].camera, initial, Eigen::Isometry3d::Identity(), path);
  ASSERT_TRUE(written.ok()) << written.error();
  const cv::Mat readBack = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(readBack.type(), CV_8UC3);
  const cv::Vec3b bgr = readBack.at<cv::Vec3b>(90, 120);
  const auto rgb = image.value().at(120, 90);
  EXPECT_EQ(bgr[0], rgb[2]);
  EXPECT_EQ(bgr[2], rgb[0]);
}

TEST(ContourOverlay, PoseOutOfViewDrawsNothing) {
  const Scene scene = makeScene();
  auto overlay = fct::ContourOverlay::create(scene.ct);
  ASSERT_TRUE(overlay.ok()) << overlay.error();
  const Eigen::Isometry3d farAway(Eigen::Translation3d(0.0, 0.0, 5000.0));
  auto contours = overlay.value().contours(scene.views[0].camera, farAway);
  ASSERT_TRUE(contours.ok()) << contours.error();
  EXPECT_TRUE(contours.value().empty());
  auto image = overlay.value().render(scene.xray, scene.views[0].camera, farAway, farAway);
  ASSERT_TRUE(image.ok()) << image.error();
  EXPECT_EQ(image.value().cols, scene.xray.cols);
}

TEST(ContourOverlay, RejectsBadInputs) {
  EXPECT_FALSE(fct::ContourOverlay::create(fct::Volume()).ok());
  const Scene scene = makeScene();
  auto tooHigh = fct::ContourOverlay::create(scene.ct, 10000.0);
  ASSERT_FALSE(tooHigh.ok());
  EXPECT_NE(tooHigh.error().find("10000"), std::string::npos) << tooHigh.error();
  auto overlay = fct::ContourOverlay::create(scene.ct);
  ASSERT_TRUE(overlay.ok()) << overlay.error();
  fct::XrayImage wrongSize = scene.xray;
  wrongSize.cols = 100;
  wrongSize.rows = static_cast<int>(wrongSize.pixels.size() / 100);
  auto mismatch = overlay.value().render(wrongSize, scene.views[0].camera, Eigen::Isometry3d::Identity(),
                                         Eigen::Isometry3d::Identity());
  ASSERT_FALSE(mismatch.ok());
  EXPECT_NE(mismatch.error().find("detector"), std::string::npos) << mismatch.error();
  EXPECT_FALSE(overlay.value().render(fct::XrayImage{}, scene.views[0].camera, Eigen::Isometry3d::Identity(),
                                      Eigen::Isometry3d::Identity()).ok());
  Eigen::Isometry3d notRigid = Eigen::Isometry3d::Identity();
  notRigid.matrix()(1, 1) = 3.0;
  EXPECT_FALSE(overlay.value().contours(scene.views[0].camera, notRigid).ok());
}
