#pragma once
// GeneticSearchOptimizer: the paper's global search (Knaan & Joskowicz 2003). From the start pose plus n random
// poses, each guess is refined by the local search; guesses whose value is more than `dropThreshold` above the
// best are dropped; n/2 new guesses are made as random pairwise combinations of the survivors on the pose manifold
// and refined; the survivors and the new guesses form the next generation. The number of new guesses halves each
// generation (n/2, n/4, ..., 1), and the search ends when one guess survives, no new guess is due, or a limit is hit.
// With n = 4 that is 5 + 2 + 1 = 8 local searches (one more per extra seed). The same seed gives the same result.

#include <cstdint>
#include <vector>

#include "Search/LocalPoseOptimizer.h"
#include "Search/PoseOptimizer.h"

namespace fct {

/// Settings of the genetic search.
struct GeneticSearchOptions {
  int randomGuesses = 4;              ///< n: random poses besides the start (>= 1)
  double spreadRotation_deg = 5.0;    ///< random poses: start + uniform in +-spread per rotation parameter
  double spreadTranslation_mm = 5.0;  ///< random poses: start + uniform in +-spread per translation parameter
  double dropThreshold = 0.1;         ///< drop guesses whose value exceeds the best by more (objective units, >= 0)
  double extrapolation = 0.25;        ///< combination weight lambda is uniform in [-e, 1 + e] (>= 0)
  int maxGenerations = 10;            ///< generations after the initial one (>= 0)
  int maxEvaluations = 20000;         ///< cap on objective evaluations of the whole search (> 0)
  std::uint32_t seed = 1;             ///< random seed; the same seed gives the same result
  LocalSearchOptions local;           ///< the local search run on every guess (simplex or BOBYQA)
  /// Guesses besides the start and the random ones (deg, mm), refined with them in the initial population: poses a
  /// coarse look elsewhere found promising (e.g. a rotation sweep's best). Empty by default.
  std::vector<PoseVector> extraSeeds;
};

/// Genetic search with a local search (downhill simplex or BOBYQA) on every guess.
class GeneticSearchOptimizer : public PoseOptimizer {
 public:
  /// A search with the given options (checked when minimize() is called).
  explicit GeneticSearchOptimizer(GeneticSearchOptions options = {}) : m_options(options) {}

  std::string name() const override { return "genetic"; }

  /// The pose "a + lambda (b - a)" on the pose manifold: rotation R_a exp(lambda log(R_a^T R_b)) (geodesic, about the
  /// rotation centre), translation t_a + lambda (t_b - t_a). lambda = 0 gives a, 1 gives b; outside [0, 1] it
  /// extrapolates. Parameters as in PoseVector (deg, mm).
  static PoseVector combine(const PoseVector& a, const PoseVector& b, double lambda);

  /// Checks the options (the local search's too); the error names the bad option and its value.
  Status validateOptions() const override;

  const GeneticSearchOptions& options() const { return m_options; }

 protected:
  /// The genetic search from `start`. Reports progress per local search with the generation, evaluation count and
  /// best value; fills OptimizationResult::generations.
  OptimizationResult search(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales,
                            const ProgressMonitor& monitor) const override;

 private:
  GeneticSearchOptions m_options;
};

}  // namespace fct
