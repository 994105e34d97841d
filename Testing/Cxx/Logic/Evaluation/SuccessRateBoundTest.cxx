#include <gtest/gtest.h>

#include <cmath>

#include "Evaluation/SuccessRateBound.h"

using fct::SuccessRateBound;

TEST(SuccessRateBound, AllSuccessesGiveTheClosedForm) {
  EXPECT_NEAR(SuccessRateBound::lower(4, 4), std::pow(0.05, 0.25), 1e-12);  // 47.3 %
  EXPECT_NEAR(SuccessRateBound::lower(20, 20), 0.8609, 1e-4);
  EXPECT_NEAR(SuccessRateBound::lower(1, 1, 0.9), 0.1, 1e-12);
}

TEST(SuccessRateBound, MatchesIndependentlyComputedValues) {
  // One-sided 95 % lower bounds, computed apart with Python's exact integer binomial coefficients (math.comb) and
  // 100 bisection steps.
  EXPECT_NEAR(SuccessRateBound::lower(10, 20), 0.3020, 1e-4);
  EXPECT_NEAR(SuccessRateBound::lower(19, 20), 0.7839, 1e-4);
  EXPECT_NEAR(SuccessRateBound::lower(1, 10), 0.0051, 1e-4);
  // Independent check of the definition: at the bound, P(X >= k) is 5 %.
  const double p = SuccessRateBound::lower(7, 12);
  double tail = 0.0;
  for (int i = 7; i <= 12; ++i) tail += std::tgamma(13.0) / (std::tgamma(i + 1.0) * std::tgamma(13.0 - i)) *
                                        std::pow(p, i) * std::pow(1 - p, 12 - i);
  EXPECT_NEAR(tail, 0.05, 1e-9);
}

TEST(SuccessRateBound, GrowsWithTrialsAtTheSameRate) {
  EXPECT_LT(SuccessRateBound::lower(9, 10), SuccessRateBound::lower(90, 100));
  EXPECT_LT(SuccessRateBound::lower(90, 100), 0.9);
  EXPECT_EQ(SuccessRateBound::lower(0, 10), 0.0);
}

TEST(SuccessRateBound, BadCountsGiveNaN) {
  EXPECT_TRUE(std::isnan(SuccessRateBound::lower(1, 0)));
  EXPECT_TRUE(std::isnan(SuccessRateBound::lower(-1, 5)));
  EXPECT_TRUE(std::isnan(SuccessRateBound::lower(6, 5)));
  EXPECT_TRUE(std::isnan(SuccessRateBound::lower(3, 5, 1.0)));
  EXPECT_TRUE(std::isnan(SuccessRateBound::lower(3, 5, std::nan(""))));
}
