#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "Simulation/StandardViews.h"

namespace {
const Eigen::Vector3d kIsocentre_mm(10.0, -20.0, 30.0);

Eigen::Vector3d principalRay(const fct::ViewSpec& view) { return view.camera.T_world_from_camera().linear().col(2); }
}  // namespace

TEST(StandardViews, ApAndLateralLookThroughTheIsocentreFromTheRightSides) {
  fct::StandardViewOptions options;
  options.count = 5;
  auto views = fct::StandardViews::build(kIsocentre_mm, options);
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(views.value().size(), 5u);
  EXPECT_EQ(views.value()[0].name, "ap");
  EXPECT_EQ(views.value()[1].name, "lateral");
  // AP: beam anterior -> posterior (+y LPS), columns toward the patient's left, rows toward the feet.
  EXPECT_LT((principalRay(views.value()[0]) - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_LT((views.value()[0].camera.T_world_from_camera().linear().col(1) + Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  // Lateral: source on the patient's left, beam toward the right (-x).
  EXPECT_LT((principalRay(views.value()[1]) + Eigen::Vector3d::UnitX()).norm(), 1e-12);
  for (const fct::ViewSpec& view : views.value()) {
    SCOPED_TRACE(view.name);
    EXPECT_NEAR((view.camera.sourcePosition_world_mm() - kIsocentre_mm).norm(), options.sourceToIsocentre_mm, 1e-9);
    bool inFront = false;
    const Eigen::Vector2d uv = view.camera.project(kIsocentre_mm, &inFront);
    EXPECT_TRUE(inFront);
    EXPECT_LT((uv - Eigen::Vector2d(399.5, 299.5)).norm(), 1e-9);
    EXPECT_EQ(view.camera.intrinsics().cols, 800);
    EXPECT_DOUBLE_EQ(view.camera.intrinsics().sourceToDetector_mm, 1500.0);
  }
  // Oblique45 is 45° from AP about the superior axis, tilted 10° out of the axial plane.
  const Eigen::Vector3d oblique = principalRay(views.value()[2]);
  EXPECT_NEAR(std::asin(std::abs(oblique.z())) * 180.0 / std::numbers::pi, 10.0, 1e-9);
  EXPECT_NEAR(std::atan2(-oblique.x(), oblique.y()) * 180.0 / std::numbers::pi, 45.0, 1e-9);
}

TEST(StandardViews, CountSelectsTheFirstViews) {
  for (int count = 1; count <= 5; ++count) {
    fct::StandardViewOptions options;
    options.count = count;
    auto views = fct::StandardViews::build(kIsocentre_mm, options);
    ASSERT_TRUE(views.ok()) << views.error();
    EXPECT_EQ(static_cast<int>(views.value().size()), count);
    EXPECT_EQ(fct::StandardViews::angles(count, 10.0).size(), static_cast<std::size_t>(count));
  }
}

TEST(StandardViews, RejectsBadGeometry) {
  const auto failsWith = [](fct::StandardViewOptions options, const char* word) {
    auto views = fct::StandardViews::build(kIsocentre_mm, options);
    ASSERT_FALSE(views.ok());
    EXPECT_NE(views.error().find(word), std::string::npos) << views.error();
  };
  fct::StandardViewOptions options;
  options.count = 0;
  failsWith(options, "1..5");
  options = {};
  options.count = 6;
  failsWith(options, "1..5");
  options = {};
  options.sourceToIsocentre_mm = 1600.0;
  failsWith(options, "source-to-isocentre");
  options = {};
  options.cols = 0;
  failsWith(options, "detector size");
  options = {};
  options.pixelSpacing_mm = -0.4;
  failsWith(options, "pixel spacing");
  EXPECT_FALSE(fct::StandardViews::build(Eigen::Vector3d(std::nan(""), 0, 0)).ok());
  EXPECT_TRUE(fct::StandardViews::angles(0, 10.0).empty());
}
