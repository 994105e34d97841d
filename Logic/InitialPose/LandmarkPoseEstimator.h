#pragma once
// LandmarkPoseEstimator: an initial bone pose T_world_from_ct from landmarks, named CT points (LPS mm) paired by name
// with points clicked on one or more calibrated views (pixels).
//
// Two methods:
// - Reprojection: one joint Levenberg–Marquardt minimization of the reprojection error (pixels) over every click in
//   every view, started from the best of: a PnP solution (OpenCV SQPnP) in each view with >= 4 clicks, and the
//   triangulation estimate when >= 3 landmarks are clicked in two views. With one view this is PnP + refinement.
// - Triangulation: each landmark clicked in >= 2 views is triangulated (LandmarkTriangulator), then the CT points are
//   fitted rigidly to the triangulated world points by least squares (Umeyama, no scale).
// Both need >= 4 landmarks that are not collinear, each named both in the CT and in at least one view.

#include <Eigen/Geometry>

#include <map>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Geometry/Landmarks.h"

namespace fct {

/// How well the estimated pose explains one landmark.
struct LandmarkResidual {
  std::string name;
  std::map<std::string, double> reprojection_px;  ///< per view where clicked: |project(T p_ct) - click| in pixels
  double distance_mm = 0.0;     ///< |T p_ct - triangulated point| in mm; NaN if clicked in fewer than 2 views
};

/// An initial pose and its residuals.
struct LandmarkPoseEstimate {
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  std::string method;                        ///< "pnp" (one view), "joint-reprojection" or "triangulation"
  std::vector<LandmarkResidual> residuals;   ///< one per used landmark, in the order of Landmarks::ct
  double rmsReprojection_px = 0.0;           ///< RMS over every click in every view
  double rms3d_mm = 0.0;                     ///< RMS of distance_mm over landmarks clicked in >= 2 views; NaN if none
};

/// Landmark-based initial pose estimation.
class LandmarkPoseEstimator {
 public:
  /// Pose minimizing the reprojection error of all clicks in all views (see the file comment). `cameras` maps view
  /// names to cameras. Fails, naming what is wrong, on: a view name without a camera, a duplicate or non-finite
  /// landmark, a landmark named in only one place (CT without clicks, or clicks without a CT point), fewer than 4
  /// landmarks, collinear CT landmarks, no usable start, or a solution behind an X-ray source.
  static Result<LandmarkPoseEstimate> fromReprojection(const Landmarks& landmarks,
                                                       const std::map<std::string, Camera>& cameras);

  /// Pose from triangulated landmarks fitted rigidly to the CT points (see the file comment). Fails as
  /// fromReprojection(), and also when a landmark is clicked in fewer than 2 views or its rays are nearly parallel.
  static Result<LandmarkPoseEstimate> fromTriangulation(const Landmarks& landmarks,
                                                        const std::map<std::string, Camera>& cameras);
};

}  // namespace fct
