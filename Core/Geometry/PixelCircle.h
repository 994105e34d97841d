#pragma once
// PixelCircle: a circle in detector pixel coordinates (col,row), pixel (0,0) = centre of the top-left pixel.
// Used for the circular field of view and for calibration-grid spheres.

#include <Eigen/Core>

namespace fct {

/// A circle on the detector, in pixels of one image (or pyramid level).
struct PixelCircle {
  Eigen::Vector2d centre_px{0.0, 0.0};  ///< (col,row) of the centre
  double radius_px = 0.0;              ///< radius in pixels

  /// True when pixel (col,row) lies inside or on the circle.
  bool contains(double col, double row) const {
    const double dc = col - centre_px.x();
    const double dr = row - centre_px.y();
    return dc * dc + dr * dr <= radius_px * radius_px;
  }
};

}  // namespace fct
