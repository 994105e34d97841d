#include "Drr/TransgraphRenderer.h"

#include "Drr/SiddonRayCaster.h"
#include "Drr/TransgraphCache.h"

namespace fct {

Result<std::unique_ptr<TransgraphRenderer>> TransgraphRenderer::create(
    std::shared_ptr<const DrrVolume> volume, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
    TransgraphParameters parameters, const std::optional<std::filesystem::path>& cacheFolder,
    const ProgressMonitor& monitor) {
  if (!volume || volume->values().voxelCount() == 0) {
    return fail("the transgraph DRR method needs a prepared CT, got an empty one");
  }
  auto siddon = std::make_shared<const SiddonRayCaster>(volume);
  Transgraph::RayIntegrator integrator = [siddon](const Eigen::Vector3d& from_ct_mm, const Eigen::Vector3d& to_ct_mm) {
    return siddon->integrate(from_ct_mm, to_ct_mm);
  };
  // The cache key hashes the prepared values (attenuation or raw), so the id only names the integrator.
  parameters.integratorId = "siddon";
  auto built = cacheFolder ? TransgraphCache::buildOrLoad(volume->values(), view, T_world_from_ct, parameters,
                                                     std::move(integrator), *cacheFolder, monitor)
                           : Transgraph::build(volume->values(), view, T_world_from_ct, parameters,
                                               std::move(integrator), monitor);
  if (!built) return fail(built.error());
  auto renderer = fromTransgraph(std::move(volume), std::move(built.value()));
  for (const auto& warning : built.warnings()) renderer.addWarning(warning);
  return renderer;
}

Result<std::unique_ptr<TransgraphRenderer>> TransgraphRenderer::fromTransgraph(std::shared_ptr<const DrrVolume> volume,
                                                                               Transgraph transgraph) {
  if (!volume) return fail("the transgraph DRR method needs a prepared CT, got none");
  if (transgraph.rayCount() == 0) return fail("the Transgraph is empty; build or load it before rendering");
  return std::unique_ptr<TransgraphRenderer>(new TransgraphRenderer(std::move(volume), std::move(transgraph)));
}

TransgraphRenderer::TransgraphRenderer(std::shared_ptr<const DrrVolume> volume, Transgraph transgraph)
    : DrrRenderer(std::move(volume)), m_transgraph(std::move(transgraph)) {}

DrrRenderStats TransgraphRenderer::integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                                                   const std::int32_t* pixels, std::size_t count, float* values) const {
  return {m_transgraph.integratePixels(levelCamera, T_world_from_ct, pixels, count, values)};
}

}  // namespace fct
