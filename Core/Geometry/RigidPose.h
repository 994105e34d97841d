#pragma once
// RigidPose: the bone pose T_world_from_ct and its 6-parameter form.
// Parameters p = (rx, ry, rz) in degrees and (tx, ty, tz) in mm, about a centre c_ct_mm given in the CT frame:
//   p_world = R(rx, ry, rz) * (p_ct - c_ct) + c_ct + t,   R = Rz(rz) * Ry(ry) * Rx(rx)  (rotations about world axes).
// So t is the world displacement of the centre, and the rotation turns the bone about its own centre.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "Base/Result.h"
#include "Geometry/PoseVector.h"

namespace fct {

/// Six pose parameters: rotations in degrees, translations in mm.
struct PoseParameters {
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();
  /// As a 6-vector (rx, ry, rz, tx, ty, tz).
  PoseVector asVector() const;
  /// From a 6-vector (rx, ry, rz, tx, ty, tz).
  static PoseParameters fromVector(const PoseVector& v);
};

/// Conversions between T_world_from_ct and PoseParameters about a centre in the CT frame.
class RigidPose {
 public:
  /// T_world_from_ct from parameters about centre c_ct_mm (see the file comment for the formula).
  static Eigen::Isometry3d toTransform(const PoseParameters& params, const Eigen::Vector3d& centre_ct_mm);
  /// Parameters about centre c_ct_mm of a rigid transform; fails if the 3x3 part is not a proper rotation.
  static Result<PoseParameters> fromTransform(const Eigen::Isometry3d& T_world_from_ct, const Eigen::Vector3d& centre_ct_mm);
  /// Checks that a 4x4 matrix is a finite rigid transform (rotation with det +1, last row 0 0 0 1) and returns it.
  static Result<Eigen::Isometry3d> validated(const Eigen::Matrix4d& matrix, const char* what = "transform");
};

}  // namespace fct
