#include "Geometry/DewarpField.h"

#include <fmt/core.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace fct {

namespace {

/// x^0..x^degree.
std::array<double, DewarpField::kMaxDegree + 1> powers(double x, int degree) {
  std::array<double, DewarpField::kMaxDegree + 1> p{};
  p[0] = 1.0;
  for (int k = 1; k <= degree; ++k) p[k] = p[k - 1] * x;
  return p;
}

}  // namespace

std::vector<std::array<int, 2>> DewarpField::terms(int degree) {
  std::vector<std::array<int, 2>> out;
  for (int total = kMinDegree; total <= degree; ++total) {
    for (int p = total; p >= 0; --p) out.push_back({p, total - p});
  }
  return out;
}

Result<DewarpField> DewarpField::create(int cols, int rows, int degree, const Eigen::VectorXd& colCoefficients_px,
                                        const Eigen::VectorXd& rowCoefficients_px) {
  if (cols <= 0 || rows <= 0) return fail(fmt::format("dewarp image size must be positive, got {}x{}", cols, rows));
  if (degree < kMinDegree || degree > kMaxDegree) {
    return fail(fmt::format("dewarp polynomial degree must be {}..{}, got {}", kMinDegree, kMaxDegree, degree));
  }
  DewarpField field;
  field.m_terms = terms(degree);
  const auto count = static_cast<Eigen::Index>(field.m_terms.size());
  if (colCoefficients_px.size() != count || rowCoefficients_px.size() != count) {
    return fail(fmt::format("a degree-{} dewarp polynomial has {} coefficients per axis, got {} and {}", degree, count,
                            colCoefficients_px.size(), rowCoefficients_px.size()));
  }
  if (!colCoefficients_px.allFinite() || !rowCoefficients_px.allFinite()) {
    return fail("dewarp coefficients must be finite numbers");
  }
  field.m_cols = cols;
  field.m_rows = rows;
  field.m_degree = degree;
  field.m_centre_px = Eigen::Vector2d(0.5 * (cols - 1), 0.5 * (rows - 1));
  field.m_radius_px = 0.5 * std::min(cols, rows);
  field.m_col_px = colCoefficients_px;
  field.m_row_px = rowCoefficients_px;
  return field;
}

Result<DewarpField> DewarpField::identity(int cols, int rows, int degree) {
  const auto count = static_cast<Eigen::Index>(terms(std::clamp(degree, kMinDegree, kMaxDegree)).size());
  return create(cols, rows, degree, Eigen::VectorXd::Zero(count), Eigen::VectorXd::Zero(count));
}

Eigen::VectorXd DewarpField::basis(const Eigen::Vector2d& uv_distorted_px) const {
  const Eigen::Vector2d xy = (uv_distorted_px - m_centre_px) / m_radius_px;
  const auto px = powers(xy.x(), m_degree), py = powers(xy.y(), m_degree);
  Eigen::VectorXd b(static_cast<Eigen::Index>(m_terms.size()));
  for (std::size_t t = 0; t < m_terms.size(); ++t) b[static_cast<Eigen::Index>(t)] = px[m_terms[t][0]] * py[m_terms[t][1]];
  return b;
}

Eigen::Vector2d DewarpField::ideal(const Eigen::Vector2d& uv_distorted_px) const {
  const Eigen::VectorXd b = basis(uv_distorted_px);
  return uv_distorted_px + m_radius_px * Eigen::Vector2d(m_col_px.dot(b), m_row_px.dot(b));
}

Eigen::Matrix2d DewarpField::jacobian(const Eigen::Vector2d& uv_distorted_px) const {
  const Eigen::Vector2d xy = (uv_distorted_px - m_centre_px) / m_radius_px;
  const auto px = powers(xy.x(), m_degree), py = powers(xy.y(), m_degree);
  // d/dd of R · c · x^p y^q = c · (p x^(p-1) y^q, q x^p y^(q-1)) since dx/dd = 1/R.
  Eigen::Matrix2d J = Eigen::Matrix2d::Identity();
  for (std::size_t t = 0; t < m_terms.size(); ++t) {
    const int p = m_terms[t][0], q = m_terms[t][1];
    const double dx = p > 0 ? p * px[p - 1] * py[q] : 0.0;
    const double dy = q > 0 ? q * px[p] * py[q - 1] : 0.0;
    const auto i = static_cast<Eigen::Index>(t);
    J(0, 0) += m_col_px[i] * dx;
    J(0, 1) += m_col_px[i] * dy;
    J(1, 0) += m_row_px[i] * dx;
    J(1, 1) += m_row_px[i] * dy;
  }
  return J;
}

std::optional<Eigen::Vector2d> DewarpField::distorted(const Eigen::Vector2d& uv_ideal_px) const {
  Eigen::Vector2d d = uv_ideal_px;
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Eigen::Vector2d residual = ideal(d) - uv_ideal_px;
    if (residual.norm() < 1e-6) return d;
    const Eigen::Matrix2d J = jacobian(d);
    if (!(std::abs(J.determinant()) > 1e-6)) return std::nullopt;
    d -= J.inverse() * residual;
    if (!d.allFinite()) return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace fct
