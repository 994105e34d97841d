#include "SeededRandom.h"

#include <algorithm>
#include <cmath>

namespace fct {

double SeededRandom::uniform01() {
  // 53 random bits from two 32-bit draws, shifted off zero.
  const std::uint64_t high = m_engine() >> 5;  // 27 bits
  const std::uint64_t low = m_engine() >> 6;   // 26 bits
  return (static_cast<double>((high << 26) | low) + 0.5) / 9007199254740992.0;  // 2^53
}

int SeededRandom::index(int count) {
  return std::min(count - 1, static_cast<int>(uniform01() * count));
}

double SeededRandom::normal() {
  if (m_hasSpare) {
    m_hasSpare = false;
    return m_spare;
  }
  const double radius = std::sqrt(-2.0 * std::log(uniform01()));
  const double angle = 2.0 * M_PI * uniform01();
  m_spare = radius * std::sin(angle);
  m_hasSpare = true;
  return radius * std::cos(angle);
}

}  // namespace fct
