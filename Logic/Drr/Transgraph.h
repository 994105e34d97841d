#pragma once
// Transgraph (LaRose et al. 2000; Knaan & Joskowicz 2003): a precomputed table of ray integrals through the CT for
// one view, valid for poses near an expected pose, read back by quadrilinear interpolation.
//
// Geometry (all in the CT frame, LPS mm). The plane frame has its origin at the centre of the CT's bounding box and
// axes (s, t, w) = the view camera's (x, y, z) axes seen from the CT at the expected pose, so w is the principal
// direction. The front plane w = front_w_mm and the back plane w = back_w_mm enclose the CT's bounding box. A ray
// from (s1, t1) on the front plane to (s2, t2) on the back plane is stored by its mid-plane point
// (s, t) = ((s1 + s2) / 2, (t1 + t2) / 2) and its offset (ds, dt) = (s2 - s1, t2 - t1); each of the four coordinates
// is sampled on a regular grid. The offset keeps only the band of rays that a C-arm can produce (several times fewer
// than the full (s1, t1, s2, t2) box), and the mid-plane point makes an offset step pivot the ray about the CT's
// middle, which measured ~20 % less interpolation error than pivoting about the front plane. An offset step moves the
// ray inside the CT at most half as far as a step of (s, t), so the offsets are sampled more coarsely (3x by default,
// chosen by measurement: at a fixed ray budget it gave a higher NCC with the exact DRR than 1x or 2x).
// The table value of a ray is the integral from its front-plane point to its back-plane point, which equals the
// integral along the whole line because the CT lies between the planes.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <atomic>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "Base/ProgressMonitor.h"
#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Image/Volume.h"

namespace fct {

/// Poses for which the table is built: the expected pose followed by a rotation of up to ±rotation_deg about each world
/// axis through the CT box centre (R = Rz·Ry·Rx) and a translation of up to ±translation_mm along each world axis.
struct TransgraphRange {
  double rotation_deg = 15.0;
  double translation_mm = 30.0;
};

/// Build parameters of a Transgraph.
struct TransgraphParameters {
  /// Sampling step of the mid-plane point (s, t), mm. 3 mm gives the paper's scale (15-30 M rays, 60-120 MB) for a
  /// pelvis or head CT at ±15 deg, ±30 mm; 1.5 mm would need 16x more (rays grow with spacing^-4).
  double spacing_mm = 3.0;
  double offsetSpacing_mm = 0.0;     ///< sampling step of the offset (ds, dt), mm; 0 = 3 x spacing_mm
  TransgraphRange range;             ///< validity range around the expected pose
  double planeMargin_mm = 1.0;       ///< gap between the CT's bounding box and each plane
  std::size_t maxRays = 250'000'000; ///< refuse tables larger than this (4 bytes per ray)
  std::string integratorId;          ///< names the ray integrator and its value mapping; part of the cache key
};

/// Where the table lies and how it is sampled; determined by the CT box, the view, the expected pose and parameters.
struct TransgraphLayout {
  Eigen::Vector3d origin_ct_mm = Eigen::Vector3d::Zero();           ///< plane-frame origin (CT box centre), CT mm
  Eigen::Matrix3d R_ct_from_plane = Eigen::Matrix3d::Identity();    ///< columns: s, t, w axes in the CT frame
  double front_w_mm = 0.0;                                          ///< w of the front plane (source side)
  double back_w_mm = 0.0;                                           ///< w of the back plane (detector side)
  Eigen::Vector4d min_mm = Eigen::Vector4d::Zero();                 ///< first sample of (s, t, ds, dt) in mm
  Eigen::Vector4d step_mm = Eigen::Vector4d::Ones();                ///< sample step of (s, t, ds, dt), mm
  std::array<int, 4> counts{0, 0, 0, 0};                            ///< samples along s, t, ds, dt

  /// Number of stored rays (product of counts).
  std::size_t rayCount() const;
  /// Bytes of the table (float per ray).
  std::size_t memory_bytes() const { return rayCount() * sizeof(float); }
  /// Front- and back-plane endpoints (CT mm) of the stored ray with sample indices (i_s, i_t, i_ds, i_dt).
  std::pair<Eigen::Vector3d, Eigen::Vector3d> rayEndpoints_ct_mm(int is, int it, int ids, int idt) const;
};

/// How a Transgraph came to be: built (and how long it took) or loaded from the disk cache.
struct TransgraphBuildInfo {
  double build_s = 0.0;               ///< wall time of the fill (or of the load), seconds
  bool loadedFromCache = false;       ///< true when the table was read from cacheFile instead of built
  std::filesystem::path cacheFile;    ///< cache file read or written (empty without a cache)
};

/// A ray table for one view, filled by an exact ray integrator and rendered by quadrilinear interpolation.
class Transgraph {
 public:
  /// Exact integral along the segment between two CT points (mm). Must be thread-safe.
  using RayIntegrator = std::function<double(const Eigen::Vector3d& from_ct_mm, const Eigen::Vector3d& to_ct_mm)>;

  Transgraph() = default;

  /// Computes the layout (planes, extents, counts) for the view's detector and every pose in the range, without
  /// filling. Fails on an empty volume, an invalid camera, a non-positive spacing or range, a source that comes
  /// within the CT's slab, or a table larger than parameters.maxRays (the message gives the spacing that would fit).
  static Result<TransgraphLayout> plan(const Volume& ct, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
                                       const TransgraphParameters& parameters);

  /// Plans and fills a table with `integrator`, in parallel over (s, t) rows. Fails like plan(), on a missing
  /// integrator, or when the monitor is cancelled.
  static Result<Transgraph> build(const Volume& ct, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
                                  const TransgraphParameters& parameters, RayIntegrator integrator,
                                  const ProgressMonitor& monitor = {});

  /// A Transgraph from a layout and its table values (e.g. read from disk, as `buildInfo` says); fails if the sizes
  /// disagree.
  static Result<Transgraph> fromTable(const TransgraphLayout& layout, std::vector<float> table,
                                      RayIntegrator integrator, TransgraphBuildInfo buildInfo = {});

  /// Integrates the rays of `count` pixels of `levelCamera` (already downsampled to the wanted pyramid level) for the
  /// CT at pose T_world_from_ct: pixel n is pixels[n] (linear index row * cols + col) or, when `pixels` is null,
  /// linear index n; writes values[n]. Rays outside the table use the integrator; returns how many did.
  /// Parallel and deterministic. Preconditions (checked by DrrRenderer): a non-empty Transgraph, a valid camera and
  /// pose, valid indices.
  std::size_t integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                       const std::int32_t* pixels, std::size_t count, float* values) const;

  /// The integral along the line through source_ct_mm and end_ct_mm (CT frame, mm), interpolated from the table;
  /// when the ray is outside the table, the integrator's value from the source to end_ct_mm. Sets *usedFallback.
  float integrate(const Eigen::Vector3d& source_ct_mm, const Eigen::Vector3d& end_ct_mm,
                  bool* usedFallback = nullptr) const;

  /// The table's geometry and sampling.
  const TransgraphLayout& layout() const { return m_layout; }
  /// The stored ray integrals, s slowest, then t, ds, dt fastest.
  const std::vector<float>& table() const { return m_table; }
  /// Number of stored rays.
  std::size_t rayCount() const { return m_table.size(); }
  /// Bytes of the stored table.
  std::size_t memory_bytes() const { return m_table.size() * sizeof(float); }
  /// How the table was obtained (build time or cache load).
  const TransgraphBuildInfo& buildInfo() const { return m_buildInfo; }
  /// Names the cache file the table was saved to (TransgraphCache::buildOrLoad after a build).
  void setCacheFile(const std::filesystem::path& file) { m_buildInfo.cacheFile = file; }

 private:
  struct PixelSampler;
  PixelSampler sampler(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct) const;
  // Quadrilinear table value of a plane-frame ray, NaN when the ray is outside the table.
  float interpolate(const Eigen::Vector3d& source_plane_mm, const Eigen::Vector3d& direction_plane) const;

  TransgraphLayout m_layout;
  std::vector<float> m_table;
  RayIntegrator m_integrator;
  TransgraphBuildInfo m_buildInfo;
};

}  // namespace fct
