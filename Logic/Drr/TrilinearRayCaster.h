#pragma once
// TrilinearRayCaster: DRRs by sampling the volume with trilinear interpolation at a fixed step along each ray
// (midpoint rule over the part of the ray where interpolated values can be non-zero: the volume's content box grown
// by half a voxel; the step is shortened so that a whole number of steps covers that part exactly). Beyond the
// outermost voxel centres the edge voxels' values extend to the box faces, so a voxel contributes over the same box
// as in SiddonRayCaster.

#include <Eigen/Core>
#include <memory>

#include "Drr/IndexSpaceRayCaster.h"

namespace fct {

/// Trilinear-sampling DRR renderer.
class TrilinearRayCaster final : public IndexSpaceRayCaster<TrilinearRayCaster> {
 public:
  /// A renderer of `volume` (must not be null) sampling every step_mm along each ray; step_mm <= 0 or non-finite
  /// selects defaultStep_mm(volume).
  TrilinearRayCaster(std::shared_ptr<const DrrVolume> volume, double step_mm = 0.0);

  /// The default sampling step in mm: half the smallest voxel spacing.
  static double defaultStep_mm(const DrrVolume& volume);

  std::string_view methodName() const override { return "raycast"; }
  /// The sampling step in mm actually used (an upper bound: each ray's step divides its in-volume length evenly).
  double step_mm() const { return m_step_mm; }

 private:
  friend class IndexSpaceRayCaster<TrilinearRayCaster>;
  /// Integral along the index-space segment a_ijk -> b_ijk whose physical length is length_mm.
  double integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk, double length_mm) const;

  double m_step_mm = 1.0;
  /// The part of the index box where a trilinear sample can be non-zero: the content box grown by half a voxel
  /// (interpolation reaches one voxel beyond the outermost non-zero voxel centres), within the volume's box.
  Eigen::Vector3d m_clipMin_ijk = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_clipMax_ijk = Eigen::Vector3d::Zero();
};

}  // namespace fct
