#pragma once
// LandmarkTriangulator: the world position of a landmark clicked in two or more calibrated views. A linear least-
// squares estimate (the point closest to all back-projected rays) is refined by Gauss–Newton on the reprojection
// error in pixels.

#include <Eigen/Core>

#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"

namespace fct {

/// One click of a landmark: the view's name, its camera, and the clicked pixel (col,row).
struct LandmarkClick {
  std::string view;
  Camera camera;
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();
};

/// Triangulates named landmarks from their clicks.
class LandmarkTriangulator {
 public:
  /// Smallest angle between two views' rays for a usable triangulation, in degrees.
  static constexpr double kMinRayAngle_deg = 2.0;

  /// World point (LPS mm) seen at the clicks. Fails (naming `name` and the views) with fewer than 2 clicks, a
  /// non-finite click, rays less than kMinRayAngle_deg apart, or a point at or behind a view's X-ray source.
  static Result<Eigen::Vector3d> triangulate(const std::string& name, const std::vector<LandmarkClick>& clicks);

  /// Pixel (col,row) of world point p_world_mm in `camera`, and optionally d(uv_px)/d(p_world_mm) in px/mm.
  static Eigen::Vector2d projectWithJacobian(const Camera& camera, const Eigen::Vector3d& p_world_mm,
                                             Eigen::Matrix<double, 2, 3>* J_px_per_mm);
};

}  // namespace fct
