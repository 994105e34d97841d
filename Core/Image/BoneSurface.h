#pragma once
// BoneSurface: points on the bone's surface in a CT, for pose error measures (mean surface distance, sTRE),
// the pose-parameter centre and scale, and contour overlays. The surface is the set of boundary voxels of
// {HU >= threshold}: voxels at or above the threshold with at least one 6-neighbour below it (or outside the volume).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// Bone surface points of a CT (CT frame = the CT's LPS mm), their centroid and RMS radius.
class BoneSurface {
 public:
  /// Default bone threshold in HU: above soft tissue and contrast-free vessels, below cancellous bone's usual range.
  static constexpr double kDefaultThreshold_hu = 250.0;
  /// Default maximum number of points kept.
  static constexpr std::size_t kDefaultMaxPoints = 20000;

  /// Extracts the boundary-voxel centres of {value >= threshold_hu} in CT LPS mm, then keeps at most maxPoints of
  /// them, evenly spread over the scan-ordered list (deterministic). Fails on an empty volume, a non-finite
  /// threshold, maxPoints == 0, or when no voxel reaches the threshold (the message gives the CT's value range).
  static Result<BoneSurface> extract(const Volume& ct, double threshold_hu = kDefaultThreshold_hu,
                                     std::size_t maxPoints = kDefaultMaxPoints);

  /// The kept surface points in CT LPS mm (never empty).
  const std::vector<Eigen::Vector3d>& points_ct_mm() const { return m_points_ct_mm; }
  /// Mean of the kept points, CT LPS mm.
  Eigen::Vector3d centroid_ct_mm() const { return m_centroid_ct_mm; }
  /// RMS distance of the kept points from the centroid, mm.
  double radius_mm() const { return m_radius_mm; }
  /// The threshold used, HU.
  double threshold_hu() const { return m_threshold_hu; }
  /// Boundary voxels found before subsampling.
  std::size_t boundaryVoxelCount() const { return m_boundaryVoxelCount; }

  /// Mean over the points of |T_a p - T_b p| in mm (world frame of the poses): the mean surface distance between
  /// two bone poses T_world_from_ct. 0 for identical poses.
  double meanDistance_mm(const Eigen::Isometry3d& T_world_from_ct_a, const Eigen::Isometry3d& T_world_from_ct_b) const;
  /// Maximum over the points of |T_a p - T_b p| in mm.
  double maxDistance_mm(const Eigen::Isometry3d& T_world_from_ct_a, const Eigen::Isometry3d& T_world_from_ct_b) const;

 private:
  BoneSurface() = default;

  std::vector<Eigen::Vector3d> m_points_ct_mm;
  Eigen::Vector3d m_centroid_ct_mm = Eigen::Vector3d::Zero();
  double m_radius_mm = 0.0;
  double m_threshold_hu = kDefaultThreshold_hu;
  std::size_t m_boundaryVoxelCount = 0;
};

}  // namespace fct
