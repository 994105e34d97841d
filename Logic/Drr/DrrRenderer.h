#pragma once
// DrrRenderer: the one interface through which everything renders digitally reconstructed radiographs (DRRs).
// A DRR pixel is the line integral of the DrrVolume's values along the segment from the X-ray source to the pixel
// centre on the detector (dimensionless for attenuation values, value·mm for raw values); 0 where the ray misses the CT.
// Implementations differ only in how they integrate a batch of rays; the checks and the pyramid/pixel-list logic
// live here. One virtual call per render, none per ray. Rendering is const and thread-safe: one renderer may
// serve several threads at once (e.g. one per view).

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "Base/Result.h"
#include "Drr/DrrVolume.h"
#include "Geometry/Camera.h"
#include "Image/FloatImage.h"

namespace fct {

/// What one render did besides its values.
struct DrrRenderStats {
  std::size_t fallbackRays = 0;  ///< rays outside a ray table (Transgraph) that were integrated exactly instead
};

/// Renders DRRs of one prepared CT for any camera and pose.
class DrrRenderer {
 public:
  virtual ~DrrRenderer() = default;
  DrrRenderer(const DrrRenderer&) = delete;
  DrrRenderer& operator=(const DrrRenderer&) = delete;

  /// The method's name as accepted by DrrRendererFactory ("raycast", "siddon", ...).
  virtual std::string_view methodName() const = 0;
  /// The prepared CT this renderer integrates.
  const DrrVolume& volume() const { return *m_volume; }

  /// Renders every pixel of camera.downsampled(level) for the CT at pose T_world_from_ct (CT mm -> world mm) into
  /// `image`, which is resized to that detector (its buffer is reused when large enough). Fails, leaving `image`
  /// untouched, on an invalid camera, a non-rigid or non-finite pose, or a level < 0 or one that leaves no pixels.
  /// With `stats`, the render's statistics are written there.
  Status render(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level, FloatImage& image,
                DrrRenderStats* stats = nullptr) const;
  /// As above, returning a new image.
  Result<FloatImage> render(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level = 0,
                            DrrRenderStats* stats = nullptr) const;

  /// Renders only the listed pixels (linear indices row*cols+col of the detector of camera.downsampled(level)):
  /// values[n] is pixel pixels[n], in list order; `values` is resized to pixels.size() (buffer reused). Duplicates are
  /// allowed. An empty list gives an empty result, not an error. Fails, leaving `values` untouched, on the errors of
  /// render() and on any index outside [0, cols*rows). With `stats`, the render's statistics are written there.
  Status renderPixels(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level,
                      const PixelIndexList& pixels, std::vector<float>& values, DrrRenderStats* stats = nullptr) const;
  /// As above, returning a new vector.
  Result<std::vector<float>> renderPixels(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level,
                                          const PixelIndexList& pixels, DrrRenderStats* stats = nullptr) const;

 protected:
  /// Takes shared ownership of a prepared CT; `volume` must not be null (DrrRendererFactory checks).
  explicit DrrRenderer(std::shared_ptr<const DrrVolume> volume);

  /// Integrates the rays of `count` pixels of the already validated `levelCamera`: pixel n is pixels[n] or, when
  /// `pixels` is null, linear index n. Writes values[n] and returns the render's statistics. Must be deterministic
  /// (independent of thread count).
  virtual DrrRenderStats integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                               const std::int32_t* pixels, std::size_t count, float* values) const = 0;

 private:
  /// The camera of `level` after checking camera, pose and level; the error names the bad input.
  Result<Camera> levelCamera(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level) const;

  std::shared_ptr<const DrrVolume> m_volume;
};

}  // namespace fct
