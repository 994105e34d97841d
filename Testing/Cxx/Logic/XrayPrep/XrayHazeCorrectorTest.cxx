#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <vector>

#include "SyntheticImages.h"
#include "XrayPrep/XrayHazeCorrector.h"
#include "XrayPrep/XrayIntensityModel.h"

namespace {

/// A smooth haze over the detector: 0.02 at the left edge rising to 0.04 at the right, times 1 + 0.2 sin(row).
float hazeAt(int col, int row, int cols) {
  return (0.02f + 0.02f * static_cast<float>(col) / static_cast<float>(cols)) * (1.0f + 0.2f * std::sin(0.02f * row));
}

/// The X-ray's line integrals (XrayIntensityModel) of intensities gain * exp(-factor * d / (1 + hardening * d)) (+ the
/// haze when `hazy`): a beam whose effective attenuation falls along thick rays when hardening > 0.
fct::FloatImage xrayOf(const fct::FloatImage& drr, double factor, double gain, bool hazy, double hardening = 0.0) {
  fct::FloatImage intensities = drr;
  for (int r = 0; r < drr.rows; ++r) {
    for (int c = 0; c < drr.cols; ++c) {
      const double d = drr.at(c, r);
      intensities.at(c, r) = static_cast<float>(gain * std::exp(-factor * d / (1.0 + hardening * d))) +
                             (hazy ? hazeAt(c, r, drr.cols) : 0.0f);
    }
  }
  auto lineIntegrals = fct::XrayIntensityModel().toLineIntegrals(
      intensities, fct::ValidMask::allValid(intensities.cols, intensities.rows));
  EXPECT_TRUE(lineIntegrals.ok()) << lineIntegrals.error();
  return lineIntegrals.value().lineIntegrals;
}

/// The deviations of `xray` from factor * drr + offset over the pixels, the offset being the median difference (line
/// integrals are known up to an offset: the X-ray's reference level).
std::vector<double> deviations(const fct::FloatImage& xray, const fct::FloatImage& drr, double factor) {
  std::vector<double> differences;
  for (std::size_t i = 0; i < drr.pixels.size(); ++i) differences.push_back(xray.pixels[i] - factor * drr.pixels[i]);
  std::vector<double> sorted = differences;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double offset = sorted[sorted.size() / 2];
  for (double& d : differences) d = std::abs(d - offset);
  return differences;
}

/// The largest of deviations().
double largestDeviation(const fct::FloatImage& xray, const fct::FloatImage& drr, double factor) {
  const std::vector<double> d = deviations(xray, drr, factor);
  return *std::max_element(d.begin(), d.end());
}

/// The mean of deviations().
double meanDeviation(const fct::FloatImage& xray, const fct::FloatImage& drr, double factor) {
  const std::vector<double> d = deviations(xray, drr, factor);
  return std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
}

}  // namespace

TEST(XrayHazeCorrector, RemovesASmoothHazeThatCompressesTheDarkPixels) {
  const fct::FloatImage drr = fct::test::phantomImage();
  const fct::FloatImage hazy = xrayOf(drr, 1.0, 0.8, true);
  ASSERT_GT(largestDeviation(hazy, drr, 1.0), 0.4);  // the haze bends the dark pixels' line integrals by that much
  const auto corrected = fct::XrayHazeCorrector::correct(hazy, drr, fct::ValidMask::allValid(drr.cols, drr.rows), 10.0);
  ASSERT_TRUE(corrected.ok()) << corrected.error();
  std::printf("deviation from the DRR, max / mean: hazy %.3f / %.4f, corrected %.3f / %.4f\n",
              largestDeviation(hazy, drr, 1.0), meanDeviation(hazy, drr, 1.0),
              largestDeviation(corrected.value().lineIntegrals, drr, 1.0),
              meanDeviation(corrected.value().lineIntegrals, drr, 1.0));
  EXPECT_LT(largestDeviation(corrected.value().lineIntegrals, drr, 1.0), 0.4 * largestDeviation(hazy, drr, 1.0));
  EXPECT_LT(meanDeviation(corrected.value().lineIntegrals, drr, 1.0), 0.4 * meanDeviation(hazy, drr, 1.0));
  EXPECT_NEAR(corrected.value().attenuationFactor, 1.0, 0.051);
  EXPECT_GT(corrected.value().meanHazeFraction, 0.02);
}

TEST(XrayHazeCorrector, LeavesAHazeFreeXrayAsItWasAndFindsItsAttenuationFactor) {
  const fct::FloatImage drr = fct::test::phantomImage();
  const fct::FloatImage clean = xrayOf(drr, 0.7, 1.0, false);
  const auto corrected = fct::XrayHazeCorrector::correct(clean, drr, fct::ValidMask::allValid(drr.cols, drr.rows), 10.0);
  ASSERT_TRUE(corrected.ok()) << corrected.error();
  std::printf("found c %.3f (0.7), hardening %.3f (0), haze fraction %.4f\n", corrected.value().attenuationFactor,
              corrected.value().hardening, corrected.value().meanHazeFraction);
  EXPECT_NEAR(corrected.value().attenuationFactor, 0.7, 0.02);
  EXPECT_LT(corrected.value().hardening, 0.05);
  // 0.03 on the X-ray's scale, which is 0.7 times the DRR's.
  EXPECT_LT(largestDeviation(corrected.value().lineIntegrals, drr, 1.0), 0.03 / 0.7) << "on the DRR's scale";
  EXPECT_LT(corrected.value().meanHazeFraction, 0.01);
}

TEST(XrayHazeCorrector, FindsTheBeamHardeningAndReturnsTheXrayOnTheDrrsScale) {
  fct::FloatImage drr = fct::test::phantomImage();  // shifted to start at 0: h's argument is then the DRR itself
  const float dMin = *std::min_element(drr.pixels.begin(), drr.pixels.end());
  for (float& d : drr.pixels) d -= dMin;
  // The attenuation falls to 1 / 1.6 of its thin-ray value at the DRR's largest value.
  const double hardening = 0.6 / *std::max_element(drr.pixels.begin(), drr.pixels.end());
  const fct::FloatImage hazy = xrayOf(drr, 1.3, 0.8, true, hardening);
  ASSERT_GT(largestDeviation(hazy, drr, 1.3), 0.5);  // the hardening and the haze bend the thick rays by that much
  const auto corrected = fct::XrayHazeCorrector::correct(hazy, drr, fct::ValidMask::allValid(drr.cols, drr.rows), 10.0);
  ASSERT_TRUE(corrected.ok()) << corrected.error();
  std::printf("found c %.3f (1.3), hardening %.3f (0.6); deviation from the DRR, max / mean: %.3f / %.4f\n",
              corrected.value().attenuationFactor, corrected.value().hardening,
              largestDeviation(corrected.value().lineIntegrals, drr, 1.0),
              meanDeviation(corrected.value().lineIntegrals, drr, 1.0));
  EXPECT_NEAR(corrected.value().attenuationFactor, 1.3, 0.1);
  // The quadratic haze surface takes up part of the bending of the thick rays, so the hardening is found low.
  EXPECT_GT(corrected.value().hardening, 0.3);
  EXPECT_LT(corrected.value().hardening, 0.8);
  EXPECT_LT(meanDeviation(corrected.value().lineIntegrals, drr, 1.0), 0.02) << "the X-ray is linear in the DRR again";
}

TEST(XrayHazeCorrector, FitsOnlyTheValidPixels) {
  const fct::FloatImage drr = fct::test::phantomImage();
  const fct::FloatImage hazy = xrayOf(drr, 1.0, 0.8, true);
  fct::FloatImage withMetal = hazy;
  fct::ValidMask mask = fct::ValidMask::allValid(drr.cols, drr.rows);
  for (int r = 40; r < 60; ++r) {  // a metal shadow the DRR lacks, masked out
    for (int c = 90; c < 100; ++c) {
      withMetal.at(c, r) += 3.0f;
      mask.valid[static_cast<std::size_t>(r) * drr.cols + c] = 0;
    }
  }
  const auto a = fct::XrayHazeCorrector::correct(hazy, drr, mask, 10.0);
  const auto b = fct::XrayHazeCorrector::correct(withMetal, drr, mask, 10.0);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.value().attenuationFactor, b.value().attenuationFactor);
  EXPECT_EQ(a.value().globalGain, b.value().globalGain);
  for (const std::int32_t i : mask.pixelList()) {
    ASSERT_NEAR(a.value().lineIntegrals.pixels[static_cast<std::size_t>(i)],
                b.value().lineIntegrals.pixels[static_cast<std::size_t>(i)], 1e-5)
        << "the masked metal changed pixel " << i;
  }
  EXPECT_LT(largestDeviation(a.value().lineIntegrals, drr, 1.0), 0.2) << "the hole's pixels are filled from around it";
}

TEST(XrayHazeCorrector, RejectsBadInputWithAReason) {
  const fct::FloatImage drr = fct::test::phantomImage();
  const fct::FloatImage xray = xrayOf(drr, 1.0, 0.8, true);
  const fct::ValidMask all = fct::ValidMask::allValid(drr.cols, drr.rows);
  auto error = [](const fct::Result<fct::HazeCorrection>& r) { return r.ok() ? std::string("(none)") : r.error(); };

  const auto mismatch = fct::XrayHazeCorrector::correct(xray, fct::test::phantomImage(64, 64), all, 10.0);
  EXPECT_NE(error(mismatch).find("differ in size"), std::string::npos) << error(mismatch);
  for (const double sigma : {0.0, -3.0, std::numeric_limits<double>::quiet_NaN()}) {
    const auto bad = fct::XrayHazeCorrector::correct(xray, drr, all, sigma);
    EXPECT_NE(error(bad).find("positive number of pixels"), std::string::npos) << error(bad);
  }
  fct::ValidMask few = fct::ValidMask::allValid(drr.cols, drr.rows);
  std::fill(few.valid.begin() + 50, few.valid.end(), 0);
  const auto tooFew = fct::XrayHazeCorrector::correct(xray, drr, few, 10.0);
  EXPECT_NE(error(tooFew).find("at least 100"), std::string::npos) << error(tooFew);
  const auto flat = fct::XrayHazeCorrector::correct(xray, fct::FloatImage::filled(drr.cols, drr.rows, 2.0f), all, 10.0);
  EXPECT_NE(error(flat).find("constant"), std::string::npos) << error(flat);
  fct::FloatImage inverted = drr;  // a DRR dark where the X-ray is: nothing like the X-ray
  for (float& v : inverted.pixels) v = 4.0f - v;
  const auto unexplained = fct::XrayHazeCorrector::correct(xray, inverted, all, 10.0);
  EXPECT_NE(error(unexplained).find("does not explain"), std::string::npos) << error(unexplained);
  const auto offScale = fct::XrayHazeCorrector::correct(xrayOf(drr, 12.0, 0.8, false), drr, all, 10.0);
  EXPECT_NE(error(offScale).find("edge of the range"), std::string::npos) << error(offScale);
  fct::FloatImage notFinite = drr;
  notFinite.pixels[7] = std::numeric_limits<float>::quiet_NaN();
  const auto nan = fct::XrayHazeCorrector::correct(xray, notFinite, all, 10.0);
  EXPECT_NE(error(nan).find("non-finite"), std::string::npos) << error(nan);
}
