#pragma once
// SiddonRayCaster: exact DRRs by voxel traversal (Siddon 1985 path lengths, traversed incrementally as in
// Jacobs et al. 1998 / Amanatides & Woo 1987). Each voxel is the box of one spacing around its centre; a ray's
// integral is the sum over the voxels it crosses of (path length in the voxel) x (voxel value). Near-axis rays (AP,
// lateral) cross their dominant axis in runs: every voxel of a run but the first has the same path length, so a run
// is a strided sum of voxel values (about half the instructions per DRR of single-boundary stepping on the head CT).
// On a processor with AVX-512, renders integrate 16 neighbouring rays at once (SiddonPacketKernel): 2-3x faster on
// the head CT, the same integrals within about 1e-6 (float positions); `integrate` is always the scalar traversal.

#include <Eigen/Core>
#include <cstdint>
#include <memory>

#include "Drr/IndexSpaceRayCaster.h"
#include "Drr/SiddonPacketKernel.h"

namespace fct {

/// How SiddonRayCaster walks the rays of a render.
enum class SiddonTraversal {
  Fastest,  ///< packets of 16 rays (SiddonPacketKernel) where the processor has AVX-512, else one ray at a time
  Scalar,   ///< one ray at a time (the reference)
};

/// Exact voxel-traversal DRR renderer.
class SiddonRayCaster final : public IndexSpaceRayCaster<SiddonRayCaster> {
 public:
  /// A renderer of `volume` (must not be null) walking its rays as `traversal` says.
  explicit SiddonRayCaster(std::shared_ptr<const DrrVolume> volume,
                           SiddonTraversal traversal = SiddonTraversal::Fastest);

  std::string_view methodName() const override { return "siddon"; }
  /// True when renders use the AVX-512 packets (asked for, and the processor has AVX-512).
  bool usesPackets() const { return m_packets; }

 protected:
  DrrRenderStats integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                                 const std::int32_t* pixels, std::size_t count, float* values) const override;

 private:
  friend class IndexSpaceRayCaster<SiddonRayCaster>;
  /// Integral along the index-space segment a_ijk -> b_ijk whose physical length is length_mm.
  double integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk, double length_mm) const;
  /// The packet kernel's view of the volume for rays whose dominant index axis is `axis` (0 = i, 1 = j, 2 = k). Rays
  /// along i read the volume's j-fastest copy, so that the window axis is contiguous.
  SiddonPacketLayout packetLayout(int axis) const;

  bool m_packets = false;
};

}  // namespace fct
