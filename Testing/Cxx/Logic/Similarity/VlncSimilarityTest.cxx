#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Similarity/DynamicRoiSelector.h"
#include "Similarity/VlncSimilarity.h"
#include "SyntheticImages.h"

namespace {

fct::RoiSelection roisOf(const fct::FloatImage& image, double fraction) {
  return fct::DynamicRoiSelector::create(image, fct::ValidMask::allValid(image.cols, image.rows))
      .value()
      .selectFraction(fraction)
      .value();
}

}  // namespace

TEST(VlncSimilarity, IdenticalIsOneNegatedIsMinusOneAndLocalOffsetsAreIgnored) {
  const fct::FloatImage xray = fct::test::phantomImage();
  const fct::RoiSelection rois = roisOf(xray, 0.15);
  const auto vlnc = fct::VlncSimilarity::create(xray, rois);
  ASSERT_TRUE(vlnc.ok()) << vlnc.error();
  EXPECT_EQ(vlnc.value().windowCount(), rois.windows.size());
  EXPECT_NEAR(vlnc.value().evaluate(xray).value(), 1.0, 1e-6);
  EXPECT_NEAR(vlnc.value().evaluate(fct::test::affine(xray, -2.0f, 1.0f)).value(), -1.0, 1e-6);
  EXPECT_NEAR(vlnc.value().evaluate(fct::test::affine(xray, 0.5f, 300.0f)).value(), 1.0, 1e-6);
  // A different gain and offset in every 7x7 tile (e.g. uneven exposure) does not matter either.
  fct::FloatImage uneven = xray;
  for (int r = 0; r < xray.rows; ++r) {
    for (int c = 0; c < xray.cols; ++c) uneven.at(c, r) = (1.0f + 0.1f * (c / 7)) * xray.at(c, r) + 3.0f * (r / 7);
  }
  EXPECT_NEAR(vlnc.value().evaluate(uneven).value(), 1.0, 1e-6);
}

TEST(VlncSimilarity, IntensityDomainIgnoresAHazeThatBendsLineIntegrals) {
  // A DRR d of smooth line integrals from 1 to 7 (a thick patient) and the X-ray of the same patient with a scatter
  // haze: I = 0.8 exp(-d) + 0.01, whose line integrals -ln(I) are not an affine map of d within a window.
  fct::FloatImage drr = fct::FloatImage::filled(128, 112);
  for (int r = 0; r < drr.rows; ++r) {
    for (int c = 0; c < drr.cols; ++c) drr.at(c, r) = 4.0f + 3.0f * std::sin(0.2f * c) * std::cos(0.15f * r);
  }
  fct::FloatImage hazy = drr;
  for (float& p : hazy.pixels) p = -std::log(0.8f * std::exp(-p) + 0.01f);
  const fct::RoiSelection rois = roisOf(drr, 0.15);
  const auto intensity = fct::VlncSimilarity::create(hazy, rois, fct::VlncDomain::Intensity);
  const auto lineIntegral = fct::VlncSimilarity::create(hazy, rois, fct::VlncDomain::LineIntegral);
  ASSERT_TRUE(intensity.ok()) << intensity.error();
  ASSERT_TRUE(lineIntegral.ok()) << lineIntegral.error();
  EXPECT_NEAR(intensity.value().evaluate(drr).value(), 1.0, 1e-5);
  EXPECT_LT(lineIntegral.value().evaluate(drr).value(), 0.99);
  // Without haze a perfect match scores 1, and a DRR moved by 3 pixels scores clearly less.
  const auto clean = fct::VlncSimilarity::create(drr, rois, fct::VlncDomain::Intensity);
  ASSERT_TRUE(clean.ok());
  EXPECT_NEAR(clean.value().evaluate(drr).value(), 1.0, 1e-6);
  fct::FloatImage moved = drr;
  for (int r = 0; r < drr.rows; ++r) {
    for (int c = 0; c < drr.cols; ++c) moved.at(c, r) = drr.at(std::min(c + 3, drr.cols - 1), r);
  }
  EXPECT_LT(clean.value().evaluate(moved).value(), 0.97);
}

TEST(VlncSimilarity, IsTheVarianceWeightedSumOfWindowNccs) {
  // Two windows: X-ray variances 1 and 9 (weights 0.1, 0.9). The DRR matches the first and is constant in the second.
  fct::FloatImage xray = fct::FloatImage::filled(14, 7);
  fct::FloatImage drr = fct::FloatImage::filled(14, 7);
  for (int r = 0; r < 7; ++r) {
    for (int c = 0; c < 7; ++c) {
      const float sign = ((r + c) % 2) ? 1.0f : -1.0f;  // checkerboard: variance ~ amplitude^2
      xray.at(c, r) = sign;
      xray.at(c + 7, r) = 3.0f * sign;
      drr.at(c, r) = 5.0f * sign + 2.0f;
      drr.at(c + 7, r) = 4.0f;
    }
  }
  fct::RoiSelection rois;
  rois.windowSize = 7;
  rois.windows = {fct::RoiWindow{0, 0, 0, 0}, fct::RoiWindow{7, 0, 0, 0}};
  const auto vlnc = fct::VlncSimilarity::create(xray, rois);
  ASSERT_TRUE(vlnc.ok()) << vlnc.error();
  EXPECT_NEAR(vlnc.value().evaluate(drr).value(), 0.1, 1e-6);
  for (int r = 0; r < 7; ++r) {
    for (int c = 0; c < 7; ++c) drr.at(c + 7, r) = -xray.at(c + 7, r);  // now anti-correlated in window 2
  }
  EXPECT_NEAR(vlnc.value().evaluate(drr).value(), 0.1 - 0.9, 1e-6);
}

TEST(VlncSimilarity, TakesItsWeightsFromAWeightImageWhenGiven) {
  // The windows of IsTheVarianceWeightedSumOfWindowNccs, weighed by an image whose variances are 4 and 1 (weights
  // 0.8, 0.2) instead of the X-ray's 1 and 9: the NCCs are still the X-ray's.
  fct::FloatImage xray = fct::FloatImage::filled(14, 7);
  fct::FloatImage weights = fct::FloatImage::filled(14, 7);
  fct::FloatImage drr = fct::FloatImage::filled(14, 7);
  for (int r = 0; r < 7; ++r) {
    for (int c = 0; c < 7; ++c) {
      const float sign = ((r + c) % 2) ? 1.0f : -1.0f;
      xray.at(c, r) = sign;
      xray.at(c + 7, r) = 3.0f * sign;
      weights.at(c, r) = 2.0f * sign + 10.0f;
      weights.at(c + 7, r) = -sign;
      drr.at(c, r) = 5.0f * sign + 2.0f;
      drr.at(c + 7, r) = -xray.at(c + 7, r);  // anti-correlated in window 2
    }
  }
  fct::RoiSelection rois;
  rois.windowSize = 7;
  rois.windows = {fct::RoiWindow{0, 0, 0, 0}, fct::RoiWindow{7, 0, 0, 0}};
  const auto own = fct::VlncSimilarity::create(xray, rois);
  const auto weighed = fct::VlncSimilarity::create(xray, rois, fct::VlncDomain::LineIntegral, &weights);
  ASSERT_TRUE(own.ok()) << own.error();
  ASSERT_TRUE(weighed.ok()) << weighed.error();
  EXPECT_NEAR(own.value().evaluate(drr).value(), 0.1 - 0.9, 1e-6);
  EXPECT_NEAR(weighed.value().evaluate(drr).value(), 0.8 - 0.2, 1e-6);
  // A window where the weight image is constant weighs nothing, whatever the X-ray shows there.
  for (int r = 0; r < 7; ++r) {
    for (int c = 7; c < 14; ++c) weights.at(c, r) = 3.0f;
  }
  const auto oneWindow = fct::VlncSimilarity::create(xray, rois, fct::VlncDomain::LineIntegral, &weights);
  ASSERT_TRUE(oneWindow.ok());
  EXPECT_EQ(oneWindow.value().windowCount(), 1u);
  EXPECT_NEAR(oneWindow.value().evaluate(drr).value(), 1.0, 1e-6);
}

TEST(VlncSimilarity, RejectsNonFiniteWindowsAndAWeightImageOfAnotherSize) {
  const fct::FloatImage xray = fct::test::phantomImage(21, 14);
  fct::RoiSelection rois;
  rois.windowSize = 7;
  rois.windows = {fct::RoiWindow{7, 7, 0, 0}};
  const fct::FloatImage smaller = fct::test::phantomImage(21, 13);
  const auto wrongSize = fct::VlncSimilarity::create(xray, rois, fct::VlncDomain::LineIntegral, &smaller);
  ASSERT_FALSE(wrongSize.ok());
  EXPECT_NE(wrongSize.error().find("21x13"), std::string::npos) << wrongSize.error();
  fct::FloatImage broken = xray;
  broken.at(10, 10) = std::nanf("");
  const auto nonFinite = fct::VlncSimilarity::create(xray, rois, fct::VlncDomain::LineIntegral, &broken);
  ASSERT_FALSE(nonFinite.ok());
  EXPECT_NE(nonFinite.error().find("weight image"), std::string::npos) << nonFinite.error();
  const auto nanXray = fct::VlncSimilarity::create(broken, rois);
  ASSERT_FALSE(nanXray.ok()) << "a NaN in the X-ray is refused too";
  EXPECT_NE(nanXray.error().find("non-finite"), std::string::npos) << nanXray.error();
}

TEST(VlncSimilarity, ConstantXrayWindowsWeighNothing) {
  fct::FloatImage xray = fct::test::phantomImage(14, 7);
  for (int r = 0; r < 7; ++r) {
    for (int c = 7; c < 14; ++c) xray.at(c, r) = 2.0f;
  }
  fct::RoiSelection rois;
  rois.windowSize = 7;
  rois.windows = {fct::RoiWindow{0, 0, 0, 0}, fct::RoiWindow{7, 0, 0, 0}};
  const auto vlnc = fct::VlncSimilarity::create(xray, rois);
  ASSERT_TRUE(vlnc.ok());
  EXPECT_EQ(vlnc.value().windowCount(), 1u);
  EXPECT_NEAR(vlnc.value().evaluate(xray).value(), 1.0, 1e-6);
  const fct::FloatImage flat = fct::FloatImage::filled(14, 7, 1.0f);
  const auto none = fct::VlncSimilarity::create(flat, rois);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none.warnings().empty());
  EXPECT_EQ(none.value().evaluate(xray).value(), 0.0);
}

TEST(VlncSimilarity, RejectsEmptySelectionsForeignWindowsAndMismatchedSizes) {
  const fct::FloatImage xray = fct::test::phantomImage(21, 14);
  fct::RoiSelection rois;
  rois.windowSize = 7;
  EXPECT_FALSE(fct::VlncSimilarity::create(xray, rois).ok());
  rois.windows = {fct::RoiWindow{15, 0, 0, 0}};
  EXPECT_FALSE(fct::VlncSimilarity::create(xray, rois).ok());
  rois.windows = {fct::RoiWindow{14, 7, 0, 0}};
  const auto vlnc = fct::VlncSimilarity::create(xray, rois);
  ASSERT_TRUE(vlnc.ok());
  EXPECT_FALSE(vlnc.value().evaluate(fct::test::phantomImage(21, 15)).ok());
}
