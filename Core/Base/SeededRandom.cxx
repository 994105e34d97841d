#include "Base/SeededRandom.h"

#include <algorithm>
#include <cmath>

namespace fct {

std::uint32_t SeededRandom::streamSeed(std::uint32_t seed, std::uint32_t stream) {
  std::uint32_t h = seed * 0x9E3779B9u ^ (stream + 0x7F4A7C15u) * 0x85EBCA6Bu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return h;
}

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

std::int64_t SeededRandom::poisson(double mean) {
  if (!(mean > 0.0)) return 0;
  if (mean < 10.0) {
    const double limit = std::exp(-mean);
    std::int64_t count = 0;
    for (double product = uniform01(); product > limit; product *= uniform01()) ++count;
    return count;
  }
  // W. Hörmann, "The transformed rejection method for generating Poisson random variables", 1993 (PTRS).
  const double sqrtMean = std::sqrt(mean), logMean = std::log(mean);
  const double b = 0.931 + 2.53 * sqrtMean;
  const double a = -0.059 + 0.02483 * b;
  const double invAlpha = 1.1239 + 1.1328 / (b - 3.4);
  const double vr = 0.9277 - 3.6224 / (b - 2.0);
  for (;;) {
    const double u = uniform01() - 0.5;
    const double v = uniform01();
    const double us = 0.5 - std::abs(u);
    const double k = std::floor((2.0 * a / us + b) * u + mean + 0.43);
    if (us >= 0.07 && v <= vr) return static_cast<std::int64_t>(k);
    if (k < 0.0 || (us < 0.013 && v > us)) continue;
    if (std::log(v) + std::log(invAlpha) - std::log(a / (us * us) + b) <= -mean + k * logMean - std::lgamma(k + 1.0)) {
      return static_cast<std::int64_t>(k);
    }
  }
}

}  // namespace fct
