// The DrrRenderer interface, exercised through both ray casters: projection geometry, pyramid levels, pixel lists,
// bad input and determinism.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <string>

#include "Drr/DrrRendererFactory.h"
#include "DrrTestPhantoms.h"

namespace {

using fct::DrrMethod;

class DrrRendererBehaviour : public ::testing::TestWithParam<DrrMethod> {
 protected:
  std::unique_ptr<fct::DrrRenderer> makeRenderer(const fct::Volume& ct) const {
    fct::DrrRendererOptions options;
    options.method = GetParam();
    return fct::DrrRendererFactory::create(fct::test::rawDrrVolume(ct), options).value();
  }
  /// A 64^3 ellipsoid phantom at a non-identity pose, with an oblique 101x77 view (odd sizes on purpose).
  void SetUp() override {
    m_ct = fct::test::emptyPhantomCt();
    fct::test::voxelize(fct::test::ellipsoid(Eigen::Vector3d(2, -1, 0), Eigen::Vector3d(25, 17, 21)), 1.0f, m_ct);
    m_pose.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 0, 1).normalized()).toRotationMatrix();
    m_pose.translation() = Eigen::Vector3d(-3, 5, 1);
    m_camera = fct::test::phantomCamera(fct::test::obliqueRotation(), 101, 77, 1.0);
  }
  fct::Volume m_ct;
  Eigen::Isometry3d m_pose = Eigen::Isometry3d::Identity();
  fct::Camera m_camera;
};

std::string methodLabel(const ::testing::TestParamInfo<DrrMethod>& info) {
  return std::string(fct::DrrRendererFactory::methodName(info.param));
}

/// Intensity-weighted centroid (col,row) of an image.
Eigen::Vector2d centroid_px(const fct::FloatImage& image) {
  double sum = 0.0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      sum += image.at(col, row);
      weighted += image.at(col, row) * Eigen::Vector2d(col, row);
    }
  }
  return weighted / sum;
}

}  // namespace

TEST_P(DrrRendererBehaviour, BeadAppearsAtItsProjectionForObliqueViewRotatedCtAndPose) {
  // A CT with a non-identity direction matrix and non-cubic voxels, holding one bright voxel.
  const Eigen::Matrix3d direction = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 3).normalized()).toRotationMatrix();
  fct::Volume ct = fct::Volume::create({32, 28, 24}, {0.8, 1.0, 1.25}, {12.0, -30.0, 7.0}, direction).value();
  const Eigen::Vector3i bead(11, 17, 9);
  ct.at(bead.x(), bead.y(), bead.z()) = 1000.0f;
  const auto renderer = makeRenderer(ct);
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  T_world_from_ct.linear() = Eigen::AngleAxisd(-0.5, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  T_world_from_ct.translation() = Eigen::Vector3d(40.0, -15.0, 25.0);
  const Eigen::Vector3d bead_world_mm = T_world_from_ct * ct.lpsFromIjk(bead.cast<double>());

  for (const Eigen::Matrix3d& R : {fct::test::obliqueRotation(),
                                   Eigen::Matrix3d(Eigen::AngleAxisd(2.1, Eigen::Vector3d(0.2, 1, 0.4).normalized()))}) {
    // The bead sits off the principal ray; 0.15 mm pixels make its blob about 10 pixels wide.
    const fct::Camera camera = fct::Camera::lookingAt(bead_world_mm + Eigen::Vector3d(0.5, -0.7, 0.3), R, 600.0, 1000.0,
                                                      96, 96, 0.15);
    const fct::FloatImage drr = renderer->render(camera, T_world_from_ct).value();
    const Eigen::Vector2d expected_px = camera.project(bead_world_mm);
    ASSERT_TRUE((expected_px.array() > 20).all() && (expected_px.array() < 76).all()) << expected_px.transpose();
    EXPECT_LT((centroid_px(drr) - expected_px).norm(), 0.1)
        << "centroid " << centroid_px(drr).transpose() << " expected " << expected_px.transpose();
  }
}

TEST_P(DrrRendererBehaviour, PyramidLevelEqualsRenderOfLevelCamera) {
  const auto renderer = makeRenderer(m_ct);
  for (int level : {1, 2}) {
    const fct::FloatImage viaLevel = renderer->render(m_camera, m_pose, level).value();
    const fct::FloatImage direct = renderer->render(m_camera.downsampled(level), m_pose).value();
    EXPECT_EQ(viaLevel.cols, 101 >> level);
    EXPECT_EQ(viaLevel.rows, 77 >> level);
    EXPECT_EQ(viaLevel.pixels, direct.pixels);
  }
}

TEST_P(DrrRendererBehaviour, PixelListGivesFullRenderValuesInListOrder) {
  const auto renderer = makeRenderer(m_ct);
  const int level = 1;
  const fct::FloatImage full = renderer->render(m_camera, m_pose, level).value();
  std::mt19937 random(7);
  std::uniform_int_distribution<std::int32_t> pick(0, full.cols * full.rows - 1);
  fct::PixelIndexList pixels;
  for (int n = 0; n < 500; ++n) pixels.push_back(pick(random));
  pixels.push_back(pixels.front());  // duplicates are allowed
  std::vector<float> values(3, -1.0f);  // reused buffer, resized by the call
  ASSERT_TRUE(renderer->renderPixels(m_camera, m_pose, level, pixels, values).ok());
  ASSERT_EQ(values.size(), pixels.size());
  int nonZero = 0;
  for (std::size_t n = 0; n < pixels.size(); ++n) {
    EXPECT_EQ(values[n], full.pixels[static_cast<std::size_t>(pixels[n])]) << "pixel " << pixels[n];
    nonZero += values[n] > 0.0f ? 1 : 0;
  }
  EXPECT_GT(nonZero, 100);
}

TEST_P(DrrRendererBehaviour, SameImageWithOneThreadAndWithAllThreads) {
  const auto renderer = makeRenderer(m_ct);
  const fct::FloatImage parallel = renderer->render(m_camera, m_pose).value();
  fct::FloatImage serial;
  {
    tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
    ASSERT_TRUE(renderer->render(m_camera, m_pose, 0, serial).ok());
  }
  EXPECT_EQ(serial.pixels, parallel.pixels);
  EXPECT_GT(*std::max_element(parallel.pixels.begin(), parallel.pixels.end()), 20.0f);
}

TEST_P(DrrRendererBehaviour, RaysMissingTheVolumeOrCrossingOnlyZerosGiveZeros) {
  const auto renderer = makeRenderer(m_ct);
  // Looking at a point 500 mm beside the CT, and looking away from it (CT behind the source).
  const fct::Camera beside = fct::Camera::lookingAt({500, 0, 0}, Eigen::Matrix3d::Identity(), 600.0, 1000.0, 40, 30, 1.0);
  Eigen::Matrix3d flip = Eigen::Matrix3d::Identity();
  flip(0, 0) = -1;
  flip(2, 2) = -1;
  const fct::Camera away = fct::Camera::create(m_camera.intrinsics(), [&] {
                             Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
                             T.translation() = Eigen::Vector3d(0, 0, -300);
                             T.linear() = flip;  // looks along -z, the CT is at +300 mm behind the source
                             return T;
                           }()).value();
  fct::Volume air = m_ct;
  air.voxels().assign(air.voxelCount(), 0.0f);
  const auto airRenderer = makeRenderer(air);
  for (const auto& [camera, r] : {std::pair{beside, renderer.get()}, std::pair{away, renderer.get()},
                                  std::pair{m_camera, airRenderer.get()}}) {
    const auto drr = r->render(camera, Eigen::Isometry3d::Identity());
    ASSERT_TRUE(drr.ok()) << drr.error();
    EXPECT_EQ(*std::max_element(drr.value().pixels.begin(), drr.value().pixels.end()), 0.0f);
    EXPECT_EQ(*std::min_element(drr.value().pixels.begin(), drr.value().pixels.end()), 0.0f);
  }
}

TEST_P(DrrRendererBehaviour, RejectsDegenerateCameraPoseAndLevel) {
  const auto renderer = makeRenderer(m_ct);
  fct::FloatImage untouched = fct::FloatImage::filled(2, 2, 5.0f);
  const fct::Status noDetector = renderer->render(fct::Camera(), m_pose, 0, untouched);
  ASSERT_FALSE(noDetector.ok());
  EXPECT_NE(noDetector.error().find("detector size"), std::string::npos) << noDetector.error();
  EXPECT_EQ(untouched.pixels, std::vector<float>(4, 5.0f));

  Eigen::Isometry3d scaled = m_pose;
  scaled.linear() *= 2.0;
  EXPECT_FALSE(renderer->render(m_camera, scaled).ok());
  Eigen::Isometry3d nanPose = m_pose;
  nanPose.translation().x() = std::nan("");
  EXPECT_FALSE(renderer->render(m_camera, nanPose).ok());

  EXPECT_FALSE(renderer->render(m_camera, m_pose, -1).ok());
  const auto tooCoarse = renderer->render(m_camera, m_pose, 7);  // 101x77 >> 7 = 0x0
  ASSERT_FALSE(tooCoarse.ok());
  EXPECT_NE(tooCoarse.error().find("leaves no pixels"), std::string::npos) << tooCoarse.error();
}

TEST_P(DrrRendererBehaviour, PixelListEdgeCases) {
  const auto renderer = makeRenderer(m_ct);
  const auto empty = renderer->renderPixels(m_camera, m_pose, 2, fct::PixelIndexList{});
  ASSERT_TRUE(empty.ok()) << empty.error();
  EXPECT_TRUE(empty.value().empty());

  const int levelPixels = (101 >> 2) * (77 >> 2);
  std::vector<float> untouched{1.0f, 2.0f};
  for (const std::int32_t bad : {-1, levelPixels}) {
    const fct::Status status = renderer->renderPixels(m_camera, m_pose, 2, fct::PixelIndexList{0, bad}, untouched);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.error().find("outside the 25 x 19 detector"), std::string::npos) << status.error();
  }
  EXPECT_EQ(untouched, (std::vector<float>{1.0f, 2.0f}));
  EXPECT_TRUE(renderer->renderPixels(m_camera, m_pose, 2, fct::PixelIndexList{levelPixels - 1}).ok());
}

INSTANTIATE_TEST_SUITE_P(Methods, DrrRendererBehaviour, ::testing::Values(DrrMethod::RayCast, DrrMethod::Siddon),
                         methodLabel);

TEST(DrrRendererFactory, ParsesMethodNamesAndRejectsUnknownOnes) {
  for (const DrrMethod method : {DrrMethod::RayCast, DrrMethod::Siddon, DrrMethod::Transgraph}) {
    const auto parsed = fct::DrrRendererFactory::parseMethod(fct::DrrRendererFactory::methodName(method));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(parsed.value(), method);
  }
  const auto unknown = fct::DrrRendererFactory::parseMethod("raytrace");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("'raycast' or 'transgraph'"), std::string::npos) << unknown.error();
}

TEST(DrrRendererFactory, BuildsTheNamedMethodAndRejectsBadSetups) {
  const auto volume = fct::test::rawDrrVolume(fct::test::emptyPhantomCt());
  fct::DrrRendererOptions options;
  options.method = DrrMethod::RayCast;
  const auto raycast = fct::DrrRendererFactory::create(volume, options);
  ASSERT_TRUE(raycast.ok()) << raycast.error();
  EXPECT_EQ(raycast.value()->methodName(), "raycast");
  EXPECT_EQ(&raycast.value()->volume(), volume.get());  // shared, not copied

  EXPECT_FALSE(fct::DrrRendererFactory::create(nullptr).ok());
  for (const double badStep : {-1.0, 1e-4, std::nan("")}) {
    options.rayCastStep_mm = badStep;
    EXPECT_FALSE(fct::DrrRendererFactory::create(volume, options).ok()) << badStep;
  }
}
