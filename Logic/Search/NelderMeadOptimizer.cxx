#include "Search/NelderMeadOptimizer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace fct {

namespace {

constexpr int kN = 6;
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

std::pair<PoseVector, double> NelderMeadOptimizer::searchScaled(ObjectiveEvaluator& evaluator,
                                                                const PoseVector& start_scaled,
                                                                bool* converged) const {
  const int firstEvaluation = evaluator.evaluations();
  StallDetector stall(m_options.stall);
  auto outOfBudget = [&] {
    return evaluator.stopped() || evaluator.evaluations() - firstEvaluation >= m_options.maxEvaluations ||
           stall.stalled();
  };
  auto evaluate = [&](const PoseVector& y_scaled) {
    const double value = evaluator.atScaled(y_scaled);
    stall.add(value);
    return value;
  };
  bool reachedTolerance = false;
  PoseVector best = start_scaled;
  double bestValue = evaluate(best);

  for (int run = 0; run <= m_options.restarts && !outOfBudget(); ++run) {
    Simplex s;
    s.vertex[0] = best;
    s.value[0] = bestValue;
    for (int i = 0; i < kN; ++i) {
      s.vertex[i + 1] = best;
      s.vertex[i + 1][i] += m_options.initialStep;
      s.value[i + 1] = evaluate(s.vertex[i + 1]);
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
      const double fr = evaluate(reflected);
      if (fr < s.value[0]) {
        const PoseVector expanded = centroid + kExpand * (reflected - centroid);
        const double fe = evaluate(expanded);
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
      const double fc = evaluate(contracted);
      if (outside ? fc <= fr : fc < s.value[kN]) {
        s.vertex[kN] = contracted;
        s.value[kN] = fc;
        continue;
      }
      for (int i = 1; i <= kN; ++i) {
        s.vertex[i] = s.vertex[0] + kShrink * (s.vertex[i] - s.vertex[0]);
        s.value[i] = evaluate(s.vertex[i]);
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

}  // namespace fct
