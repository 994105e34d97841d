#pragma once
// StallDetector: tells a local search that it has stopped improving. It follows the best objective value of the
// evaluations it is given and reports a stall once the best improved, over the last `window` evaluations, by no more
// than `relativeImprovement` times its magnitude (the best `window` evaluations ago). Off when window is 0.

#include <cstddef>
#include <vector>

#include "Base/Result.h"

namespace fct {

/// When a search counts as stalled; window 0 switches the test off.
struct StallOptions {
  int window = 0;                    ///< evaluations looked back over (0: never stalls; else >= 1)
  double relativeImprovement = 0.0;  ///< stalled when (best then - best now) <= this * |best then| (>= 0)
};

/// Follows one search's evaluations and says when they stopped improving.
class StallDetector {
 public:
  /// A detector with the given options (checked by validate()).
  explicit StallDetector(StallOptions options = {}) : m_options(options) {}

  /// Checks the options; the error names the bad option and its value.
  Status validate() const;
  /// Takes the next evaluation's value (NaN and +infinity count as no improvement); returns stalled().
  bool add(double value);
  /// True once the best improved by no more than the threshold over the last `window` evaluations.
  bool stalled() const { return m_stalled; }

 private:
  StallOptions m_options;
  std::vector<double> m_bestSoFar;  ///< best value after each evaluation
  bool m_stalled = false;
};

}  // namespace fct
