#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.h"
#include "TestXrayLoader.h"
#include "XrayPrep/XrayPreparation.h"

TEST(XrayPreparation, PreparesRealShoulderFluoroscopyIntoThreeLevels) {
  FCT_REQUIRE_DATA("xray/rf_shoulder_kwire.dcm");
  const auto xray = fct::test::loadXrayWithDcmtk(fct::test::dataDir() / "xray/rf_shoulder_kwire.dcm");
  ASSERT_TRUE(xray.has_value());
  const auto prepared = fct::XrayPreparation().prepare(*xray);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const fct::PreparedXray& p = prepared.value();
  ASSERT_EQ(p.pyramid.levelCount(), 3);
  EXPECT_EQ(p.pyramid.level(1).image.cols, 256);
  EXPECT_EQ(p.pyramid.level(2).image.cols, 128);
  EXPECT_EQ(p.pyramid.level(2).image.rows, 116);
  ASSERT_TRUE(p.fieldOfView.has_value());
  EXPECT_GT(p.validFraction, 0.6);
  EXPECT_LT(p.validFraction, 0.84);  // at most the non-black part
  EXPECT_GT(p.referenceIntensity, 200.0);  // the saturated direct exposure at the top
  std::printf("RF prepared: valid %.1f %% of level 0, I0 = %.1f\n", 100.0 * p.validFraction, p.referenceIntensity);
  // The dense K-wire (dark in the image) has a larger line integral than the soft tissue beside it.
  const fct::FloatImage& level0 = p.pyramid.level(0).image;
  EXPECT_GT(level0.at(250, 101), level0.at(250, 115) + 0.3f);
}

TEST(XrayPreparation, ExcludesGivenSpheresMarginAndOwnFovMask) {
  fct::XrayImage xray;
  xray.cols = 64;
  xray.rows = 48;
  xray.pixels.assign(64u * 48u, 1000.0f);
  for (int i = 0; i < 64 * 48; ++i) xray.pixels[static_cast<std::size_t>(i)] -= static_cast<float>(i % 64);
  xray.fovMask.assign(64u * 48u, 1);
  xray.fovMask[20 * 64 + 40] = 0;
  fct::XrayPreparationOptions options;
  options.detectFieldOfView = false;
  options.margin_px = 3;
  options.spheres = {fct::PixelCircle{{20.0, 20.0}, 3.0}};
  options.sphereMargin_px = 1.0;
  options.levelCount = 2;
  const auto prepared = fct::XrayPreparation(options).prepare(xray);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const fct::ValidMask& mask = prepared.value().pyramid.level(0).mask;
  EXPECT_FALSE(mask.isValid(2, 20));
  EXPECT_FALSE(mask.isValid(20, 24));  // radius 3 + 1 px margin
  EXPECT_TRUE(mask.isValid(20, 25));
  EXPECT_FALSE(mask.isValid(40, 20));
  EXPECT_TRUE(mask.isValid(41, 20));
  EXPECT_FALSE(prepared.value().fieldOfView.has_value());
}

TEST(XrayPreparation, DetectsDarkCalibrationSpheres) {
  fct::XrayImage xray;
  xray.cols = 160;
  xray.rows = 120;
  xray.pixels.resize(160u * 120u);
  const std::vector<fct::PixelCircle> truth = {{{40.0, 30.0}, 6.0}, {{100.5, 70.0}, 6.0}, {{60.0, 90.0}, 7.0}};
  for (int r = 0; r < 120; ++r) {
    for (int c = 0; c < 160; ++c) {
      float v = 800.0f + 2.0f * static_cast<float>(c);
      for (const auto& s : truth) {
        if (s.contains(c, r)) v = 150.0f;
      }
      if (std::hypot(c - 130.0, r - 30.0) < 6.0) v = 1200.0f;  // a bright disc is not a sphere
      xray.pixels[static_cast<std::size_t>(r) * 160 + c] = v;
    }
  }
  fct::XrayPreparationOptions options;
  options.detectFieldOfView = false;
  options.detectSpheres = true;
  const auto prepared = fct::XrayPreparation(options).prepare(xray);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const auto& found = prepared.value().spheres;
  ASSERT_EQ(found.size(), truth.size());
  for (const auto& s : truth) {
    const auto match = std::find_if(found.begin(), found.end(), [&](const fct::PixelCircle& f) {
      return (f.centre_px - s.centre_px).norm() < 1.5 && std::abs(f.radius_px - s.radius_px) < 1.5;
    });
    EXPECT_NE(match, found.end()) << "sphere at " << s.centre_px.transpose();
  }
  EXPECT_FALSE(prepared.value().pyramid.level(0).mask.isValid(40, 30));
  EXPECT_TRUE(prepared.value().pyramid.level(0).mask.isValid(130, 30));
}

TEST(XrayPreparation, RejectsInconsistentImagesAndMasksThatLeaveNothing) {
  fct::XrayImage xray;
  xray.cols = 10;
  xray.rows = 10;
  xray.pixels.assign(99, 1.0f);
  EXPECT_FALSE(fct::XrayPreparation().prepare(xray).ok());
  xray.pixels.assign(100, 1.0f);
  xray.fovMask.assign(50, 1);
  EXPECT_FALSE(fct::XrayPreparation().prepare(xray).ok());
  xray.fovMask.clear();
  fct::XrayPreparationOptions options;
  options.detectFieldOfView = false;
  options.margin_px = 5;
  const auto result = fct::XrayPreparation(options).prepare(xray);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("margin"), std::string::npos) << result.error();
}

TEST(XrayPreparation, ExcludesMetalShadowAndReportsItsFractionUnlessSwitchedOff) {
  // A smooth bright-to-dark ramp (soft tissue and bone) with a 4 px wide wire passing 3 % of the signal.
  fct::XrayImage xray;
  xray.cols = 128;
  xray.rows = 96;
  xray.pixels.resize(128u * 96u);
  for (int row = 0; row < 96; ++row) {
    for (int col = 0; col < 128; ++col) {
      float intensity = 3000.0f * std::exp(-0.01f * static_cast<float>(col));
      if (col >= 60 && col < 64) intensity *= 0.03f;
      xray.pixels[static_cast<std::size_t>(row) * 128 + col] = intensity;
    }
  }
  fct::XrayPreparationOptions options;
  options.detectFieldOfView = false;
  options.margin_px = 2;
  options.levelCount = 1;
  const auto prepared = fct::XrayPreparation(options).prepare(xray);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const fct::ValidMask& mask = prepared.value().pyramid.level(0).mask;
  EXPECT_FALSE(mask.isValid(61, 48));
  EXPECT_FALSE(mask.isValid(58, 48)) << "dilated";
  EXPECT_TRUE(mask.isValid(20, 48));
  EXPECT_TRUE(mask.isValid(110, 48));
  // The wire and the 2.7 mm dilation each side (7 px at the assumed 0.4 mm pixels), of the field columns.
  const double wireFraction = (4.0 + 2 * 7) / (128.0 - 4);
  EXPECT_NEAR(prepared.value().metalFraction, wireFraction, 1e-9);

  options.excludeMetal = false;
  const auto kept = fct::XrayPreparation(options).prepare(xray);
  ASSERT_TRUE(kept.ok()) << kept.error();
  EXPECT_TRUE(kept.value().pyramid.level(0).mask.isValid(61, 48));
  EXPECT_EQ(kept.value().metalFraction, 0.0);
}
