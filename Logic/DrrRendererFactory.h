#pragma once
// DrrRendererFactory: picks a DRR method by name and builds its renderer for a prepared CT.

#include <memory>
#include <string_view>

#include "DrrRenderer.h"
#include "DrrVolume.h"
#include "Result.h"

namespace fct {

/// The DRR methods.
enum class DrrMethod {
  RayCast,  ///< "raycast": trilinear sampling at a fixed step (TrilinearRayCaster)
  Siddon,   ///< "siddon": exact voxel traversal (SiddonRayCaster)
};

/// Method and method parameters of a renderer.
struct DrrRendererOptions {
  DrrMethod method = DrrMethod::Siddon;
  double rayCastStep_mm = 0.0;  ///< RayCast sampling step; 0 selects TrilinearRayCaster::defaultStep_mm
};

/// Builds DRR renderers.
class DrrRendererFactory {
 public:
  /// Parses "raycast" or "siddon"; the error lists the accepted names.
  static Result<DrrMethod> parseMethod(std::string_view name);
  /// The name parseMethod() accepts for `method`.
  static std::string_view methodName(DrrMethod method);
  /// A renderer of `volume` with the given options. Fails on a null or empty volume, or a ray-cast step that is
  /// negative, non-finite or below 1/100 of the smallest voxel spacing.
  static Result<std::unique_ptr<DrrRenderer>> create(std::shared_ptr<const DrrVolume> volume,
                                                     const DrrRendererOptions& options = {});
};

}  // namespace fct
