#include "Search/PoseOptimizer.h"

#include <fmt/core.h>

#include <cmath>

namespace fct {

namespace {
constexpr const char* kParameterNames[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
}  // namespace

Result<PoseVector> PoseOptimizer::scalesForBoneRadius(double radius_mm) {
  if (!std::isfinite(radius_mm) || radius_mm <= 0.0) {
    return fail(fmt::format("bone radius must be a positive number of mm to derive parameter scales, got {}", radius_mm));
  }
  PoseVector scales;
  const double rotation_deg = 180.0 / (M_PI * radius_mm);
  scales << rotation_deg, rotation_deg, rotation_deg, 1.0, 1.0, 1.0;
  return scales;
}

Status PoseOptimizer::validateInputs(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales) {
  if (!objective) return fail("no objective function given to the pose optimizer");
  for (int i = 0; i < 6; ++i) {
    if (!std::isfinite(start[i])) {
      return fail(fmt::format("start pose parameter {} is {}; give a finite initial pose", kParameterNames[i], start[i]));
    }
    if (!std::isfinite(scales[i]) || scales[i] <= 0.0) {
      return fail(fmt::format("scale of pose parameter {} must be positive and finite, got {}; use "
                              "PoseOptimizer::scalesForBoneRadius",
                              kParameterNames[i], scales[i]));
    }
  }
  return Ok{};
}

Result<OptimizationResult> PoseOptimizer::minimize(const PoseObjective& objective, const PoseVector& start,
                                                   const PoseVector& scales, const ProgressMonitor& monitor) const {
  if (Status inputs = validateInputs(objective, start, scales); !inputs) return fail(inputs.error());
  if (Status options = validateOptions(); !options) return fail(options.error());
  OptimizationResult result = search(objective, start, scales, monitor);
  if (!std::isfinite(result.value) && !result.cancelled) {
    return fail(fmt::format("{}: the objective gave NaN or infinity at all {} evaluated poses; check that the poses "
                            "project the CT into the images",
                            name(), result.evaluations));
  }
  return result;
}

}  // namespace fct
