#include "Search/GeneticSearchOptimizer.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "Base/SeededRandom.h"
#include "Geometry/RigidPose.h"

namespace fct {

namespace {
struct Guess {
  PoseVector params;
  double value;
};
}  // namespace

PoseVector GeneticSearchOptimizer::combine(const PoseVector& a, const PoseVector& b, double lambda) {
  // About centre 0 the transform's translation equals the translation parameters, so rotation and translation
  // separate: the rotation is interpolated on SO(3), the translation (of the rotation centre) linearly.
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d R_a = RigidPose::toTransform(PoseParameters::fromVector(a), origin).linear();
  const Eigen::Matrix3d R_b = RigidPose::toTransform(PoseParameters::fromVector(b), origin).linear();
  const Eigen::AngleAxisd delta(R_a.transpose() * R_b);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_a * Eigen::AngleAxisd(lambda * delta.angle(), delta.axis()).toRotationMatrix();
  T.translation() = a.tail<3>() + lambda * (b.tail<3>() - a.tail<3>());
  // T is a proper rotation by construction, so the conversion cannot fail.
  return RigidPose::fromTransform(T, origin).value().asVector();
}

Status GeneticSearchOptimizer::validateOptions() const {
  const auto& o = m_options;
  if (o.randomGuesses < 1) {
    return fail(fmt::format("genetic search needs at least 1 random guess (n), got {}", o.randomGuesses));
  }
  if (!std::isfinite(o.spreadRotation_deg) || o.spreadRotation_deg < 0.0 || !std::isfinite(o.spreadTranslation_mm) ||
      o.spreadTranslation_mm < 0.0) {
    return fail(fmt::format("genetic search spreads must be finite and non-negative, got {} deg and {} mm",
                            o.spreadRotation_deg, o.spreadTranslation_mm));
  }
  if (std::isnan(o.dropThreshold) || o.dropThreshold < 0.0) {
    return fail(fmt::format("genetic search drop threshold must be 0 or more, got {}", o.dropThreshold));
  }
  if (!std::isfinite(o.extrapolation) || o.extrapolation < 0.0) {
    return fail(fmt::format("genetic search extrapolation must be finite and 0 or more, got {}", o.extrapolation));
  }
  if (o.maxGenerations < 0) {
    return fail(fmt::format("genetic search generation limit must be 0 or more, got {}", o.maxGenerations));
  }
  if (o.maxEvaluations <= 0) {
    return fail(fmt::format("genetic search maximum evaluations must be positive, got {}", o.maxEvaluations));
  }
  for (const PoseVector& seed : o.extraSeeds) {
    if (!seed.allFinite()) return fail("genetic search extra seeds must be finite poses");
  }
  return LocalPoseOptimizer::create(o.local)->validateOptions();
}

OptimizationResult GeneticSearchOptimizer::search(const PoseObjective& objective, const PoseVector& start,
                                                  const PoseVector& scales, const ProgressMonitor& monitor) const {
  const auto& o = m_options;
  ObjectiveEvaluator evaluator(objective, start, scales, o.maxEvaluations, monitor);
  SeededRandom random(o.seed);
  const std::unique_ptr<LocalPoseOptimizer> local = LocalPoseOptimizer::create(o.local);

  int planned = o.randomGuesses + 1 + static_cast<int>(o.extraSeeds.size());
  for (int children = o.randomGuesses / 2, g = 1; children > 0 && g <= o.maxGenerations; children /= 2, ++g) {
    planned += children;
  }
  int done = 0;
  int generation = 0;
  auto refine = [&](const PoseVector& params) {
    const auto [best_scaled, value] = local->searchScaled(evaluator, evaluator.toScaled(params), nullptr);
    ++done;
    monitor.report(name(), static_cast<double>(done) / planned,
                   fmt::format("generation {}, local search {}/{}, {} evaluations, best value {:.6g}", generation, done,
                               planned, evaluator.evaluations(), evaluator.bestValue()));
    return Guess{evaluator.toParams(best_scaled), value};
  };

  std::vector<PoseVector> seeds{start};
  seeds.insert(seeds.end(), o.extraSeeds.begin(), o.extraSeeds.end());
  PoseVector spread;
  spread << Eigen::Vector3d::Constant(o.spreadRotation_deg), Eigen::Vector3d::Constant(o.spreadTranslation_mm);
  for (int i = 0; i < o.randomGuesses; ++i) {
    PoseVector p = start;
    for (int k = 0; k < 6; ++k) p[k] += random.uniform(-spread[k], spread[k]);
    seeds.push_back(p);
  }
  std::vector<Guess> population;
  for (const auto& p : seeds) {
    if (evaluator.stopped()) break;
    population.push_back(refine(p));
  }

  std::vector<GenerationRecord> records;
  bool finished = false;
  for (int children = o.randomGuesses / 2;; children /= 2) {
    std::stable_sort(population.begin(), population.end(),
                     [](const Guess& a, const Guess& b) { return a.value < b.value; });
    records.push_back({generation, evaluator.evaluations(), evaluator.bestValue(), static_cast<int>(population.size())});
    if (evaluator.stopped()) break;
    const double limit = population.front().value + o.dropThreshold;
    std::erase_if(population, [&](const Guess& g) { return !(g.value <= limit); });  // keeps the best, even if +inf
    if (population.size() == 1 || children == 0 || generation == o.maxGenerations) {
      finished = true;
      break;
    }
    ++generation;
    const std::vector<Guess> survivors = population;
    for (int c = 0; c < children && !evaluator.stopped(); ++c) {
      const int i = random.index(static_cast<int>(survivors.size()));
      int j = random.index(static_cast<int>(survivors.size()) - 1);
      if (j >= i) ++j;
      const double lambda = random.uniform(-o.extrapolation, 1.0 + o.extrapolation);
      population.push_back(refine(combine(survivors[i].params, survivors[j].params, lambda)));
    }
  }

  OptimizationResult result = evaluator.result(finished);
  result.generations = std::move(records);
  return result;
}

}  // namespace fct
