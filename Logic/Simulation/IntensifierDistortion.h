#pragma once
// IntensifierDistortion: the geometric distortion of an image-intensifier C-arm. A point at ideal (pinhole-camera)
// pixel u appears at the observed pixel
//   d(u) = c + Rot(φ) · (u − c) · (1 + k ρ²),   ρ = |u − c| / R,   φ = s · ρ²
// with c the detector centre, R half the smaller detector side, k the pincushion coefficient (> 0: pincushion,
// < 0: barrel) and s the S-distortion angle in radians at ρ = 1 (the rotation of the electron image that grows with
// radius, as the Earth's magnetic field causes). The inverse d -> u has no closed form and is solved by Newton's
// method. A displacement field d(u) − u per ideal pixel is what a dewarp needs; it is saved with simulated cases.

#include <Eigen/Core>

#include "Base/Result.h"
#include "Image/FloatImage.h"

namespace fct {

/// Per ideal pixel u: the observed position d(u) = u + (dcol, drow), in pixels.
struct DisplacementField {
  FloatImage dcol_px;
  FloatImage drow_px;
};

/// Pincushion and S-distortion of an image intensifier.
class IntensifierDistortion {
 public:
  /// The distortion of a cols x rows detector. Fails on a non-positive size, |pincushion| > 0.1 or
  /// |sDistortion_deg| > 10 (where the map may stop being invertible), or non-finite values.
  static Result<IntensifierDistortion> create(int cols, int rows, double pincushion, double sDistortion_deg);

  /// Observed pixel (col,row) of the ideal pixel uv_ideal_px.
  Eigen::Vector2d distort(const Eigen::Vector2d& uv_ideal_px) const;
  /// Ideal pixel of the observed pixel uv_observed_px (Newton's method, to 1e-9 px).
  Eigen::Vector2d undistort(const Eigen::Vector2d& uv_observed_px) const;

  /// The observed image of an ideal image (bilinear; observed pixels whose ideal position is off the image are 0).
  /// Fails on an image of another size.
  Result<FloatImage> warp(const FloatImage& ideal) const;
  /// The displacement field of this distortion on its detector.
  DisplacementField field() const;

  /// The ideal image of an observed image, given the displacement field (e.g. read back from the saved NRRDs):
  /// ideal(u) = observed(u + field(u)), bilinear, 0 off the image. Fails on size mismatches or an empty image.
  static Result<FloatImage> dewarp(const FloatImage& observed, const DisplacementField& field);

 private:
  int m_cols = 0;
  int m_rows = 0;
  Eigen::Vector2d m_centre_px = Eigen::Vector2d::Zero();
  double m_radius_px = 1.0;
  double m_pincushion = 0.0;
  double m_sDistortion_rad = 0.0;
};

}  // namespace fct
