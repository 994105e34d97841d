#pragma once
// ItkTransformFile: the bone pose as an ITK text transform (.tfm) that 3D Slicer opens.
// ITK files hold the resampling transform (fixed -> moving) in LPS, and Slicer loads a linear one as the node's
// "transform from parent". So for a transform that moves the CT into the world when applied to it in Slicer
// (transform to parent = T_world_from_ct), the file holds the inverse, T_ct_from_world, in LPS mm:
//   #Insight Transform File V1.0
//   #Transform 0
//   Transform: AffineTransform_double_3_3
//   Parameters: R00 R01 R02 R10 R11 R12 R20 R21 R22 tx ty tz     (row-major rotation, then translation)
//   FixedParameters: 0 0 0                                        (centre of rotation)

#include <Eigen/Geometry>
#include <filesystem>

#include "Base/Result.h"

namespace fct {

/// Reads and writes ITK text transform files.
class ItkTransformFile {
 public:
  /// Writes T_world_from_ct (LPS mm) atomically as an AffineTransform_double_3_3 holding its inverse (see above).
  /// Fails if it is not a finite rigid transform or the path is unwritable.
  static Status write(const Eigen::Isometry3d& T_world_from_ct, const std::filesystem::path& path);

  /// Reads a single affine/matrix-offset transform (any centre of rotation) and returns T_world_from_ct, the
  /// inverse of the stored transform. Fails naming the file on a missing header or line, a wrong parameter count,
  /// a composite or non-linear transform, NaN, or a transform that is not rigid.
  static Result<Eigen::Isometry3d> read(const std::filesystem::path& path);
};

}  // namespace fct
