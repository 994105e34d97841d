// MetalMaskReview: of two wire-shaped ridges the X-ray's detector takes for metal, the one the DRR shows too (anatomy)
// is given back and the one it lacks (a tool) stays excluded, whatever the DRR's scale; where the CT does not cover the
// rays nothing is judged; a DRR without either changes nothing; bad input fails.
#include <gtest/gtest.h>

#include "XrayPrep/MetalMaskDetector.h"
#include "XrayPrep/MetalMaskReview.h"

namespace {

/// A 160x120 line-integral image at 0.4 mm pixels: soft tissue 1.0 and 6 px (2.4 mm, a K-wire's shadow) wide vertical
/// ridges, rows 20..99, adding 2.5 at columns 38..43 (`anatomy`) and at columns 108..113 (`tool`).
fct::FloatImage ridges(bool anatomy, bool tool) {
  fct::FloatImage image = fct::FloatImage::filled(160, 120, 1.0f);
  for (int row = 20; row < 100; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      if ((anatomy && col >= 38 && col <= 43) || (tool && col >= 108 && col <= 113)) image.at(col, row) += 2.5f;
    }
  }
  return image;
}

/// The X-ray's metal mask as the preparation makes it (the detector's defaults at 0.4 mm pixels).
fct::ValidMask xrayMetalMask(const fct::FloatImage& xray, const fct::ValidMask& field) {
  auto metal = fct::MetalMaskDetector().detect(xray, field, 0.4);
  EXPECT_TRUE(metal.ok()) << metal.error();
  return metal.value().mask;
}

}  // namespace

TEST(MetalMaskReview, GivesBackTheRidgeTheDrrShowsAndKeepsTheTool) {
  const fct::ValidMask field = fct::ValidMask::allValid(160, 120);
  const fct::ValidMask xrayMask = xrayMetalMask(ridges(true, true), field);
  ASSERT_FALSE(xrayMask.isValid(41, 60)) << "the detector takes the anatomical ridge for metal";
  ASSERT_FALSE(xrayMask.isValid(111, 60));

  // The DRR shows the ridge one pixel to the side (a pose near, not at, the truth) and no tool, at 0.6 times the
  // X-ray's scale (its ridge alone would stand too low for the detector's 1.0).
  fct::FloatImage drr = fct::FloatImage::filled(160, 120, 0.6f);
  for (int row = 21; row < 101; ++row) {
    for (int col = 39; col <= 44; ++col) drr.at(col, row) += 0.6f * 2.5f;
  }
  auto reviewed = fct::MetalMaskReview().review(field, xrayMask, ridges(true, true), drr, field, 0.4);
  ASSERT_TRUE(reviewed.ok()) << reviewed.error();
  const fct::MetalMaskReviewOutcome& outcome = reviewed.value();
  EXPECT_EQ(outcome.piecesGivenBack, 1);
  EXPECT_EQ(outcome.piecesKept, 1);
  EXPECT_TRUE(outcome.mask.isValid(41, 60)) << "anatomy compared again";
  EXPECT_TRUE(outcome.mask.isValid(34, 60)) << "with its dilation";
  EXPECT_FALSE(outcome.mask.isValid(111, 60)) << "the tool stays out";
  std::size_t toolPixels = 0;
  for (std::size_t i = 0; i < xrayMask.valid.size(); ++i) toolPixels += xrayMask.valid[i] == 0 && (i % 160) > 80;
  // The tool stays out with the detector's dilation around its shadow (its ends may lose a few pixels).
  EXPECT_LE(outcome.metalPixelCount, toolPixels);
  EXPECT_GE(outcome.metalPixelCount, 0.9 * static_cast<double>(toolPixels));

  // Where the CT does not cover the rays (beyond its cut faces) the review cannot judge: the ridge stays out there.
  fct::ValidMask uncoveredLeft = field;
  for (int row = 0; row < 120; ++row) {
    for (int col = 0; col < 80; ++col) uncoveredLeft.valid[static_cast<std::size_t>(row) * 160 + col] = 0;
  }
  auto unjudged = fct::MetalMaskReview().review(field, xrayMask, ridges(true, true), drr, uncoveredLeft, 0.4);
  ASSERT_TRUE(unjudged.ok()) << unjudged.error();
  EXPECT_EQ(unjudged.value().piecesGivenBack, 0);
  EXPECT_FALSE(unjudged.value().mask.isValid(41, 60));
}

TEST(MetalMaskReview, ADrrWithoutTheRidgesChangesNothing) {
  const fct::ValidMask field = fct::ValidMask::allValid(160, 120);
  const fct::ValidMask xrayMask = xrayMetalMask(ridges(true, true), field);
  auto reviewed = fct::MetalMaskReview().review(field, xrayMask, ridges(true, true), ridges(false, false), field, 0.4);
  ASSERT_TRUE(reviewed.ok()) << reviewed.error();
  EXPECT_EQ(reviewed.value().piecesGivenBack, 0);
  EXPECT_EQ(reviewed.value().piecesKept, 2);
  EXPECT_FALSE(reviewed.value().mask.isValid(41, 60));
  EXPECT_FALSE(reviewed.value().mask.isValid(111, 60));
  const auto before = xrayMask.valid.size() - xrayMask.validCount();
  EXPECT_GE(reviewed.value().metalPixelCount, 0.9 * static_cast<double>(before));

  // No metal at all: nothing to review.
  auto clean = fct::MetalMaskReview().review(field, field, ridges(false, false), ridges(true, false), field, 0.4);
  ASSERT_TRUE(clean.ok()) << clean.error();
  EXPECT_EQ(clean.value().piecesKept + clean.value().piecesGivenBack, 0);
  EXPECT_EQ(clean.value().metalPixelCount, 0u);
}

TEST(MetalMaskReview, RejectsMismatchedSizesAndAMaskOutsideTheField) {
  const fct::ValidMask field = fct::ValidMask::allValid(160, 120);
  auto small = fct::MetalMaskReview().review(field, field, ridges(false, false), fct::FloatImage::filled(80, 60, 1.0f),
                                             field, 0.4);
  ASSERT_FALSE(small.ok());
  EXPECT_NE(small.error().find("80x60"), std::string::npos) << small.error();

  fct::ValidMask narrowField = field;
  narrowField.excludeMargin(10);
  auto outside =
      fct::MetalMaskReview().review(narrowField, field, ridges(false, false), ridges(false, false), field, 0.4);
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.error().find("outside the field"), std::string::npos) << outside.error();
}
