#pragma once
// SiddonRayCaster: exact DRRs by voxel traversal (Siddon 1985 path lengths, traversed incrementally as in
// Jacobs et al. 1998 / Amanatides & Woo 1987). Each voxel is the box of one spacing around its centre; a ray's
// integral is the sum over the voxels it crosses of (path length in the voxel) x (voxel value). Near-axis rays (AP,
// lateral) cross their dominant axis in runs: every voxel of a run but the first has the same path length, so a run
// is a strided sum of voxel values (about half the instructions per DRR of single-boundary stepping on the head CT).

#include <Eigen/Core>
#include <memory>

#include "Drr/IndexSpaceRayCaster.h"

namespace fct {

/// Exact voxel-traversal DRR renderer.
class SiddonRayCaster final : public IndexSpaceRayCaster<SiddonRayCaster> {
 public:
  /// A renderer of `volume` (must not be null).
  explicit SiddonRayCaster(std::shared_ptr<const DrrVolume> volume);

  std::string_view methodName() const override { return "siddon"; }

 private:
  friend class IndexSpaceRayCaster<SiddonRayCaster>;
  /// Integral along the index-space segment a_ijk -> b_ijk whose physical length is length_mm.
  double integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk, double length_mm) const;
};

}  // namespace fct
