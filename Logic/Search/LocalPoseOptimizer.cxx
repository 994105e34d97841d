#include "Search/LocalPoseOptimizer.h"

#include <fmt/core.h>

#include <cmath>

#include "Search/BobyqaOptimizer.h"
#include "Search/NelderMeadOptimizer.h"

namespace fct {

namespace {
constexpr int kReportInterval = 25;  // evaluations between progress reports of a stand-alone run
}  // namespace

std::unique_ptr<LocalPoseOptimizer> LocalPoseOptimizer::create(const LocalSearchOptions& options) {
  if (options.method == LocalSearchMethod::Bobyqa) return std::make_unique<BobyqaOptimizer>(options);
  return std::make_unique<NelderMeadOptimizer>(options);
}

Status LocalPoseOptimizer::validateOptions() const {
  const auto& o = m_options;
  if (!std::isfinite(o.tolerance) || o.tolerance <= 0.0) {
    return fail(fmt::format("{} tolerance must be positive (scaled units), got {}", name(), o.tolerance));
  }
  if (!std::isfinite(o.initialStep) || o.initialStep <= o.tolerance) {
    return fail(fmt::format("{} initial step {} must be larger than the tolerance {} (scaled units)", name(),
                            o.initialStep, o.tolerance));
  }
  if (o.maxEvaluations <= 0) {
    return fail(fmt::format("{} maximum evaluations must be positive, got {}", name(), o.maxEvaluations));
  }
  if (o.restarts < 0) return fail(fmt::format("{} restarts must be 0 or more, got {}", name(), o.restarts));
  if (const Status stall = StallDetector(o.stall).validate(); !stall) {
    return fail(fmt::format("{} {}", name(), stall.error()));
  }
  return Ok{};
}

OptimizationResult LocalPoseOptimizer::search(const PoseObjective& objective, const PoseVector& start,
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
