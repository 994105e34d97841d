#include <gtest/gtest.h>

#include <cmath>

#include "Base/SeededRandom.h"

TEST(SeededRandom, PoissonHasItsMeanAsMeanAndVariance) {
  for (const double mean : {0.7, 4.0, 9.5, 10.5, 60.0, 5000.0}) {
    SCOPED_TRACE(mean);
    fct::SeededRandom random(11);
    const int samples = 40000;
    double sum = 0.0, sumSquares = 0.0;
    for (int n = 0; n < samples; ++n) {
      const double k = static_cast<double>(random.poisson(mean));
      ASSERT_GE(k, 0.0);
      sum += k;
      sumSquares += k * k;
    }
    const double sampleMean = sum / samples;
    const double sampleVariance = sumSquares / samples - sampleMean * sampleMean;
    EXPECT_NEAR(sampleMean, mean, 5.0 * std::sqrt(mean / samples));
    EXPECT_NEAR(sampleVariance / mean, 1.0, 0.05);
  }
}

TEST(SeededRandom, PoissonIsReproducibleAndZeroForNonPositiveMeans) {
  fct::SeededRandom a(5), b(5);
  for (int n = 0; n < 100; ++n) ASSERT_EQ(a.poisson(37.0), b.poisson(37.0));
  EXPECT_EQ(a.poisson(0.0), 0);
  EXPECT_EQ(a.poisson(-3.0), 0);
  EXPECT_EQ(a.poisson(std::nan("")), 0);
}
