#pragma once
// NccAccumulator: the inner loop shared by the NCC-based similarity metrics. The fixed side (the X-ray) is centred
// once (mean removed, norm stored); per evaluation only sums of the moving side (the DRR) are accumulated:
//     NCC = sum(xc_i * d_i) / (|xc| * sqrt(sum(d_i^2) - (sum d_i)^2 / n)),
// which equals the textbook NCC because sum(xc_i) = 0. The moving values are shifted by their first value before
// squaring, which removes the cancellation of large offsets and makes a constant moving side give exactly 0.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace fct {

/// Running sums of one NCC between a centred fixed series and a moving series. Header-only; no allocation.
class NccAccumulator {
 public:
  /// Starts a sum whose moving values are measured from `shift` (pass the first moving value).
  explicit NccAccumulator(double shift) : m_shift(shift) {}

  /// Adds one pair: the fixed value already centred, and the raw moving value.
  void add(float fixedCentred, float moving) {
    const double d = static_cast<double>(moving) - m_shift;
    m_sum += d;
    m_sumSquares += d * d;
    m_sumProducts += static_cast<double>(fixedCentred) * d;
  }

  /// The NCC in [-1, 1] over `count` pairs given the fixed series' norm; 0 if either side is constant; NaN if a
  /// moving value was not finite.
  double correlation(double fixedNorm, std::size_t count) const {
    if (!std::isfinite(m_sumSquares) || !std::isfinite(m_sumProducts)) return std::numeric_limits<double>::quiet_NaN();
    const double movingSquares = m_sumSquares - m_sum * m_sum / static_cast<double>(count);
    if (!(fixedNorm > 0.0) || !(movingSquares > 1e-12 * m_sumSquares)) return 0.0;
    return std::clamp(m_sumProducts / (fixedNorm * std::sqrt(movingSquares)), -1.0, 1.0);
  }

  /// Removes the mean of `values` in place and returns the norm sqrt(sum of squares) of the result (two-pass).
  static double centreInPlace(float* values, std::size_t count) {
    if (count == 0) return 0.0;
    double sum = 0.0;
    for (std::size_t i = 0; i < count; ++i) sum += values[i];
    const double mean = sum / static_cast<double>(count);
    double squares = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      values[i] = static_cast<float>(values[i] - mean);
      squares += static_cast<double>(values[i]) * values[i];
    }
    // A series constant up to float rounding of its mean counts as constant.
    const double scale = std::abs(mean) * 1e-6;
    return squares > scale * scale * static_cast<double>(count) ? std::sqrt(squares) : 0.0;
  }

 private:
  double m_shift;
  double m_sum = 0.0;
  double m_sumSquares = 0.0;
  double m_sumProducts = 0.0;
};

}  // namespace fct
