#include "Drr/DrrRendererFactory.h"

#include <fmt/core.h>

#include <cmath>

#include "Base/NameTable.h"
#include "Drr/SiddonRayCaster.h"
#include "Drr/TransgraphRenderer.h"
#include "Drr/TrilinearRayCaster.h"

namespace fct {

namespace {

/// The names of the DRR methods on the command line and in files.
constexpr NameTable<DrrMethod, 3> kMethods{
    {{"raycast", DrrMethod::RayCast}, {"siddon", DrrMethod::Siddon}, {"transgraph", DrrMethod::Transgraph}}};

}  // namespace

Result<DrrMethod> DrrRendererFactory::parseMethod(std::string_view name) {
  if (const auto method = valueNamed(name, kMethods)) return *method;
  return fail(fmt::format("unknown DRR method '{}'; use 'siddon', 'raycast' or 'transgraph'", name));
}

std::string_view DrrRendererFactory::methodName(DrrMethod method) { return nameOf(method, kMethods); }

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
    case DrrMethod::Transgraph:
      return fail("the transgraph DRR method is built for one view and an expected pose; use createForView");
  }
  return fail("unknown DRR method");
}

Result<std::unique_ptr<DrrRenderer>> DrrRendererFactory::createForView(std::shared_ptr<const DrrVolume> volume,
                                                                       const DrrRendererOptions& options,
                                                                       const Camera& view,
                                                                       const Eigen::Isometry3d& T_expected_world_from_ct,
                                                                       const ProgressMonitor& monitor) {
  if (options.method != DrrMethod::Transgraph) return create(std::move(volume), options);
  auto renderer = TransgraphRenderer::create(std::move(volume), view, T_expected_world_from_ct, options.transgraph,
                                             options.transgraphCacheFolder, monitor);
  if (!renderer.ok()) return fail(renderer.error());
  const std::vector<std::string> warnings = renderer.warnings();
  Result<std::unique_ptr<DrrRenderer>> result(std::unique_ptr<DrrRenderer>(std::move(renderer).value()));
  for (const auto& warning : warnings) result.addWarning(warning);
  return result;
}

}  // namespace fct
