#include "Widgets/RunTimeEstimator.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

namespace fct {

Result<std::vector<double>> RunTimeEstimator::measureSecondsPerPixel(RegistrationCase& registrationCase,
                                                                    const Eigen::Isometry3d& T_world_from_ct) {
  using Clock = std::chrono::steady_clock;
  std::vector<double> secondsPerPixel;
  for (int level = 0; level < registrationCase.levelCount(); ++level) {
    double seconds = 0.0;
    double pixels = 0.0;
    for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) {
      auto renderer = registrationCase.levelRenderer(v, level, T_world_from_ct);  // made before the clock starts
      if (!renderer) return fail(renderer.error());
      const Clock::time_point start = Clock::now();
      auto drr = renderer.value()->render(registrationCase.camera(v), T_world_from_ct, level);
      seconds += std::chrono::duration<double>(Clock::now() - start).count();
      if (!drr) return fail(fmt::format("view '{}': {}", registrationCase.viewName(v), drr.error()));
      pixels += static_cast<double>(drr.value().pixels.size());
    }
    secondsPerPixel.push_back(pixels > 0.0 ? seconds / pixels : 0.0);
  }
  return secondsPerPixel;
}

Result<double> RunTimeEstimator::budgetSeconds(const RegistrationSchedule& schedule,
                                               const RegistrationCase& registrationCase,
                                               const std::vector<double>& secondsPerPixel) {
  double total_s = 0.0;
  for (const RegistrationStage& stage : schedule.stages) {
    if (stage.level < 0 || stage.level >= static_cast<int>(secondsPerPixel.size()) ||
        stage.level >= registrationCase.levelCount()) {
      return fail(fmt::format("stage '{}' uses pyramid level {}, which the case does not have", stage.name, stage.level));
    }
    double pixels = 0.0;
    for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) {
      const double valid = static_cast<double>(registrationCase.prepared(v).pyramid.level(stage.level).mask.validCount());
      if (stage.pixels.kind == PixelSetKind::Rois) {
        pixels += stage.pixels.targetFraction * valid;
      } else if (stage.metric != SimilarityMetric::Vlnc && stage.pixels.maxPixels > 0) {
        pixels += std::min(valid, static_cast<double>(stage.pixels.maxPixels));
      } else {
        pixels += valid;
      }
    }
    total_s += stage.maxEvaluations * pixels * secondsPerPixel[static_cast<std::size_t>(stage.level)];
  }
  return total_s;
}

}  // namespace fct
