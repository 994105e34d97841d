#include "Search/StallDetector.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fct {

Status StallDetector::validate() const {
  if (m_options.window < 0) {
    return fail(fmt::format("stall window must be 0 (off) or a positive number of evaluations, got {}",
                            m_options.window));
  }
  if (!std::isfinite(m_options.relativeImprovement) || m_options.relativeImprovement < 0.0) {
    return fail(fmt::format("stall relative improvement must be finite and 0 or more, got {}",
                            m_options.relativeImprovement));
  }
  return Ok{};
}

bool StallDetector::add(double value) {
  if (m_options.window <= 0) return false;
  const double previous = m_bestSoFar.empty() ? std::numeric_limits<double>::infinity() : m_bestSoFar.back();
  m_bestSoFar.push_back(std::isnan(value) ? previous : std::min(previous, value));
  const auto window = static_cast<std::size_t>(m_options.window);
  if (m_bestSoFar.size() <= window) return m_stalled;
  const double then = m_bestSoFar[m_bestSoFar.size() - 1 - window];
  const double now = m_bestSoFar.back();
  if (std::isfinite(then)) m_stalled = m_stalled || then - now <= m_options.relativeImprovement * std::abs(then);
  return m_stalled;
}

}  // namespace fct
