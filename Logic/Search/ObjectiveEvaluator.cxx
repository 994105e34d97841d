#include "Search/ObjectiveEvaluator.h"

#include <fmt/core.h>

#include <cmath>
#include <limits>

namespace fct {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

ObjectiveEvaluator::ObjectiveEvaluator(const PoseObjective& objective, const PoseVector& start,
                                       const PoseVector& scales, int maxEvaluations, const ProgressMonitor& monitor)
    : m_objective(objective), m_scales(scales), m_maxEvaluations(maxEvaluations), m_monitor(monitor),
      m_bestValue(kInf), m_bestParams(start) {}

double ObjectiveEvaluator::atScaled(const PoseVector& y_scaled) {
  if (stopped()) return kInf;
  if (m_monitor.cancelled()) {
    m_cancelled = true;
    return kInf;
  }
  const PoseVector params = toParams(y_scaled);
  double value = m_objective(params);
  ++m_evaluations;
  if (std::isnan(value)) value = kInf;
  if (value < m_bestValue) {
    m_bestValue = value;
    m_bestParams = params;
  }
  if (m_reportInterval > 0 && m_evaluations % m_reportInterval == 0) {
    m_monitor.report(m_reportStage, static_cast<double>(m_evaluations) / m_maxEvaluations,
                     fmt::format("{} evaluations, best value {:.6g}", m_evaluations, m_bestValue));
  }
  return value;
}

OptimizationResult ObjectiveEvaluator::result(bool converged) const {
  OptimizationResult result;
  result.params = m_bestParams;
  result.value = m_bestValue;
  result.evaluations = m_evaluations;
  result.converged = converged && !m_cancelled;
  result.cancelled = m_cancelled;
  return result;
}

}  // namespace fct
