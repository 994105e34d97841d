#pragma once
// LocalPoseOptimizer: the local pose searches (the own downhill simplex, NLopt's BOBYQA), which share their options
// and run either alone or inside another strategy's evaluator (each guess of the genetic search). create() makes the
// one the options name.

#include <memory>
#include <utility>

#include "Search/ObjectiveEvaluator.h"
#include "Search/PoseOptimizer.h"
#include "Search/StallDetector.h"

namespace fct {

/// Which local search runs.
enum class LocalSearchMethod {
  Simplex,  ///< the own downhill simplex (NelderMeadOptimizer)
  Bobyqa,   ///< NLopt's BOBYQA: a quadratic model of the objective, refitted at each evaluation (BobyqaOptimizer)
};

/// Settings of a local search, in scaled units (about 1 mm of bone-surface motion each).
struct LocalSearchOptions {
  double initialStep = 2.0;      ///< first step per axis (simplex edge, BOBYQA trust radius), scaled units (> tolerance)
  double tolerance = 0.01;       ///< stop once the search moves less than this along every axis, scaled units
  int maxEvaluations = 2000;     ///< cap on objective evaluations per call (> 0)
  int restarts = 1;              ///< fresh searches started from the converged best (>= 0)
  StallOptions stall;            ///< also stop (without restarting) once the search stops improving (off by default)
  LocalSearchMethod method = LocalSearchMethod::Simplex;  ///< which search create() makes
};

/// A local search over the 6 pose parameters.
class LocalPoseOptimizer : public PoseOptimizer {
 public:
  /// A search with the given options (checked when minimize() is called).
  explicit LocalPoseOptimizer(LocalSearchOptions options) : m_options(options) {}

  /// The search the options' method names.
  static std::unique_ptr<LocalPoseOptimizer> create(const LocalSearchOptions& options);

  /// Runs one local search from `start_scaled` inside another strategy's evaluator (which counts, caps and cancels);
  /// returns the best scaled point and its value, and sets `converged` if the tolerance was reached.
  virtual std::pair<PoseVector, double> searchScaled(ObjectiveEvaluator& evaluator, const PoseVector& start_scaled,
                                                     bool* converged) const = 0;

  /// Checks the options; the error names the search, the bad option and its value.
  Status validateOptions() const override;

  const LocalSearchOptions& options() const { return m_options; }

 protected:
  /// One local search from `start`; reports progress every 25 evaluations and once at the end.
  OptimizationResult search(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales,
                            const ProgressMonitor& monitor) const override;

  LocalSearchOptions m_options;
};

}  // namespace fct
