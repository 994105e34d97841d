#pragma once
// Landmarks: named 3D points in the CT frame and named 2D points per X-ray view.

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

namespace fct {

/// A named point in the CT's physical LPS frame, in mm.
struct CtLandmark {
  std::string name;
  Eigen::Vector3d p_ct_mm = Eigen::Vector3d::Zero();
};

/// A named point on one view's detector, in pixels (col,row).
struct ImageLandmark {
  std::string name;
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();
};

/// All landmarks of a case: CT points and, per view name, the clicked image points.
struct Landmarks {
  std::vector<CtLandmark> ct;
  std::map<std::string, std::vector<ImageLandmark>> imageByView;
};

}  // namespace fct
