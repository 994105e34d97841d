#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "IO/Volume/VolumeFileIO.h"
#include "RegistrationTestCase.h"
#include "TestSupport.h"
#include "TestXrayLoader.h"
#include "XrayPrep/FieldOfViewDetector.h"

namespace {

/// An image-intensifier-like frame: a bright field inside `circle` with a soft 6 px edge and dark anatomy, black
/// outside.
fct::FloatImage circularField(int cols, int rows, const fct::PixelCircle& circle) {
  fct::FloatImage image = fct::FloatImage::filled(cols, rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double d = std::hypot(c - circle.centre_px.x(), r - circle.centre_px.y());
      const double edge = std::clamp((circle.radius_px - d) / 6.0, 0.0, 1.0);
      double v = 150.0 + 40.0 * std::sin(0.1 * c);
      if (std::hypot(c - 90.0, r - 80.0) < 25.0) v = 20.0;  // a dark (dense) structure inside the field
      image.at(c, r) = static_cast<float>(edge * v);
    }
  }
  return image;
}

}  // namespace

TEST(FieldOfViewDetector, FindsCircleCutByImageBorder) {
  const fct::PixelCircle truth{{130.3, 118.7}, 125.0};
  const auto fov = fct::FieldOfViewDetector().detect(circularField(256, 220, truth));
  ASSERT_TRUE(fov.ok()) << fov.error();
  ASSERT_TRUE(fov.value().circle.has_value());
  EXPECT_NEAR((fov.value().circle->centre_px - truth.centre_px).norm(), 0.0, 1.0);
  EXPECT_NEAR(fov.value().circle->radius_px, truth.radius_px, 1.5);
  EXPECT_TRUE(fov.value().mask.isValid(90, 80));  // the dark structure stays in the field
  EXPECT_FALSE(fov.value().mask.isValid(130 + 120, 119));  // 5 px inside the true edge: within the inset
  EXPECT_TRUE(fov.value().mask.isValid(130 + 110, 119));
  EXPECT_FALSE(fov.value().mask.isValid(2, 2));
}

TEST(FieldOfViewDetector, FallsBackToErodedRegionForRectangularCollimator) {
  fct::FloatImage image = fct::FloatImage::filled(100, 80, 0.0f);
  for (int r = 20; r < 60; ++r) {
    for (int c = 10; c < 90; ++c) image.at(c, r) = 100.0f + 0.5f * static_cast<float>(c);
  }
  const auto fov = fct::FieldOfViewDetector({0.1, 0.01, 2.0, 3}).detect(image);
  ASSERT_TRUE(fov.ok()) << fov.error();
  EXPECT_FALSE(fov.value().circle.has_value());
  EXPECT_EQ(fov.value().mask.validCount(), (80u - 6u) * (40u - 6u));
  EXPECT_TRUE(fov.value().mask.isValid(13, 23));
  EXPECT_FALSE(fov.value().mask.isValid(12, 23));
}

TEST(FieldOfViewDetector, FullyExposedImageIsAllField) {
  fct::FloatImage image = fct::FloatImage::filled(64, 64, 50.0f);
  image.at(10, 10) = 0.0f;  // one dead pixel is not a collimator
  const auto fov = fct::FieldOfViewDetector().detect(image);
  ASSERT_TRUE(fov.ok()) << fov.error();
  EXPECT_FALSE(fov.value().circle.has_value());
  EXPECT_EQ(fov.value().mask.validCount(), 64u * 64u);
}

TEST(FieldOfViewDetector, SimulatedViewWithBoneReachingTheBorderIsAllField) {
  // A collimator-free simulated view: I = I0 exp(-line integral) of a dense body cut by the left image border, so
  // its darkest pixels touch the border and fade smoothly into the exposed area, plus a little noise.
  fct::FloatImage image = fct::FloatImage::filled(200, 160);
  for (int r = 0; r < 160; ++r) {
    for (int c = 0; c < 200; ++c) {
      const double inside = 1.0 - std::pow((c + 20.0) / 90.0, 2) - std::pow((r - 80.0) / 70.0, 2);
      const double lineIntegral = 6.0 * std::sqrt(std::max(0.0, inside));
      image.at(c, r) = static_cast<float>(1000.0 * std::exp(-lineIntegral) + 3.0 * std::sin(1.7 * c + 2.3 * r));
    }
  }
  const auto fov = fct::FieldOfViewDetector().detect(image);
  ASSERT_TRUE(fov.ok()) << fov.error();
  EXPECT_FALSE(fov.value().circle.has_value());
  EXPECT_LT(fov.value().edgeStep, 2.0);
  EXPECT_EQ(fov.value().mask.validCount(), 200u * 160u) << "the dark bone at the border is not background";
  EXPECT_EQ(fov.value().backgroundFraction, 0.0);
}

TEST(FieldOfViewDetector, SimulatedLateralPelvisIsAllField) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  auto ct = fct::VolumeFileIO::read(fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz");
  ASSERT_TRUE(ct.ok()) << ct.error();
  auto simulated = fct::test::simulateCase(std::move(ct).value());
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  for (const fct::RegistrationView& view : simulated.value().views) {
    const auto fov = fct::FieldOfViewDetector().detect(fct::FloatImage{view.xray.cols, view.xray.rows, view.xray.pixels});
    ASSERT_TRUE(fov.ok()) << fov.error();
    EXPECT_FALSE(fov.value().circle.has_value()) << view.name;
    EXPECT_EQ(fov.value().mask.validCount(), view.xray.pixels.size()) << view.name;
  }
}

TEST(FieldOfViewDetector, RejectsTinyBlankAndNonFiniteImages) {
  const fct::FieldOfViewDetector detector;
  EXPECT_FALSE(detector.detect(fct::FloatImage::filled(2, 2, 1.0f)).ok());
  EXPECT_FALSE(detector.detect(fct::FloatImage::filled(16, 16, 0.0f)).ok());
  fct::FloatImage withNaN = fct::FloatImage::filled(16, 16, 1.0f);
  withNaN.at(4, 4) = std::nanf("");
  EXPECT_FALSE(detector.detect(withNaN).ok());
  EXPECT_FALSE(fct::FieldOfViewDetector({1.5, 0.01, 2.0, 3}).detect(fct::FloatImage::filled(16, 16, 1.0f)).ok());
  EXPECT_FALSE(fct::FieldOfViewDetector({0.1, 0.01, 2.0, 3, 0, 2.0}).detect(fct::FloatImage::filled(16, 16, 1.0f)).ok());
}

TEST(FieldOfViewDetector, FindsCircularFieldOfRealShoulderFluoroscopy) {
  FCT_REQUIRE_DATA("xray/rf_shoulder_kwire.dcm");
  const auto xray = fct::test::loadXrayWithDcmtk(fct::test::dataDir() / "xray/rf_shoulder_kwire.dcm");
  ASSERT_TRUE(xray.has_value());
  ASSERT_EQ(xray->cols, 512);
  ASSERT_EQ(xray->rows, 464);
  const auto fov = fct::FieldOfViewDetector().detect(fct::FloatImage{xray->cols, xray->rows, xray->pixels});
  ASSERT_TRUE(fov.ok()) << fov.error();
  ASSERT_TRUE(fov.value().circle.has_value());
  const fct::PixelCircle& circle = *fov.value().circle;
  std::printf("RF field of view: centre (%.1f, %.1f) px, radius %.1f px, background %.1f %%\n", circle.centre_px.x(),
              circle.centre_px.y(), circle.radius_px, 100.0 * fov.value().backgroundFraction);
  // The field spans (nearly) the full width and is cut at top and bottom.
  EXPECT_NEAR(circle.centre_px.x(), 255.5, 5.0);
  EXPECT_NEAR(circle.centre_px.y(), 231.5, 10.0);
  EXPECT_NEAR(circle.radius_px, 256.0, 8.0);
  EXPECT_GE(fov.value().edgeStep, 2.0) << "a real field edge is a step";
  // Every black (background) pixel is excluded.
  for (std::size_t i = 0; i < xray->pixels.size(); ++i) {
    if (xray->pixels[i] == 0.0f) {
      ASSERT_EQ(fov.value().mask.valid[i], 0) << "pixel " << i;
    }
  }
}
