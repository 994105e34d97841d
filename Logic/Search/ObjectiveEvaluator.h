#pragma once
// ObjectiveEvaluator: the bookkeeping shared by the pose search strategies. It evaluates the objective in scaled
// coordinates (y = p / scales), counts evaluations, keeps the best pose, turns NaN into +infinity (the worst), and
// stops evaluating (returning +infinity) once the caller cancels or the evaluation budget is spent.

#include "Search/PoseOptimizer.h"

namespace fct {

/// Counts, guards and remembers the evaluations of one optimization run.
class ObjectiveEvaluator {
 public:
  /// Wraps `objective` (kept by reference: it must outlive the evaluator); `maxEvaluations` > 0 caps the total;
  /// `start` (deg, mm) is reported as the best pose until something has been evaluated.
  ObjectiveEvaluator(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales,
                     int maxEvaluations, const ProgressMonitor& monitor);

  /// Objective at scaled coordinates y; +infinity for NaN, and +infinity without evaluating once stopped().
  double atScaled(const PoseVector& y_scaled);
  /// Also sends a progress report under `stage` every `interval` evaluations (fraction = evaluations / maximum).
  void reportEvery(int interval, std::string stage) {
    m_reportInterval = interval;
    m_reportStage = std::move(stage);
  }
  /// Parameters (deg, mm) of scaled coordinates.
  PoseVector toParams(const PoseVector& y_scaled) const { return y_scaled.cwiseProduct(m_scales); }
  /// Scaled coordinates of parameters (deg, mm).
  PoseVector toScaled(const PoseVector& params) const { return params.cwiseQuotient(m_scales); }

  /// True once cancelled or out of evaluations: further atScaled() calls return +infinity without evaluating.
  bool stopped() const { return m_cancelled || m_evaluations >= m_maxEvaluations; }
  /// True if the cancel flag was seen.
  bool cancelled() const { return m_cancelled; }
  /// Evaluations made so far.
  int evaluations() const { return m_evaluations; }
  /// Lowest value seen so far (+infinity before any finite value).
  double bestValue() const { return m_bestValue; }

  /// The run's result so far: best pose and value, evaluation count, cancelled flag, and `converged`.
  OptimizationResult result(bool converged) const;

 private:
  const PoseObjective& m_objective;
  PoseVector m_scales;
  int m_maxEvaluations;
  const ProgressMonitor& m_monitor;
  int m_reportInterval = 0;
  std::string m_reportStage;
  int m_evaluations = 0;
  bool m_cancelled = false;
  double m_bestValue;
  PoseVector m_bestParams;
};

}  // namespace fct
