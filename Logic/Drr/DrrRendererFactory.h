#pragma once
// DrrRendererFactory: picks a DRR method by name and builds its renderer for a prepared CT.

#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <optional>
#include <string_view>

#include "Base/ProgressMonitor.h"
#include "Base/Result.h"
#include "Drr/DrrRenderer.h"
#include "Drr/DrrVolume.h"
#include "Drr/Transgraph.h"

namespace fct {

/// The DRR methods.
enum class DrrMethod {
  RayCast,  ///< "raycast": trilinear sampling at a fixed step (TrilinearRayCaster)
  Siddon,   ///< "siddon": exact voxel traversal (SiddonRayCaster)
  Transgraph,  ///< "transgraph": precomputed ray table of one view around an expected pose (TransgraphRenderer)
};

/// Method and method parameters of a renderer.
struct DrrRendererOptions {
  DrrMethod method = DrrMethod::Siddon;
  double rayCastStep_mm = 0.0;  ///< RayCast sampling step; 0 selects TrilinearRayCaster::defaultStep_mm
  TransgraphParameters transgraph;  ///< Transgraph table sampling and validity range
  /// Transgraph disk cache: nullopt = no cache, an empty path = TransgraphCache::defaultFolder().
  std::optional<std::filesystem::path> transgraphCacheFolder = std::filesystem::path();
};

/// Builds DRR renderers.
class DrrRendererFactory {
 public:
  /// Parses "raycast", "siddon" or "transgraph"; the error lists the accepted names.
  static Result<DrrMethod> parseMethod(std::string_view name);
  /// The name parseMethod() accepts for `method`.
  static std::string_view methodName(DrrMethod method);
  /// A renderer of `volume` with the given options. Fails on a null or empty volume, or a ray-cast step that is
  /// negative, non-finite or below 1/100 of the smallest voxel spacing.
  /// Fails for Transgraph, which is built per view: use createForView.
  static Result<std::unique_ptr<DrrRenderer>> create(std::shared_ptr<const DrrVolume> volume,
                                                     const DrrRendererOptions& options = {});
  /// A renderer for one view whose poses stay near T_expected_world_from_ct: builds (or loads from the cache) the
  /// Transgraph of that view for the Transgraph method; the view-independent methods ignore view and pose. The
  /// monitor sees the table build and can cancel it. Fails like create() and TransgraphRenderer::create().
  static Result<std::unique_ptr<DrrRenderer>> createForView(std::shared_ptr<const DrrVolume> volume,
                                                            const DrrRendererOptions& options, const Camera& view,
                                                            const Eigen::Isometry3d& T_expected_world_from_ct,
                                                            const ProgressMonitor& monitor = {});
};

}  // namespace fct
