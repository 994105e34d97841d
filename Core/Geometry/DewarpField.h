#pragma once
// DewarpField: the geometric correction of an image-intensifier X-ray, a smooth map from distorted (stored image)
// pixels d to ideal (pinhole-camera) pixels u of a cols x rows detector:
//   u(d) = d + R · Σ_{2 <= p+q <= degree} (a_pq, b_pq) · x^p y^q,   (x, y) = (d − c) / R,
// c the detector centre ((cols − 1)/2, (rows − 1)/2) and R half the smaller detector side. The polynomial has no
// constant or linear term: the ideal pixel grid is the one that agrees with the stored image, position and
// Jacobian, at the detector centre, where an intensifier's distortion is smallest. The inverse u -> d (needed to
// resample an image onto the ideal grid) is solved by Newton's method.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "Base/Result.h"

namespace fct {

/// A polynomial map from distorted to ideal detector pixels.
class DewarpField {
 public:
  /// Lowest and highest supported polynomial degree.
  static constexpr int kMinDegree = 2;
  static constexpr int kMaxDegree = 9;

  /// The exponents (p, q) of x^p y^q in coefficient order (by total degree, then falling p) for `degree`.
  static std::vector<std::array<int, 2>> terms(int degree);

  /// The field of a cols x rows detector with the given coefficients (in terms(degree) order, px). Fails on a
  /// non-positive size, a degree outside kMinDegree..kMaxDegree, a coefficient count that is not the term count, or
  /// non-finite coefficients.
  static Result<DewarpField> create(int cols, int rows, int degree, const Eigen::VectorXd& colCoefficients_px,
                                    const Eigen::VectorXd& rowCoefficients_px);
  /// The identity field (all coefficients 0) of a cols x rows detector; fails as create().
  static Result<DewarpField> identity(int cols, int rows, int degree);

  /// The monomials x^p y^q of the distorted pixel uv_distorted_px, in terms() order (the fit's design row, / R px).
  Eigen::VectorXd basis(const Eigen::Vector2d& uv_distorted_px) const;
  /// Ideal pixel (col,row) of the distorted pixel uv_distorted_px.
  Eigen::Vector2d ideal(const Eigen::Vector2d& uv_distorted_px) const;
  /// Jacobian d(ideal)/d(distorted) at uv_distorted_px (dimensionless).
  Eigen::Matrix2d jacobian(const Eigen::Vector2d& uv_distorted_px) const;
  /// Distorted pixel whose ideal pixel is uv_ideal_px (Newton's method from uv_ideal_px, to 1e-6 px); nullopt when
  /// Newton does not converge or the Jacobian is singular there (far outside the calibrated field).
  std::optional<Eigen::Vector2d> distorted(const Eigen::Vector2d& uv_ideal_px) const;

  int cols() const { return m_cols; }
  int rows() const { return m_rows; }
  int degree() const { return m_degree; }
  /// The normalisation centre c and radius R (px).
  const Eigen::Vector2d& centre_px() const { return m_centre_px; }
  double radius_px() const { return m_radius_px; }
  /// Coefficients of the column and row corrections, px, in terms() order.
  const Eigen::VectorXd& colCoefficients_px() const { return m_col_px; }
  const Eigen::VectorXd& rowCoefficients_px() const { return m_row_px; }

 private:
  int m_cols = 0;
  int m_rows = 0;
  int m_degree = kMinDegree;
  std::vector<std::array<int, 2>> m_terms;
  Eigen::Vector2d m_centre_px = Eigen::Vector2d::Zero();
  double m_radius_px = 1.0;
  Eigen::VectorXd m_col_px;
  Eigen::VectorXd m_row_px;
};

}  // namespace fct
