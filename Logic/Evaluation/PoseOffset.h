#pragma once
// PoseOffset: moves a bone pose by a chosen or random offset, measured the way surgeons and the paper measure pose
// error: rotations about the bone's centre and the resulting mean bone-surface distance. Used to make start poses
// for known-truth cases (the CLI's `fluoroct pose`, tests, benchmarks and studies).

#include <Eigen/Geometry>
#include <cstdint>

#include "Base/Result.h"
#include "Geometry/RigidPose.h"
#include "Image/BoneSurface.h"

namespace fct {

/// Offsets of a bone pose T_world_from_ct about the bone centre.
class PoseOffset {
 public:
  /// T_reference moved by `offset`: rotation R(rx, ry, rz) (RigidPose's convention, world axes) about the bone
  /// centroid's world position, then translation t in world mm:
  /// p_world = R (T_reference p_ct - c_world) + c_world + t, with c_world = T_reference * centroid_ct_mm.
  static Eigen::Isometry3d apply(const BoneSurface& bone, const Eigen::Isometry3d& T_reference,
                                 const PoseParameters& offset);

  /// A random pose whose mean bone-surface distance from T_reference is distance_mm (within 1e-3 mm): a direction
  /// drawn uniformly on the 6-D sphere in scaled units (1 unit of rotation ~ 1 mm of surface motion at the bone's
  /// RMS radius) and scaled by bisection. Deterministic for a seed. Fails on a negative or non-finite distance or one
  /// above 500 mm.
  static Result<Eigen::Isometry3d> randomAtSurfaceDistance(const BoneSurface& bone, const Eigen::Isometry3d& T_reference,
                                                           double distance_mm, std::uint32_t seed);
};

}  // namespace fct
