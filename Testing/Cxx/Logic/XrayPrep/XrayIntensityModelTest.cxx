#include <gtest/gtest.h>

#include <cmath>

#include "SyntheticImages.h"
#include "XrayPrep/XrayIntensityModel.h"

namespace {

/// Intensities I = I0 exp(-p) of the line integrals p (p >= 0, with some pixels at p = 0).
fct::FloatImage beerLambert(const fct::FloatImage& lineIntegrals, float i0) {
  fct::FloatImage out = lineIntegrals;
  for (float& v : out.pixels) v = i0 * std::exp(-v);
  return out;
}

fct::FloatImage nonNegativePhantom() {
  fct::FloatImage p = fct::test::phantomImage();
  for (float& v : p.pixels) v = std::max(0.0f, v);
  return p;
}

}  // namespace

TEST(XrayIntensityModel, RecoversLineIntegralsOfBeerLambertImage) {
  const fct::FloatImage p = nonNegativePhantom();
  const fct::FloatImage intensities = beerLambert(p, 3000.0f);
  const fct::ValidMask all = fct::ValidMask::allValid(p.cols, p.rows);
  const auto result = fct::XrayIntensityModel({100.0, 1e-3}).toLineIntegrals(intensities, all);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_NEAR(result.value().referenceIntensity, 3000.0, 1e-2);
  for (std::size_t i = 0; i < p.pixels.size(); ++i) ASSERT_NEAR(result.value().lineIntegrals.pixels[i], p.pixels[i], 1e-4);
}

TEST(XrayIntensityModel, UnknownGainDoesNotChangeTheResult) {
  const fct::FloatImage intensities = beerLambert(nonNegativePhantom(), 200.0f);
  const fct::ValidMask all = fct::ValidMask::allValid(intensities.cols, intensities.rows);
  const fct::XrayIntensityModel model;  // default: 99.5th percentile
  const auto a = model.toLineIntegrals(intensities, all);
  const auto b = model.toLineIntegrals(fct::test::affine(intensities, 7.5f, 0.0f), all);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NEAR(b.value().referenceIntensity / a.value().referenceIntensity, 7.5, 1e-4);
  for (std::size_t i = 0; i < intensities.pixels.size(); ++i) {
    ASSERT_NEAR(a.value().lineIntegrals.pixels[i], b.value().lineIntegrals.pixels[i], 1e-5);
    ASSERT_GE(a.value().lineIntegrals.pixels[i], 0.0f);
  }
}

TEST(XrayIntensityModel, ClampsDarkPixelsToTheFloor) {
  fct::FloatImage intensities = fct::FloatImage::filled(4, 4, 100.0f);
  intensities.at(1, 1) = 0.0f;
  intensities.at(2, 1) = -5.0f;
  const auto result =
      fct::XrayIntensityModel({99.5, 1e-2}).toLineIntegrals(intensities, fct::ValidMask::allValid(4, 4));
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_NEAR(result.value().lineIntegrals.at(1, 1), -std::log(1e-2), 1e-5);
  EXPECT_NEAR(result.value().lineIntegrals.at(2, 1), -std::log(1e-2), 1e-5);
  EXPECT_NEAR(result.value().lineIntegrals.at(0, 0), 0.0, 1e-6);
}

TEST(XrayIntensityModel, RejectsBlackImageMismatchedMaskAndNaN) {
  const fct::XrayIntensityModel model;
  const fct::ValidMask mask = fct::ValidMask::allValid(4, 4);
  EXPECT_FALSE(model.toLineIntegrals(fct::FloatImage::filled(4, 4, 0.0f), mask).ok());
  EXPECT_FALSE(model.toLineIntegrals(fct::FloatImage::filled(5, 4, 1.0f), mask).ok());
  fct::FloatImage withNaN = fct::FloatImage::filled(4, 4, 1.0f);
  withNaN.at(3, 3) = std::nanf("");
  EXPECT_FALSE(model.toLineIntegrals(withNaN, mask).ok());
  fct::ValidMask none = mask;
  none.excludeMargin(2);
  EXPECT_FALSE(model.toLineIntegrals(fct::FloatImage::filled(4, 4, 1.0f), none).ok());
  EXPECT_FALSE(fct::XrayIntensityModel({0.0, 1e-3}).toLineIntegrals(fct::FloatImage::filled(4, 4, 1.0f), mask).ok());
}
