#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>

#include "Drr/DrrRendererFactory.h"
#include "Drr/DrrVolume.h"
#include "Drr/TransgraphRenderer.h"
#include "DrrTestPhantoms.h"
#include "Geometry/Camera.h"
#include "Geometry/RigidPose.h"
#include "Image/Volume.h"
#include "TestSupport.h"

namespace {

using fct::TransgraphRenderer;

constexpr double kBallRadius_mm = 40.0;
constexpr float kBallValue = 2.0f;

// A 72^3 CT at 1.5 mm with a tilted direction matrix, holding a uniform ball at its centre (partial-volume voxelized).
fct::Volume ballVolume() {
  const Eigen::Matrix3d direction = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(72, 72, 72), Eigen::Vector3d::Constant(1.5),
                                       Eigen::Vector3d(12.0, -30.0, 55.0), direction)
                       .value();
  fct::test::voxelize(fct::test::ellipsoid(ct.centre_lps_mm(), Eigen::Vector3d::Constant(kBallRadius_mm)), kBallValue,
                      ct);
  return ct;
}

struct BallScene {
  std::shared_ptr<const fct::DrrVolume> volume;
  Eigen::Vector3d centre_ct_mm;
  Eigen::Isometry3d T_expected;
  fct::Camera view;
  fct::TransgraphParameters parameters;

  BallScene() {
    const fct::Volume ct = ballVolume();
    fct::DrrValueOptions raw;
    raw.kind = fct::DrrValueKind::Raw;
    volume = std::make_shared<const fct::DrrVolume>(fct::DrrVolume::create(ct, raw).value());
    centre_ct_mm = ct.centre_lps_mm();
    T_expected = fct::RigidPose::toTransform(
        fct::PoseParameters{Eigen::Vector3d(-4.0, 9.0, 3.0), Eigen::Vector3d(5.0, 15.0, -10.0)}, centre_ct_mm);
    const Eigen::Matrix3d R_world_from_camera =
        (Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(1.5, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    view = fct::Camera::lookingAt(T_expected * centre_ct_mm, R_world_from_camera, 1000.0, 1500.0, 64, 48, 3.0);
    parameters.spacing_mm = 2.5;
    parameters.range.rotation_deg = 5.0;
    parameters.range.translation_mm = 10.0;
  }

  Eigen::Isometry3d poseWithin(const Eigen::Vector3d& rotation_deg, const Eigen::Vector3d& translation_mm) const {
    return fct::RigidPose::toTransform(fct::PoseParameters{rotation_deg, translation_mm}, T_expected * centre_ct_mm) *
           T_expected;
  }
};

TEST(TransgraphRenderer, MatchesAnalyticBallThroughVoxelizedVolumeInsideRange) {
  const BallScene scene;
  auto created = TransgraphRenderer::create(scene.volume, scene.view, scene.T_expected, scene.parameters);
  ASSERT_TRUE(created.ok()) << created.error();
  const TransgraphRenderer& renderer = *created.value();
  EXPECT_EQ(renderer.methodName(), "transgraph");
  EXPECT_GT(renderer.transgraph().rayCount(), 0u);

  const double r = scene.parameters.range.rotation_deg, t = scene.parameters.range.translation_mm;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Isometry3d> poses = {scene.T_expected,
                                          scene.poseWithin(Eigen::Vector3d(r, r, -r), Eigen::Vector3d(t, -t, t))};
  for (int k = 0; k < 2; ++k) {
    poses.push_back(scene.poseWithin(r * Eigen::Vector3d(unit(random), unit(random), unit(random)),
                                     t * Eigen::Vector3d(unit(random), unit(random), unit(random))));
  }
  for (const auto& pose : poses) {
    fct::DrrRenderStats stats;
    auto drr = renderer.render(scene.view, pose, 0, &stats);
    ASSERT_TRUE(drr.ok()) << drr.error();
    EXPECT_EQ(stats.fallbackRays, 0u);
    // Closed form per pixel (-1 where the ray is not through the interior), then 5 x 5 patch means: a single ray
    // through a voxelized ball differs from the closed form by up to a few % (which voxel column it crosses), the
    // patch mean cancels that, as in the ray casters' accuracy tests.
    const fct::FloatImage& image = drr.value();
    const Eigen::Isometry3d T_ct_from_world = pose.inverse();
    const Eigen::Vector3d source = T_ct_from_world * scene.view.sourcePosition_world_mm();
    const auto ball = fct::test::ellipsoid(scene.centre_ct_mm, Eigen::Vector3d::Constant(kBallRadius_mm));
    fct::FloatImage exact = fct::FloatImage::filled(image.cols, image.rows, -1.0f);
    for (int row = 0; row < image.rows; ++row) {
      for (int col = 0; col < image.cols; ++col) {
        const Eigen::Vector3d end = T_ct_from_world * scene.view.detectorPoint_world_mm(Eigen::Vector2d(col, row));
        double grazing = 1.0;
        const double chord = ball.chord_mm(source, (end - source).normalized(), &grazing);
        if (grazing <= 0.8) exact.at(col, row) = static_cast<float>(chord * kBallValue);
      }
    }
    int checked = 0;
    for (int row = 0; row + 5 <= image.rows; row += 5) {
      for (int col = 0; col + 5 <= image.cols; col += 5) {
        double rendered = 0.0, expected = 0.0;
        bool interior = true;
        for (int r = row; r < row + 5; ++r) {
          for (int c = col; c < col + 5; ++c) {
            interior = interior && exact.at(c, r) >= 0.0f;
            rendered += image.at(c, r);
            expected += exact.at(c, r);
          }
        }
        if (!interior) continue;
        EXPECT_NEAR(rendered, expected, 0.01 * expected) << "5 x 5 patch at (" << col << ", " << row << ")";
        ++checked;
      }
    }
    EXPECT_GT(checked, 20);
  }
}

TEST(TransgraphRenderer, SecondCreateLoadsCachedTableAndRendersTheSame) {
  BallScene scene;
  scene.parameters.spacing_mm = 5.0;
  const auto folder = fct::test::scratchDir();
  auto first = TransgraphRenderer::create(scene.volume, scene.view, scene.T_expected, scene.parameters, folder);
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_FALSE(first.value()->transgraph().buildInfo().loadedFromCache);
  auto second = TransgraphRenderer::create(scene.volume, scene.view, scene.T_expected, scene.parameters, folder);
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_TRUE(second.value()->transgraph().buildInfo().loadedFromCache);
  EXPECT_TRUE(second.warnings().empty());
  const Eigen::Isometry3d pose = scene.poseWithin(Eigen::Vector3d(1.0, 2.0, -3.0), Eigen::Vector3d(-4.0, 3.0, 2.0));
  EXPECT_EQ(first.value()->render(scene.view, pose, 1).value().pixels,
            second.value()->render(scene.view, pose, 1).value().pixels);

  // Other values (attenuation instead of raw) are another table.
  fct::DrrValueOptions attenuation;
  auto other = std::make_shared<const fct::DrrVolume>(
      fct::DrrVolume::create(scene.volume->values(), attenuation).value());
  auto third = TransgraphRenderer::create(other, scene.view, scene.T_expected, scene.parameters, folder);
  ASSERT_TRUE(third.ok()) << third.error();
  EXPECT_FALSE(third.value()->transgraph().buildInfo().loadedFromCache);
}

}  // namespace

TEST(TransgraphRenderer, FactoryBuildsItPerViewAndRefusesItWithoutAView) {
  const BallScene scene;
  fct::DrrRendererOptions options;
  options.method = fct::DrrMethod::Transgraph;
  options.transgraph = scene.parameters;
  options.transgraphCacheFolder = std::nullopt;
  const auto withoutView = fct::DrrRendererFactory::create(scene.volume, options);
  ASSERT_FALSE(withoutView.ok());
  EXPECT_NE(withoutView.error().find("createForView"), std::string::npos) << withoutView.error();

  const auto renderer = fct::DrrRendererFactory::createForView(scene.volume, options, scene.view, scene.T_expected);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  EXPECT_EQ(renderer.value()->methodName(), "transgraph");
  // Inside the range the table agrees with the exact Siddon render of the same pose (block means within 1 %).
  options.method = fct::DrrMethod::Siddon;
  const auto siddon = fct::DrrRendererFactory::createForView(scene.volume, options, scene.view, scene.T_expected);
  ASSERT_TRUE(siddon.ok()) << siddon.error();
  const Eigen::Isometry3d pose = scene.poseWithin({2.0, -1.0, 1.5}, {3.0, -4.0, 2.0});
  const auto table = renderer.value()->render(scene.view, pose);
  const auto exact = siddon.value()->render(scene.view, pose);
  ASSERT_TRUE(table.ok() && exact.ok());
  double sumTable = 0.0, sumExact = 0.0;
  for (std::size_t n = 0; n < exact.value().pixels.size(); ++n) {
    sumTable += table.value().pixels[n];
    sumExact += exact.value().pixels[n];
  }
  ASSERT_GT(sumExact, 0.0);
  EXPECT_NEAR(sumTable / sumExact, 1.0, 0.01);
}
