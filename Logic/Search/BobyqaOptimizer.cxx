#include "Search/BobyqaOptimizer.h"

#include <nlopt.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace fct {

namespace {

constexpr int kN = 6;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// What the NLopt callback needs: the shared evaluator, this search's budget, stall test and best point.
struct BobyqaRun {
  ObjectiveEvaluator& evaluator;
  int firstEvaluation = 0;
  int maxEvaluations = 0;
  StallDetector stall;
  nlopt_opt opt = nullptr;
  PoseVector best = PoseVector::Zero();
  double bestValue = kInf;
  double worstFinite = -kInf;

  bool outOfBudget() const {
    return evaluator.stopped() || evaluator.evaluations() - firstEvaluation >= maxEvaluations || stall.stalled();
  }
};

double objectiveCallback(unsigned n, const double* x, double* /*gradient: derivative-free*/, void* data) {
  auto& run = *static_cast<BobyqaRun*>(data);
  PoseVector y_scaled;
  for (unsigned i = 0; i < n; ++i) y_scaled[i] = x[i];
  const double value = run.evaluator.atScaled(y_scaled);
  run.stall.add(value);
  if (value < run.bestValue) {
    run.bestValue = value;
    run.best = y_scaled;
  }
  if (std::isfinite(value)) run.worstFinite = std::max(run.worstFinite, value);
  if (run.outOfBudget()) nlopt_force_stop(run.opt);
  if (std::isfinite(value)) return value;
  return std::isfinite(run.worstFinite) ? run.worstFinite + std::max(1.0, std::abs(run.worstFinite)) : 1.0;
}

/// One BOBYQA run from `start_scaled`; returns true when it ended on the tolerance.
bool runOnce(BobyqaRun& run, const PoseVector& start_scaled, const LocalSearchOptions& options) {
  nlopt_opt opt = nlopt_create(NLOPT_LN_BOBYQA, kN);
  if (!opt) return false;  // out of memory: nothing evaluated, the caller keeps its best
  run.opt = opt;
  std::array<double, kN> x{};
  std::array<double, kN> step{};
  for (int i = 0; i < kN; ++i) {
    x[i] = start_scaled[i];
    step[i] = options.initialStep;
  }
  nlopt_set_min_objective(opt, objectiveCallback, &run);
  nlopt_set_initial_step(opt, step.data());
  nlopt_set_xtol_abs1(opt, options.tolerance);
  nlopt_set_maxeval(opt, std::max(1, options.maxEvaluations - (run.evaluator.evaluations() - run.firstEvaluation)));
  double value = 0.0;
  const nlopt_result outcome = nlopt_optimize(opt, x.data(), &value);
  nlopt_destroy(opt);
  run.opt = nullptr;
  return outcome == NLOPT_XTOL_REACHED || outcome == NLOPT_FTOL_REACHED;
}

}  // namespace

std::pair<PoseVector, double> BobyqaOptimizer::searchScaled(ObjectiveEvaluator& evaluator,
                                                            const PoseVector& start_scaled, bool* converged) const {
  BobyqaRun run{evaluator, evaluator.evaluations(), m_options.maxEvaluations, StallDetector(m_options.stall)};
  run.best = start_scaled;
  bool reachedTolerance = false;
  for (int attempt = 0; attempt <= m_options.restarts && !run.outOfBudget(); ++attempt) {
    const double before = run.bestValue;
    reachedTolerance = runOnce(run, run.best, m_options);
    // A restart that finds nothing better confirms the minimum; stop early.
    if (attempt > 0 && !(run.bestValue < before)) break;
  }
  if (converged) *converged = reachedTolerance;
  return {run.best, run.bestValue};
}

}  // namespace fct
