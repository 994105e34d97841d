#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "Image/ValidMask.h"
#include "Similarity/NccSimilarity.h"
#include "SyntheticImages.h"

namespace {

fct::PixelIndexList everyPixel(const fct::FloatImage& image) {
  return fct::ValidMask::allValid(image.cols, image.rows).pixelList();
}

}  // namespace

TEST(NccSimilarity, IdenticalIsOneNegatedIsMinusOneAndGainOffsetIsIgnored) {
  const fct::FloatImage xray = fct::test::phantomImage();
  const auto ncc = fct::NccSimilarity::create(xray, everyPixel(xray));
  ASSERT_TRUE(ncc.ok()) << ncc.error();
  EXPECT_NEAR(ncc.value().evaluate(xray).value(), 1.0, 1e-6);
  EXPECT_NEAR(ncc.value().evaluate(fct::test::affine(xray, -1.0f, 0.0f)).value(), -1.0, 1e-6);
  EXPECT_NEAR(ncc.value().evaluate(fct::test::affine(xray, 0.02f, 50.0f)).value(), 1.0, 1e-6);
  EXPECT_NEAR(ncc.value().evaluate(fct::test::affine(xray, 350.0f, -7.0f)).value(), 1.0, 1e-6);
  EXPECT_EQ(ncc.value().name(), "NCC");
}

TEST(NccSimilarity, MatchesTextbookFormulaOnASubset) {
  std::mt19937 random(7);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  const fct::FloatImage xray = fct::test::phantomImage();
  fct::FloatImage drr = xray;
  for (float& v : drr.pixels) v = 1000.0f + v + 0.7f * noise(random);
  fct::PixelIndexList subset;
  for (std::int32_t i = 3; i < static_cast<std::int32_t>(xray.pixels.size()); i += 5) subset.push_back(i);
  double mx = 0, md = 0;
  for (const auto i : subset) {
    mx += xray.pixels[i];
    md += drr.pixels[i];
  }
  mx /= subset.size();
  md /= subset.size();
  double sxd = 0, sxx = 0, sdd = 0;
  for (const auto i : subset) {
    sxd += (xray.pixels[i] - mx) * (drr.pixels[i] - md);
    sxx += (xray.pixels[i] - mx) * (xray.pixels[i] - mx);
    sdd += (drr.pixels[i] - md) * (drr.pixels[i] - md);
  }
  const double expected = sxd / std::sqrt(sxx * sdd);
  const auto ncc = fct::NccSimilarity::create(xray, subset);
  ASSERT_TRUE(ncc.ok());
  EXPECT_EQ(ncc.value().pixelCount(), subset.size());
  EXPECT_NEAR(ncc.value().evaluate(drr).value(), expected, 1e-6);
  EXPECT_GT(expected, 0.3);
  EXPECT_LT(expected, 0.99);
}

TEST(NccSimilarity, ConstantImagesGiveZeroNotNaN) {
  const fct::FloatImage xray = fct::test::phantomImage();
  const auto ncc = fct::NccSimilarity::create(xray, everyPixel(xray));
  ASSERT_TRUE(ncc.ok());
  const auto flatDrr = ncc.value().evaluate(fct::FloatImage::filled(xray.cols, xray.rows, 12345.678f));
  ASSERT_TRUE(flatDrr.ok());
  EXPECT_EQ(flatDrr.value(), 0.0);
  const fct::FloatImage flatXray = fct::FloatImage::filled(xray.cols, xray.rows, 0.3f);
  const auto flat = fct::NccSimilarity::create(flatXray, everyPixel(flatXray));
  ASSERT_TRUE(flat.ok());
  EXPECT_FALSE(flat.warnings().empty());
  EXPECT_EQ(flat.value().evaluate(xray).value(), 0.0);
}

TEST(NccSimilarity, RejectsEmptySetsForeignIndicesMismatchedSizesAndNaN) {
  const fct::FloatImage xray = fct::test::phantomImage(16, 16);
  EXPECT_FALSE(fct::NccSimilarity::create(xray, {}).ok());
  EXPECT_FALSE(fct::NccSimilarity::create(xray, {0, 256}).ok());
  EXPECT_FALSE(fct::NccSimilarity::create(xray, {-1}).ok());
  const auto ncc = fct::NccSimilarity::create(xray, everyPixel(xray));
  ASSERT_TRUE(ncc.ok());
  EXPECT_FALSE(ncc.value().evaluate(fct::test::phantomImage(16, 17)).ok());
  fct::FloatImage withNaN = xray;
  withNaN.at(5, 5) = std::nanf("");
  EXPECT_FALSE(ncc.value().evaluate(withNaN).ok());
}
