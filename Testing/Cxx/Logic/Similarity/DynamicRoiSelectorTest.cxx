#include <gtest/gtest.h>

#include <cmath>

#include "Similarity/DynamicRoiSelector.h"
#include "SyntheticImages.h"
#include "TestSupport.h"
#include "TestXrayLoader.h"
#include "XrayPrep/XrayPreparation.h"

namespace {

/// 70x49 image: a vertical step edge between columns 31 and 32 on otherwise flat areas (plus faint noise-free ramp).
fct::FloatImage stepEdge() {
  fct::FloatImage image = fct::FloatImage::filled(70, 49);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) image.at(c, r) = (c >= 32 ? 10.0f : 2.0f) + 0.001f * static_cast<float>(r);
  }
  return image;
}

}  // namespace

TEST(DynamicRoiSelector, SelectsTheWindowsOnAnEdgeAndNotTheFlatAreas) {
  const fct::FloatImage image = stepEdge();
  const auto selector = fct::DynamicRoiSelector::create(image, fct::ValidMask::allValid(70, 49), 7);
  ASSERT_TRUE(selector.ok()) << selector.error();
  EXPECT_EQ(selector.value().candidateCount(), 10u * 7u);
  const auto selection = selector.value().selectAboveThreshold(0.5);
  ASSERT_TRUE(selection.ok()) << selection.error();
  ASSERT_EQ(selection.value().windows.size(), 7u);  // the column of windows 28..34 that straddles the edge
  for (const fct::RoiWindow& w : selection.value().windows) EXPECT_EQ(w.col0, 28);
  EXPECT_EQ(selection.value().pixels.size(), 7u * 49u);
  EXPECT_EQ(selection.value().pixels[49], 7 * 70 + 28);  // window 1 starts at its top-left pixel
  EXPECT_NEAR(selection.value().keptFraction, 7.0 * 49.0 / (70.0 * 49.0), 1e-12);
}

TEST(DynamicRoiSelector, NormalizedVarianceIgnoresGainAndOffset) {
  const fct::FloatImage image = fct::test::phantomImage();
  const fct::ValidMask all = fct::ValidMask::allValid(image.cols, image.rows);
  const auto a = fct::DynamicRoiSelector::create(image, all).value().selectFraction(0.12);
  const auto b = fct::DynamicRoiSelector::create(fct::test::affine(image, -3.0f, 40.0f), all).value().selectFraction(0.12);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.value().pixels, b.value().pixels);
}

TEST(DynamicRoiSelector, DropsWindowsWithAnyMaskedPixel) {
  const fct::FloatImage image = stepEdge();
  fct::ValidMask mask = fct::ValidMask::allValid(70, 49);
  mask.valid[10 * 70 + 30] = 0;  // inside edge window (28, 7)
  const auto selector = fct::DynamicRoiSelector::create(image, mask, 7);
  ASSERT_TRUE(selector.ok());
  EXPECT_EQ(selector.value().candidateCount(), 69u);
  const auto selection = selector.value().selectAboveThreshold(0.5);
  ASSERT_TRUE(selection.ok());
  EXPECT_EQ(selection.value().windows.size(), 6u);
  for (const std::int32_t i : selection.value().pixels) EXPECT_EQ(mask.valid[static_cast<std::size_t>(i)], 1);
}

TEST(DynamicRoiSelector, FractionSelectionsMatchTheTargetAndAreNested) {
  const fct::FloatImage image = fct::test::phantomImage();
  const auto selector = fct::DynamicRoiSelector::create(image, fct::ValidMask::allValid(image.cols, image.rows));
  ASSERT_TRUE(selector.ok());
  const double windowFraction = 49.0 / static_cast<double>(image.pixels.size());
  std::size_t previous = 0;
  for (const double target : {0.05, 0.10, 0.15, 0.30}) {
    const auto selection = selector.value().selectFraction(target);
    ASSERT_TRUE(selection.ok()) << selection.error();
    EXPECT_NEAR(selection.value().keptFraction, target, windowFraction);
    EXPECT_GE(selection.value().windows.size(), previous);
    previous = selection.value().windows.size();
    // Thresholding at the reported threshold gives back the same windows.
    const auto same = selector.value().selectAboveThreshold(selection.value().threshold);
    ASSERT_TRUE(same.ok());
    EXPECT_GE(same.value().windows.size(), selection.value().windows.size());
  }
  EXPECT_EQ(selector.value().selectAll().windows.size(), selector.value().candidateCount());
}

TEST(DynamicRoiSelector, RejectsConstantImagesBadSizesAndEmptySelections) {
  const fct::ValidMask all = fct::ValidMask::allValid(20, 20);
  const auto constant = fct::DynamicRoiSelector::create(fct::FloatImage::filled(20, 20, 3.0f), all);
  ASSERT_FALSE(constant.ok());
  EXPECT_NE(constant.error().find("constant"), std::string::npos);
  const fct::FloatImage image = fct::test::phantomImage(20, 20);
  EXPECT_FALSE(fct::DynamicRoiSelector::create(image, all, 1).ok());
  EXPECT_FALSE(fct::DynamicRoiSelector::create(image, fct::ValidMask::allValid(20, 21)).ok());
  EXPECT_FALSE(fct::DynamicRoiSelector::create(image, all, 21).ok());  // no complete window
  const auto selector = fct::DynamicRoiSelector::create(image, all);
  ASSERT_TRUE(selector.ok());
  const auto none = selector.value().selectAboveThreshold(1e9);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().find("lower the threshold"), std::string::npos);
  EXPECT_FALSE(selector.value().selectFraction(0.0).ok());
  EXPECT_FALSE(selector.value().selectFraction(1.5).ok());
}

TEST(DynamicRoiSelector, RoisOnRealShoulderAvoidCollimatorAndBackground) {
  FCT_REQUIRE_DATA("xray/rf_shoulder_kwire.dcm");
  const auto xray = fct::test::loadXrayWithDcmtk(fct::test::dataDir() / "xray/rf_shoulder_kwire.dcm");
  ASSERT_TRUE(xray.has_value());
  const auto prepared = fct::XrayPreparation().prepare(*xray);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const fct::PixelCircle fov = *prepared.value().fieldOfView;
  for (int level = 0; level < 3; ++level) {
    const fct::PyramidLevel& l = prepared.value().pyramid.level(level);
    const auto selector = fct::DynamicRoiSelector::create(l.image, l.mask, 7);
    ASSERT_TRUE(selector.ok()) << selector.error();
    const auto selection = selector.value().selectFraction(0.12);
    ASSERT_TRUE(selection.ok()) << selection.error();
    EXPECT_NEAR(selection.value().keptFraction, 0.12, 0.005) << "level " << level;
    const double scale = 1 << level;
    // Level-k pixel (c,r) covers level-0 pixels centred at scale*(c,r) + (scale-1)/2.
    int histogram[8] = {0};  // ROI pixels by distance inside the boundary, 4 px (level 0) bins
    int onWire = 0;
    for (const std::int32_t i : selection.value().pixels) {
      const double c0 = scale * (i % l.image.cols) + 0.5 * (scale - 1);
      const double r0 = scale * (i / l.image.cols) + 0.5 * (scale - 1);
      const double inside_px = fov.radius_px - std::hypot(c0 - fov.centre_px.x(), r0 - fov.centre_px.y());
      if (inside_px < 32.0) ++histogram[static_cast<int>(std::max(0.0, inside_px) / 4.0)];
      ASSERT_GT(xray->at(static_cast<int>(c0), static_cast<int>(r0)), 0.0f) << "ROI pixel on the black background";
      if (r0 >= 90 && r0 <= 112 && c0 >= 110 && c0 <= 380) ++onWire;
    }
    std::printf("level %d: %zu windows, kept %.3f, threshold nv %.3f, on K-wire %d px, near boundary (4 px bins):",
                level, selection.value().windows.size(), selection.value().keptFraction, selection.value().threshold,
                onWire);
    for (int h : histogram) std::printf(" %d", h);
    std::printf("\n");
    // The collimator band (the 12 px inside the detected boundary, and everything outside it) holds no ROI pixel.
    EXPECT_EQ(histogram[0] + histogram[1] + histogram[2], 0) << "level " << level;
    // The K-wire's edges attract ROIs: its box (22 x 271 level-0 px) is covered far above the 12 % average.
    const double wireBoxPixels = 23.0 * 271.0 / (scale * scale);
    EXPECT_GT(onWire / wireBoxPixels, 0.4) << "level " << level;
  }
}
