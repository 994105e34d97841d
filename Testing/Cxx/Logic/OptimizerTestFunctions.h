#pragma once
// Analytic objectives for the optimizer tests, in scaled coordinates d = (p - target) / scales.

#include <atomic>
#include <cmath>

#include "Search/PoseOptimizer.h"

namespace fct::test {

/// Scales of a bone of radius 57.3 mm: about 1 deg and 1 mm per scaled unit.
inline PoseVector unitScales() { return PoseOptimizer::scalesForBoneRadius(180.0 / M_PI).value(); }

/// A pose away from zero, used as the global minimum.
inline PoseVector targetPose() {
  PoseVector t;
  t << 3.0, -2.0, 5.0, 10.0, -4.0, 7.0;
  return t;
}

/// `objective`, counting its calls in `calls` and raising `cancel` at call number `cancelAt` (a user pressing Cancel).
inline PoseObjective cancellingAt(int cancelAt, PoseObjective objective, int& calls, std::atomic<bool>& cancel) {
  return [cancelAt, objective = std::move(objective), &calls, &cancel](const PoseVector& p) {
    if (++calls == cancelAt) cancel = true;
    return objective(p);
  };
}

/// Quadratic bowl with different curvatures per axis; minimum 0 at target.
inline PoseObjective bowl(const PoseVector& target, const PoseVector& scales) {
  return [=](const PoseVector& p) {
    const PoseVector d = (p - target).cwiseQuotient(scales);
    PoseVector w;
    w << 1.0, 2.0, 0.5, 1.0, 3.0, 0.7;
    return d.cwiseProduct(d).dot(w);
  };
}

/// 6-D Rosenbrock in scaled units, minimum 0 at target + scales (d = 1).
inline PoseObjective rosenbrock(const PoseVector& target, const PoseVector& scales) {
  return [=](const PoseVector& p) {
    const PoseVector d = (p - target).cwiseQuotient(scales);
    double f = 0.0;
    for (int i = 0; i < 5; ++i) f += 100.0 * std::pow(d[i + 1] - d[i] * d[i], 2) + std::pow(1.0 - d[i], 2);
    return f;
  };
}

/// A bowl plus cosine bumps of period 4 scaled units along each axis: per axis, local minima near d = -4, 0, +4, so
/// 3^6 local minima in all; the global one (value 0) at target.
inline PoseObjective bumpyBowl(const PoseVector& target, const PoseVector& scales) {
  return [=](const PoseVector& p) {
    const PoseVector d = (p - target).cwiseQuotient(scales);
    double f = 0.0;
    for (int i = 0; i < 6; ++i) f += 0.15 * d[i] * d[i] + 1.0 - std::cos(2.0 * M_PI * d[i] / 4.0);
    return f;
  };
}

/// A start in the corner local minimum d = (4, -4, 4, 4, -4, 4) of bumpyBowl, where the simplex alone is trapped.
inline PoseVector trappedStart(const PoseVector& target, const PoseVector& scales) {
  PoseVector d;
  d << 4.0, -4.0, 4.0, 4.0, -4.0, 4.0;
  return target + d.cwiseProduct(scales);
}

/// Distance of p from target in scaled units.
inline double scaledDistance(const PoseVector& p, const PoseVector& target, const PoseVector& scales) {
  return (p - target).cwiseQuotient(scales).norm();
}

}  // namespace fct::test
