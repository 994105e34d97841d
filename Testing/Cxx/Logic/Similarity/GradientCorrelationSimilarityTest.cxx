#include <gtest/gtest.h>

#include <cmath>

#include "Image/ValidMask.h"
#include "Similarity/GradientCorrelationSimilarity.h"
#include "SyntheticImages.h"

TEST(GradientCorrelationSimilarity, IdenticalIsOneNegatedIsMinusOneAndGainOffsetIsIgnored) {
  const fct::FloatImage xray = fct::test::phantomImage();
  const auto gc = fct::GradientCorrelationSimilarity::create(
      xray, fct::ValidMask::allValid(xray.cols, xray.rows).pixelList());
  ASSERT_TRUE(gc.ok()) << gc.error();
  EXPECT_EQ(gc.value().pixelCount(), static_cast<std::size_t>((xray.cols - 2) * (xray.rows - 2)));  // border dropped
  EXPECT_NEAR(gc.value().evaluate(xray).value(), 1.0, 1e-6);
  EXPECT_NEAR(gc.value().evaluate(fct::test::affine(xray, -1.0f, 3.0f)).value(), -1.0, 1e-6);
  EXPECT_NEAR(gc.value().evaluate(fct::test::affine(xray, 4.0f, -100.0f)).value(), 1.0, 1e-6);
}

TEST(GradientCorrelationSimilarity, DropsWhenTheDrrIsShiftedAndIsZeroForFlatDrr) {
  const fct::FloatImage xray = fct::test::phantomImage();
  const auto gc = fct::GradientCorrelationSimilarity::create(
      xray, fct::ValidMask::allValid(xray.cols, xray.rows).pixelList());
  ASSERT_TRUE(gc.ok());
  fct::FloatImage shifted = xray;
  for (int r = 0; r < xray.rows; ++r) {
    for (int c = 2; c < xray.cols; ++c) shifted.at(c, r) = xray.at(c - 2, r);
  }
  const double value = gc.value().evaluate(shifted).value();
  EXPECT_LT(value, 0.9);
  EXPECT_GT(value, -1.0);
  EXPECT_EQ(gc.value().evaluate(fct::FloatImage::filled(xray.cols, xray.rows, 7.0f)).value(), 0.0);
}

TEST(GradientCorrelationSimilarity, RejectsBorderOnlySetsForeignIndicesAndMismatchedSizes) {
  const fct::FloatImage xray = fct::test::phantomImage(16, 16);
  EXPECT_FALSE(fct::GradientCorrelationSimilarity::create(xray, {0, 1, 15, 255}).ok());
  EXPECT_FALSE(fct::GradientCorrelationSimilarity::create(xray, {}).ok());
  EXPECT_FALSE(fct::GradientCorrelationSimilarity::create(xray, {300}).ok());
  const auto gc = fct::GradientCorrelationSimilarity::create(xray, {17, 18, 40});
  ASSERT_TRUE(gc.ok());
  EXPECT_FALSE(gc.value().evaluate(fct::test::phantomImage(15, 16)).ok());
}
