// ImageSimilarity contract: every similarity measure, called through the interface, gives its best value (1) for
// identical images and its worst (-1) for a negated DRR, ignores a gain and offset of the DRR, gives 0 (not NaN) for a
// constant DRR or X-ray as documented, fails on NaN or infinity in a compared DRR pixel and ignores it elsewhere, and
// fails on a size mismatch naming both sizes. A new measure joins by adding a traits specialisation and its type to
// ContractSimilarities.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>

#include "Similarity/DynamicRoiSelector.h"
#include "Similarity/GradientCorrelationSimilarity.h"
#include "Similarity/NccSimilarity.h"
#include "Similarity/VlncSimilarity.h"
#include "SyntheticImages.h"

namespace {

/// Pixels compared by every measure here: all but a margin of this many pixels, so a pixel in the margin (e.g. (0,0))
/// is not compared, not even as the 3x3 neighbour of a compared one (gradient correlation).
constexpr int kMargin = 4;

/// Linear indices of the pixels at least kMargin from the border.
fct::PixelIndexList interiorPixels(const fct::FloatImage& image) {
  fct::PixelIndexList pixels;
  for (int r = kMargin; r < image.rows - kMargin; ++r) {
    for (int c = kMargin; c < image.cols - kMargin; ++c) pixels.push_back(r * image.cols + c);
  }
  return pixels;
}

/// How the contract makes each measure on an X-ray: its own kind of compared set over the interior pixels.
template <typename Similarity>
struct SimilarityTraits;

template <>
struct SimilarityTraits<fct::NccSimilarity> {
  static fct::Result<fct::NccSimilarity> create(const fct::FloatImage& xray) {
    return fct::NccSimilarity::create(xray, interiorPixels(xray));
  }
};

template <>
struct SimilarityTraits<fct::GradientCorrelationSimilarity> {
  static fct::Result<fct::GradientCorrelationSimilarity> create(const fct::FloatImage& xray) {
    return fct::GradientCorrelationSimilarity::create(xray, interiorPixels(xray));
  }
};

template <>
struct SimilarityTraits<fct::VlncSimilarity> {
  /// VLNC compares windows, not a pixel list: every 7x7 window inside the margin. (The dynamic ROIs would choose
  /// among them by X-ray variance, and refuse a constant X-ray before VLNC could show how it handles one.)
  static fct::Result<fct::VlncSimilarity> create(const fct::FloatImage& xray) {
    fct::RoiSelection windows;
    windows.windowSize = 7;
    for (int r = kMargin; r + 7 <= xray.rows - kMargin; r += 7) {
      for (int c = kMargin; c + 7 <= xray.cols - kMargin; c += 7) windows.windows.push_back(fct::RoiWindow{c, r, 0, 0});
    }
    return fct::VlncSimilarity::create(xray, windows);
  }
};

template <typename Similarity>
class ImageSimilarityContract : public ::testing::Test {
 protected:
  using Traits = SimilarityTraits<Similarity>;
  const fct::FloatImage xray = fct::test::phantomImage();

  /// The phantom shifted right by 2 px with a little noise: a DRR at a slightly wrong pose.
  fct::FloatImage nearMiss() const {
    fct::FloatImage drr = xray;
    std::mt19937 random(3);
    std::normal_distribution<float> noise(0.0f, 0.05f);
    for (int r = 0; r < xray.rows; ++r) {
      for (int c = 0; c < xray.cols; ++c) drr.at(c, r) = xray.at(std::max(0, c - 2), r) + noise(random);
    }
    return drr;
  }
};

using ContractSimilarities =
    ::testing::Types<fct::NccSimilarity, fct::VlncSimilarity, fct::GradientCorrelationSimilarity>;
TYPED_TEST_SUITE(ImageSimilarityContract, ContractSimilarities);

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TYPED_TEST(ImageSimilarityContract, IdenticalImagesGiveTheBestValueAndANegatedDrrTheWorst) {
  const auto created = TestFixture::Traits::create(this->xray);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_TRUE(created.warnings().empty());
  const fct::ImageSimilarity& measure = created.value();
  EXPECT_FALSE(measure.name().empty());
  EXPECT_EQ(measure.cols(), this->xray.cols);
  EXPECT_EQ(measure.rows(), this->xray.rows);
  const auto same = measure.evaluate(this->xray);
  ASSERT_TRUE(same.ok()) << same.error();
  EXPECT_NEAR(same.value(), 1.0, 1e-6);
  const auto negated = measure.evaluate(fct::test::affine(this->xray, -1.0f, 0.0f));
  ASSERT_TRUE(negated.ok()) << negated.error();
  EXPECT_NEAR(negated.value(), -1.0, 1e-6);
  const auto miss = measure.evaluate(this->nearMiss());
  ASSERT_TRUE(miss.ok()) << miss.error();
  EXPECT_LT(miss.value(), same.value() - 0.01);
  EXPECT_GT(miss.value(), -1.0);
}

TYPED_TEST(ImageSimilarityContract, GainAndOffsetOfTheDrrDoNotChangeTheValue) {
  const auto created = TestFixture::Traits::create(this->xray);
  ASSERT_TRUE(created.ok()) << created.error();
  const fct::ImageSimilarity& measure = created.value();
  const fct::FloatImage drr = this->nearMiss();
  const double reference = measure.evaluate(drr).value();
  for (const auto& [gain, offset] : {std::pair{0.02f, 50.0f}, std::pair{3.0f, -7.0f}, std::pair{350.0f, 1000.0f}}) {
    const auto scaled = measure.evaluate(fct::test::affine(drr, gain, offset));
    ASSERT_TRUE(scaled.ok()) << scaled.error();
    EXPECT_NEAR(scaled.value(), reference, 1e-4) << "gain " << gain << ", offset " << offset;
  }
}

TYPED_TEST(ImageSimilarityContract, ConstantDrrGivesZeroNotNaN) {
  const auto created = TestFixture::Traits::create(this->xray);
  ASSERT_TRUE(created.ok()) << created.error();
  const fct::ImageSimilarity& measure = created.value();
  for (const float level : {0.0f, 7.0f, 12345.678f}) {
    const auto flat = measure.evaluate(fct::FloatImage::filled(this->xray.cols, this->xray.rows, level));
    ASSERT_TRUE(flat.ok()) << flat.error();
    EXPECT_EQ(flat.value(), 0.0) << "constant DRR " << level;
  }
}

TYPED_TEST(ImageSimilarityContract, ConstantXrayIsAcceptedWithAWarningAndScoresZero) {
  const fct::FloatImage flatXray = fct::FloatImage::filled(this->xray.cols, this->xray.rows, 0.3f);
  const auto created = TestFixture::Traits::create(flatXray);
  ASSERT_TRUE(created.ok()) << created.error();
  EXPECT_FALSE(created.warnings().empty());
  const fct::ImageSimilarity& measure = created.value();
  for (const fct::FloatImage& drr : {this->xray, flatXray}) {
    const auto value = measure.evaluate(drr);
    ASSERT_TRUE(value.ok()) << value.error();
    EXPECT_EQ(value.value(), 0.0);
  }
}

TYPED_TEST(ImageSimilarityContract, NonFiniteComparedPixelFailsAndOneOutsideIsIgnored) {
  const auto created = TestFixture::Traits::create(this->xray);
  ASSERT_TRUE(created.ok()) << created.error();
  const fct::ImageSimilarity& measure = created.value();
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    fct::FloatImage inside = this->xray;
    inside.at(40, 50) = bad;
    const auto failed = measure.evaluate(inside);
    ASSERT_FALSE(failed.ok()) << "value " << bad;
    EXPECT_TRUE(contains(failed.error(), "NaN or infinite")) << failed.error();
    EXPECT_TRUE(contains(failed.error(), measure.name())) << failed.error();

    fct::FloatImage outside = this->xray;
    outside.at(0, 0) = bad;
    outside.at(this->xray.cols - 1, this->xray.rows - 1) = bad;
    const auto ignored = measure.evaluate(outside);
    ASSERT_TRUE(ignored.ok()) << ignored.error();
    EXPECT_NEAR(ignored.value(), 1.0, 1e-6);
  }
}

TYPED_TEST(ImageSimilarityContract, SizeMismatchFailsNamingBothSizes) {
  const auto created = TestFixture::Traits::create(this->xray);
  ASSERT_TRUE(created.ok()) << created.error();
  const fct::ImageSimilarity& measure = created.value();
  const auto narrow = measure.evaluate(fct::test::phantomImage(127, 112));
  ASSERT_FALSE(narrow.ok());
  EXPECT_TRUE(contains(narrow.error(), "127x112")) << narrow.error();
  EXPECT_TRUE(contains(narrow.error(), "128x112")) << narrow.error();
  const auto transposed = measure.evaluate(fct::test::phantomImage(112, 128));
  EXPECT_FALSE(transposed.ok());
  EXPECT_FALSE(measure.evaluate(fct::FloatImage{}).ok());
  fct::FloatImage truncated = this->xray;
  truncated.pixels.resize(truncated.pixels.size() / 2);
  const auto half = measure.evaluate(truncated);
  ASSERT_FALSE(half.ok());
  EXPECT_TRUE(contains(half.error(), "values")) << half.error();
}
