#include "Evaluation/SuccessRateBound.h"

#include <cmath>
#include <limits>

namespace fct {

namespace {

/// P(X >= k) for X ~ Binomial(n, p), 0 < p < 1, summed in the log domain.
double upperTail(int k, int n, double p) {
  double sum = 0.0;
  const double logP = std::log(p), logQ = std::log1p(-p);
  for (int i = k; i <= n; ++i) {
    const double logChoose = std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0);
    sum += std::exp(logChoose + i * logP + (n - i) * logQ);
  }
  return sum;
}

}  // namespace

double SuccessRateBound::lower(int successes, int trials, double confidence) {
  if (trials <= 0 || successes < 0 || successes > trials || !(confidence > 0.0 && confidence < 1.0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (successes == 0) return 0.0;
  const double alpha = 1.0 - confidence;
  if (successes == trials) return std::pow(alpha, 1.0 / trials);  // the closed form of the general case
  // P(X >= successes) grows with p: bisect for the p where it equals alpha.
  double low = 0.0, high = 1.0;
  for (int iteration = 0; iteration < 60; ++iteration) {
    const double mid = 0.5 * (low + high);
    (upperTail(successes, trials, mid) < alpha ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

}  // namespace fct
