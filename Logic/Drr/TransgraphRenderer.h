#pragma once
// TransgraphRenderer: the "transgraph" DRR method. Renders by quadrilinear interpolation in a Transgraph built for
// one view and an expected pose (see Transgraph.h); rays outside the table fall back to the exact Siddon integral.
// Values are those of the DrrVolume (attenuation or raw), like every DrrRenderer.

#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <optional>

#include "Base/ProgressMonitor.h"
#include "Drr/DrrRenderer.h"
#include "Drr/Transgraph.h"

namespace fct {

/// DRR renderer backed by a Transgraph.
class TransgraphRenderer final : public DrrRenderer {
 public:
  /// Builds the Transgraph of `view` around the expected pose T_world_from_ct, filled with SiddonRayCaster on
  /// `volume`; with a cacheFolder (empty path: TransgraphCache::defaultFolder()) a table cached by an earlier run is
  /// loaded instead and a new one is saved. parameters.integratorId is set from the volume's value options.
  /// Fails on a null or empty volume and like TransgraphCache::buildOrLoad(); cache problems are warnings of the result.
  static Result<std::unique_ptr<TransgraphRenderer>> create(std::shared_ptr<const DrrVolume> volume,
                                                            const Camera& view,
                                                            const Eigen::Isometry3d& T_world_from_ct,
                                                            TransgraphParameters parameters = {},
                                                            const std::optional<std::filesystem::path>& cacheFolder = {},
                                                            const ProgressMonitor& monitor = {});

  /// Wraps an already built or loaded Transgraph (of any integrator) over `volume`. Fails on a null volume or an
  /// empty Transgraph.
  static Result<std::unique_ptr<TransgraphRenderer>> fromTransgraph(std::shared_ptr<const DrrVolume> volume,
                                                                    Transgraph transgraph);

  std::string_view methodName() const override { return "transgraph"; }

  /// The table: layout, ray count, memory, build or load time.
  const Transgraph& transgraph() const { return m_transgraph; }

 protected:
  /// Rays outside the table are integrated exactly and counted in the statistics.
  DrrRenderStats integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                                 const std::int32_t* pixels, std::size_t count, float* values) const override;

 private:
  TransgraphRenderer(std::shared_ptr<const DrrVolume> volume, Transgraph transgraph);

  Transgraph m_transgraph;
};

}  // namespace fct
