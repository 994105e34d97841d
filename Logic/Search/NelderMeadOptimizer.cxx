#include "Search/NelderMeadOptimizer.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace fct {

namespace {

constexpr int kN = 6;
constexpr int kReportInterval = 25;  // evaluations between progress reports of a stand-alone run
// Gao & Han (2012) adaptive coefficients for dimension n.
constexpr double kReflect = 1.0;
constexpr double kExpand = 1.0 + 2.0 / kN;
constexpr double kContract = 0.75 - 1.0 / (2.0 * kN);
constexpr double kShrink = 1.0 - 1.0 / kN;

struct Simplex {
  std::array<PoseVector, kN + 1> vertex;
  std::array<double, kN + 1> value;

  void sort() {
    std::array<int, kN + 1> order;
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return value[a] < value[b]; });
    const auto v = vertex;
    const auto f = value;
    for (int i = 0; i <= kN; ++i) {
      vertex[i] = v[order[i]];
      value[i] = f[order[i]];
    }
  }
  /// Largest distance of a vertex from the best one along any axis (scaled units).
  double size() const {
    double s = 0.0;
    for (int i = 1; i <= kN; ++i) s = std::max(s, (vertex[i] - vertex[0]).cwiseAbs().maxCoeff());
    return s;
  }
};

}  // namespace

Status NelderMeadOptimizer::validateOptions() const {
  const auto& o = m_options;
  if (!std::isfinite(o.tolerance) || o.tolerance <= 0.0) {
    return fail(fmt::format("Nelder–Mead tolerance must be positive (scaled units), got {}", o.tolerance));
  }
  if (!std::isfinite(o.initialStep) || o.initialStep <= o.tolerance) {
    return fail(fmt::format("Nelder–Mead initial step {} must be larger than the tolerance {} (scaled units)",
                            o.initialStep, o.tolerance));
  }
  if (o.maxEvaluations <= 0) {
    return fail(fmt::format("Nelder–Mead maximum evaluations must be positive, got {}", o.maxEvaluations));
  }
  if (o.restarts < 0) return fail(fmt::format("Nelder–Mead restarts must be 0 or more, got {}", o.restarts));
  return Ok{};
}

std::pair<PoseVector, double> NelderMeadOptimizer::searchScaled(ObjectiveEvaluator& evaluator,
                                                                const PoseVector& start_scaled,
                                                                bool* converged) const {
  const int firstEvaluation = evaluator.evaluations();
  auto outOfBudget = [&] {
    return evaluator.stopped() || evaluator.evaluations() - firstEvaluation >= m_options.maxEvaluations;
  };
  bool reachedTolerance = false;
  PoseVector best = start_scaled;
  double bestValue = evaluator.atScaled(best);

  for (int run = 0; run <= m_options.restarts && !outOfBudget(); ++run) {
    Simplex s;
    s.vertex[0] = best;
    s.value[0] = bestValue;
    for (int i = 0; i < kN; ++i) {
      s.vertex[i + 1] = best;
      s.vertex[i + 1][i] += m_options.initialStep;
      s.value[i + 1] = evaluator.atScaled(s.vertex[i + 1]);
    }
    reachedTolerance = false;
    while (!outOfBudget()) {
      s.sort();
      if (s.size() < m_options.tolerance) {
        reachedTolerance = true;
        break;
      }
      PoseVector centroid = PoseVector::Zero();
      for (int i = 0; i < kN; ++i) centroid += s.vertex[i];
      centroid /= kN;
      const PoseVector& worst = s.vertex[kN];
      const PoseVector reflected = centroid + kReflect * (centroid - worst);
      const double fr = evaluator.atScaled(reflected);
      if (fr < s.value[0]) {
        const PoseVector expanded = centroid + kExpand * (reflected - centroid);
        const double fe = evaluator.atScaled(expanded);
        if (fe < fr) {
          s.vertex[kN] = expanded;
          s.value[kN] = fe;
        } else {
          s.vertex[kN] = reflected;
          s.value[kN] = fr;
        }
        continue;
      }
      if (fr < s.value[kN - 1]) {
        s.vertex[kN] = reflected;
        s.value[kN] = fr;
        continue;
      }
      const bool outside = fr < s.value[kN];
      const PoseVector contracted =
          outside ? PoseVector(centroid + kContract * (reflected - centroid))
                  : PoseVector(centroid + kContract * (worst - centroid));
      const double fc = evaluator.atScaled(contracted);
      if (outside ? fc <= fr : fc < s.value[kN]) {
        s.vertex[kN] = contracted;
        s.value[kN] = fc;
        continue;
      }
      for (int i = 1; i <= kN; ++i) {
        s.vertex[i] = s.vertex[0] + kShrink * (s.vertex[i] - s.vertex[0]);
        s.value[i] = evaluator.atScaled(s.vertex[i]);
      }
    }
    s.sort();
    const bool improved = s.value[0] < bestValue;
    if (s.value[0] <= bestValue) {
      best = s.vertex[0];
      bestValue = s.value[0];
    }
    // A restart that finds nothing better confirms the minimum; stop early.
    if (run > 0 && !improved) break;
  }
  if (converged) *converged = reachedTolerance;
  return {best, bestValue};
}

OptimizationResult NelderMeadOptimizer::search(const PoseObjective& objective, const PoseVector& start,
                                               const PoseVector& scales, const ProgressMonitor& monitor) const {
  ObjectiveEvaluator evaluator(objective, start, scales, m_options.maxEvaluations, monitor);
  evaluator.reportEvery(kReportInterval, name());
  bool converged = false;
  (void)searchScaled(evaluator, evaluator.toScaled(start), &converged);
  OptimizationResult result = evaluator.result(converged);
  monitor.report(name(), 1.0,
                 fmt::format("{} evaluations, best value {:.6g}{}", result.evaluations, result.value,
                             result.cancelled ? " (cancelled)" : ""));
  return result;
}

}  // namespace fct
