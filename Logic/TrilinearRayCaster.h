#pragma once
// TrilinearRayCaster: DRRs by sampling the volume with trilinear interpolation at a fixed step along each ray
// (midpoint rule over the part of the ray inside the volume's voxel boxes; the step is shortened so that a whole
// number of steps covers that part exactly). Beyond the outermost voxel centres the edge voxels' values extend
// to the box faces, so a voxel contributes over the same box as in SiddonRayCaster.

#include <Eigen/Core>
#include <memory>

#include "DrrRenderer.h"

namespace fct {

/// Trilinear-sampling DRR renderer.
class TrilinearRayCaster final : public DrrRenderer {
 public:
  /// A renderer of `volume` (must not be null) sampling every step_mm along each ray; step_mm <= 0 or non-finite
  /// selects defaultStep_mm(volume).
  TrilinearRayCaster(std::shared_ptr<const DrrVolume> volume, double step_mm = 0.0);

  /// The default sampling step in mm: half the smallest voxel spacing.
  static double defaultStep_mm(const DrrVolume& volume);

  std::string_view methodName() const override { return "raycast"; }
  /// The sampling step in mm actually used (an upper bound: each ray's step divides its in-volume length evenly).
  double step_mm() const { return m_step_mm; }

  /// Sampled line integral of the volume's values along the segment from_ct_mm -> to_ct_mm (CT frame, LPS mm):
  /// dimensionless for attenuation values, value·mm for raw values; 0 if the segment misses the volume.
  double integrate(const Eigen::Vector3d& from_ct_mm, const Eigen::Vector3d& to_ct_mm) const;

 protected:
  void integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct, const std::int32_t* pixels,
                       std::size_t count, float* values) const override;

 private:
  /// Integral along the index-space segment a_ijk -> b_ijk whose physical length is length_mm.
  double integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk, double length_mm) const;

  double m_step_mm = 1.0;
};

}  // namespace fct
