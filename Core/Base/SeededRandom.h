#pragma once
// SeededRandom: reproducible random numbers for the searches. std::mt19937's output sequence is fixed by the
// standard, but std::uniform_real_distribution / normal_distribution are not, so the conversions are our own:
// the same seed gives the same numbers with every compiler and standard library.

#include <cstdint>
#include <random>

namespace fct {

/// A seeded generator of uniform and Gaussian numbers.
class SeededRandom {
 public:
  /// A generator started from `seed`.
  explicit SeededRandom(std::uint32_t seed) : m_engine(seed) {}

  /// The seed of stream `stream` (e.g. an image row) of `seed`: an integer hash, so neighbouring streams get
  /// unrelated generators and per-row parallel work is reproducible for any thread count.
  static std::uint32_t streamSeed(std::uint32_t seed, std::uint32_t stream);

  /// Uniform in the open interval (0, 1).
  double uniform01();
  /// Uniform in [low, high).
  double uniform(double low, double high) { return low + (high - low) * uniform01(); }
  /// Uniform integer in [0, count); count must be > 0.
  int index(int count);
  /// Standard normal (Box–Muller).
  double normal();
  /// Poisson-distributed count with the given mean (>= 0): multiplication method below a mean of 10, Hörmann's
  /// transformed rejection (PTRS) above; exact in distribution. A mean <= 0 or NaN gives 0.
  std::int64_t poisson(double mean);

 private:
  std::mt19937 m_engine;
  bool m_hasSpare = false;
  double m_spare = 0.0;
};

}  // namespace fct
