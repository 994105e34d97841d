// MetalMaskDetector: a dark (high line integral) thin bar is masked with its dilation, smooth bone and its edges are
// not, nor a skull-like rim as dense as the bar, invalid pixels stay invalid and are not counted, a clean image loses
// nothing, a short wire stub is metal only where the field's edge cuts it, a screw seen nearly end-on is found and a
// dense spot near a bone edge is not, a wire crossing a screw is still found, a wire crossing high-contrast bone is
// found, and bad input fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "XrayPrep/MetalMaskDetector.h"

namespace {

/// A 160x120 line-integral image: soft tissue 1.0, a bone disc (centre 60,60, radius 30) adding 1.2 with a smooth
/// 4 px edge, and optionally a 3 px wide vertical metal bar at columns 110..112, rows 20..99, adding `barExcess`.
fct::FloatImage boneImage(float barExcess) {
  fct::FloatImage image = fct::FloatImage::filled(160, 120, 1.0f);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const double r = std::hypot(col - 60.0, row - 60.0);
      image.at(col, row) += static_cast<float>(1.2 / (1.0 + std::exp((r - 30.0) / 1.0)));
      if (col >= 110 && col <= 112 && row >= 20 && row < 100) image.at(col, row) += barExcess;
    }
  }
  return image;
}

/// Adds `excess` to the pixels of `image` within `halfWidth_px` of the segment a-b (a wire or a screw shaft).
void addBar(fct::FloatImage& image, double ax, double ay, double bx, double by, double halfWidth_px, float excess) {
  const double dx = bx - ax, dy = by - ay, lengthSquared = dx * dx + dy * dy;
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const double t = std::clamp(((col - ax) * dx + (row - ay) * dy) / lengthSquared, 0.0, 1.0);
      if (std::hypot(col - ax - t * dx, row - ay - t * dy) <= halfWidth_px) image.at(col, row) += excess;
    }
  }
}

}  // namespace

TEST(MetalMaskDetector, MasksDarkBarWithDilationButNotBone) {
  const fct::ValidMask field = fct::ValidMask::allValid(160, 120);
  fct::MetalMaskOptions options;
  options.dilation_mm = 1.6;  // 4 px at the assumed 0.4 mm
  const auto metal = fct::MetalMaskDetector(options).detect(boneImage(3.0f), field);
  ASSERT_TRUE(metal.ok()) << metal.error();
  const fct::ValidMask& mask = metal.value().mask;
  EXPECT_FALSE(mask.isValid(111, 60));
  EXPECT_FALSE(mask.isValid(106, 60)) << "dilated by 4 px";
  EXPECT_TRUE(mask.isValid(105, 60));
  EXPECT_TRUE(mask.isValid(111, 10)) << "beyond the bar's end plus dilation";
  EXPECT_TRUE(mask.isValid(60, 60)) << "bone centre";
  EXPECT_TRUE(mask.isValid(30, 60)) << "bone edge";
  EXPECT_EQ(metal.value().metalPixelCount, static_cast<std::size_t>((3 + 8) * (80 + 8)));
}

TEST(MetalMaskDetector, OneSidedCurvedRimIsBoneNotMetal) {
  // At 1 mm pixels, a skull seen tangentially: outside the skull 0.2, inside 1.3, and along the inner surface (a circle
  // of radius 100 px) a rim standing 1.5 above the inside and 2.6 above the outside, as dense as the straight 3 px bar
  // beside it (adding 2.0 over 60 mm). The bar is metal, no pixel of the rim is.
  fct::FloatImage image = fct::FloatImage::filled(200, 120, 0.0f);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const double r = std::hypot(col - 100.0, row - 150.0);
      image.at(col, row) = static_cast<float>(0.2 + 1.1 / (1.0 + std::exp((r - 100.0) / 1.0)) +
                                              1.5 * std::exp(-0.5 * std::pow((r - 97.0) / 1.5, 2)));
      if (col >= 185 && col <= 187 && row >= 15 && row < 75) image.at(col, row) += 2.0f;
    }
  }
  const auto metal = fct::MetalMaskDetector().detect(image, fct::ValidMask::allValid(200, 120), 1.0);
  ASSERT_TRUE(metal.ok()) << metal.error();
  EXPECT_FALSE(metal.value().mask.isValid(186, 40)) << "the bar is metal";
  for (int col = 40; col <= 120; ++col) {
    const int rimRow = static_cast<int>(std::lround(150.0 - std::sqrt(97.0 * 97.0 - std::pow(col - 100.0, 2))));
    EXPECT_TRUE(metal.value().mask.isValid(col, rimRow)) << "rim at column " << col;
  }
}

TEST(MetalMaskDetector, CleanImageLosesNoPixel) {
  const fct::ValidMask field = fct::ValidMask::allValid(160, 120);
  const auto metal = fct::MetalMaskDetector().detect(boneImage(0.0f), field);
  ASSERT_TRUE(metal.ok()) << metal.error();
  EXPECT_EQ(metal.value().metalPixelCount, 0u);
  EXPECT_EQ(metal.value().mask.valid, field.valid);
}

TEST(MetalMaskDetector, IgnoresInvalidPixelsAroundTheField) {
  // Outside a circular field the line integral is at its clamp (black border); that must not raise the background
  // nor count as metal, and the bar inside the field is still found.
  fct::FloatImage image = boneImage(3.0f);
  fct::ValidMask field = fct::ValidMask::allValid(160, 120);
  field.excludeOutside(fct::PixelCircle{{80.0, 60.0}, 58.0});
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    if (!field.valid[i]) image.pixels[i] = 6.9f;
  }
  const auto metal = fct::MetalMaskDetector().detect(image, field);
  ASSERT_TRUE(metal.ok()) << metal.error();
  EXPECT_FALSE(metal.value().mask.isValid(111, 60));
  EXPECT_FALSE(metal.value().mask.isValid(0, 0)) << "invalid stays invalid";
  EXPECT_TRUE(metal.value().mask.isValid(80, 60));
  EXPECT_TRUE(metal.value().mask.isValid(30, 60));
}

TEST(MetalMaskDetector, RejectsSizeMismatchBadOptionsAndNaN) {
  const fct::FloatImage image = boneImage(0.0f);
  EXPECT_FALSE(fct::MetalMaskDetector().detect(image, fct::ValidMask::allValid(10, 10)).ok());
  fct::MetalMaskOptions badWindow;
  badWindow.narrowWindow_mm = 0.0;
  EXPECT_FALSE(fct::MetalMaskDetector(badWindow).detect(image, fct::ValidMask::allValid(160, 120)).ok());
  fct::MetalMaskOptions badExcess;
  badExcess.minExcess = 0.0;
  EXPECT_FALSE(fct::MetalMaskDetector(badExcess).detect(image, fct::ValidMask::allValid(160, 120)).ok());
  fct::FloatImage withNan = image;
  withNan.at(5, 5) = std::nanf("");
  const auto failed = fct::MetalMaskDetector().detect(withNan, fct::ValidMask::allValid(160, 120));
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.error().find("non-finite"), std::string::npos) << failed.error();
}

TEST(MetalMaskDetector, WindowInMillimetresFollowsThePixelSpacing) {
  // At 0.5 mm pixels the 30 mm window is 60 px, wider than the 3 px bar: found. At 10 mm pixels the window (3 px) is
  // as narrow as the bar, which then is not a narrow ridge.
  const fct::ValidMask field = fct::ValidMask::allValid(160, 120);
  const fct::FloatImage image = boneImage(3.0f);
  const auto fine = fct::MetalMaskDetector().detect(image, field, 0.5);
  ASSERT_TRUE(fine.ok()) << fine.error();
  EXPECT_FALSE(fine.value().mask.isValid(111, 60));
  const auto coarse = fct::MetalMaskDetector().detect(image, field, 10.0);
  ASSERT_TRUE(coarse.ok()) << coarse.error();
  EXPECT_TRUE(coarse.value().mask.isValid(111, 60));
  EXPECT_FALSE(fct::MetalMaskDetector().detect(image, field, -1.0).ok());
}

TEST(MetalMaskDetector, ShortWireStubIsMetalOnlyWhereTheFieldEdgeCutsIt) {
  // At 0.4 mm pixels a thin steel wire (adding 1.8) shows 8 mm of itself where it enters through the bottom edge, and
  // another 8 mm piece of wire lies inside the field. Only the first can be part of a longer wire.
  fct::FloatImage image = boneImage(0.0f);
  addBar(image, 140.0, 100.0, 140.0, 125.0, 1.0, 1.8f);
  addBar(image, 20.0, 20.0, 20.0, 40.0, 1.0, 1.8f);
  const auto metal = fct::MetalMaskDetector().detect(image, fct::ValidMask::allValid(160, 120), 0.4);
  ASSERT_TRUE(metal.ok()) << metal.error();
  EXPECT_FALSE(metal.value().mask.isValid(140, 110)) << "the stub cut by the field edge";
  EXPECT_TRUE(metal.value().mask.isValid(20, 30)) << "a short mark inside the field is not seeded";
}

TEST(MetalMaskDetector, ScrewSeenNearlyEndOnIsMetalButADenseSpotNearTheBoneEdgeIsNot) {
  // At 0.4 mm pixels: a titanium screw tilted toward the beam shows its head (a disc of 8 mm, adding 1.8) and a 4 mm
  // stub of shaft, too short for a bar. A spot as dense (a disc of 6.4 mm) lies inside the bone disc 4 mm from its
  // edge: bone around it on one side, soft tissue a few mm beyond on the other, as a dense spot of bone has.
  fct::FloatImage image = boneImage(0.0f);
  addBar(image, 125.0, 35.0, 125.01, 35.0, 10.0, 1.8f);
  addBar(image, 125.0, 35.0, 131.0, 40.0, 5.0, 0.8f);
  addBar(image, 60.0, 78.0, 60.01, 78.0, 8.0, 1.8f);
  const auto metal = fct::MetalMaskDetector().detect(image, fct::ValidMask::allValid(160, 120), 0.4);
  ASSERT_TRUE(metal.ok()) << metal.error();
  EXPECT_FALSE(metal.value().mask.isValid(125, 35)) << "the screw's head";
  EXPECT_FALSE(metal.value().mask.isValid(130, 39)) << "the stub of shaft";
  EXPECT_TRUE(metal.value().mask.isValid(60, 78)) << "the dense spot near the bone edge";
}

TEST(MetalMaskDetector, WireCrossingAScrewIsStillFoundAsAStraightBar) {
  // At 0.4 mm pixels a 60 mm steel wire (adding 1.8) crosses the end of a titanium screw shaft (7 px wide, adding
  // 1.5): together they make one T-shaped piece that is not straight as a whole.
  fct::FloatImage image = fct::FloatImage::filled(240, 200, 1.0f);
  addBar(image, 30.0, 40.0, 180.0, 40.0, 1.0, 1.8f);
  addBar(image, 160.0, 30.0, 160.0, 80.0, 3.0, 1.5f);
  const auto metal = fct::MetalMaskDetector().detect(image, fct::ValidMask::allValid(240, 200), 0.4);
  ASSERT_TRUE(metal.ok()) << metal.error();
  EXPECT_FALSE(metal.value().mask.isValid(60, 40)) << "the wire";
  EXPECT_FALSE(metal.value().mask.isValid(160, 45)) << "the screw where the wire meets it";
  EXPECT_TRUE(metal.value().mask.isValid(60, 150)) << "soft tissue";
}

TEST(MetalMaskDetector, WireCrossingHighContrastBoneIsMetal) {
  // At 0.4 mm pixels a 60 mm steel wire (adding 1.6) crosses a 40 mm slab of dense bone (adding 2.0 over soft tissue),
  // as a K-wire crosses the skull base in a lateral view: within 15 mm of the slab's edges the bone's own contrast is
  // 1.25 times the wire's excess. The wire is metal along its whole length, the slab's edges are not. A detector that
  // takes only candidates with less bone contrast than 0.7 times their excess cuts the wire into short pieces and
  // finds none of it.
  fct::FloatImage image = fct::FloatImage::filled(240, 200, 1.0f);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      image.at(col, row) += static_cast<float>(2.0 / (1.0 + std::exp((70.0 - col) / 1.0)) /
                                               (1.0 + std::exp((col - 170.0) / 1.0)));
    }
  }
  addBar(image, 45.0, 100.0, 195.0, 100.0, 1.0, 1.6f);
  const fct::ValidMask field = fct::ValidMask::allValid(240, 200);
  const auto metal = fct::MetalMaskDetector().detect(image, field, 0.4);
  ASSERT_TRUE(metal.ok()) << metal.error();
  for (int col : {50, 80, 120, 160, 190}) {
    EXPECT_FALSE(metal.value().mask.isValid(col, 100)) << "wire at column " << col;
  }
  EXPECT_TRUE(metal.value().mask.isValid(70, 30)) << "the slab's edge";
  EXPECT_TRUE(metal.value().mask.isValid(120, 30)) << "the slab";
  fct::MetalMaskOptions tight;
  tight.maxContrastRatio = 0.7;
  const auto tightMetal = fct::MetalMaskDetector(tight).detect(image, field, 0.4);
  ASSERT_TRUE(tightMetal.ok()) << tightMetal.error();
  EXPECT_EQ(tightMetal.value().metalPixelCount, 0u);
}
