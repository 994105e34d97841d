#include "DrrRendererFactory.h"

#include <fmt/core.h>

#include <cmath>

#include "SiddonRayCaster.h"
#include "TrilinearRayCaster.h"

namespace fct {

Result<DrrMethod> DrrRendererFactory::parseMethod(std::string_view name) {
  if (name == "raycast") return DrrMethod::RayCast;
  if (name == "siddon") return DrrMethod::Siddon;
  return fail(fmt::format("unknown DRR method '{}'; use 'raycast' or 'siddon'", name));
}

std::string_view DrrRendererFactory::methodName(DrrMethod method) {
  switch (method) {
    case DrrMethod::RayCast: return "raycast";
    case DrrMethod::Siddon: return "siddon";
  }
  return "unknown";
}

Result<std::unique_ptr<DrrRenderer>> DrrRendererFactory::create(std::shared_ptr<const DrrVolume> volume,
                                                                const DrrRendererOptions& options) {
  if (!volume || volume->values().voxelCount() == 0) {
    return fail("no CT prepared for DRR rendering; load a CT and convert it with DrrVolume::create first");
  }
  switch (options.method) {
    case DrrMethod::RayCast: {
      const double step_mm = options.rayCastStep_mm;
      const double minSpacing_mm = volume->values().spacing_mm().minCoeff();
      if (!std::isfinite(step_mm) || step_mm < 0.0 || (step_mm > 0.0 && step_mm < 0.01 * minSpacing_mm)) {
        return fail(fmt::format("ray-cast step must be 0 (default) or at least {:.4g} mm (1/100 of the smallest voxel "
                                "spacing), got {} mm",
                                0.01 * minSpacing_mm, step_mm));
      }
      return std::unique_ptr<DrrRenderer>(std::make_unique<TrilinearRayCaster>(std::move(volume), step_mm));
    }
    case DrrMethod::Siddon:
      return std::unique_ptr<DrrRenderer>(std::make_unique<SiddonRayCaster>(std::move(volume)));
  }
  return fail("unknown DRR method");
}

}  // namespace fct
