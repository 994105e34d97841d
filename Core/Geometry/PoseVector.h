#pragma once
// PoseVector: the six pose parameters as one vector, (rx, ry, rz) in degrees then (tx, ty, tz) in mm, the form in
// which the pose search works (PoseParameters::asVector(); see RigidPose.h for what they mean).

#include <Eigen/Core>

namespace fct {

/// Six pose parameters (rx, ry, rz) in degrees and (tx, ty, tz) in mm, as in PoseParameters::asVector().
using PoseVector = Eigen::Matrix<double, 6, 1>;

}  // namespace fct
