#include "Simulation/IntensifierDistortion.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace fct {

namespace {

/// image sampled at (mapCol, mapRow) per pixel, bilinear, 0 outside.
Result<FloatImage> remap(const FloatImage& image, const cv::Mat& mapCol, const cv::Mat& mapRow) {
  try {
    const cv::Mat source(image.rows, image.cols, CV_32F, const_cast<float*>(image.pixels.data()));
    FloatImage out = FloatImage::filled(mapCol.cols, mapCol.rows);
    cv::Mat target(out.rows, out.cols, CV_32F, out.pixels.data());
    cv::remap(source, target, mapCol, mapRow, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0.0));
    return out;
  } catch (const cv::Exception& e) {
    return fail(fmt::format("image remapping failed: {}", e.what()));
  }
}

}  // namespace

Result<IntensifierDistortion> IntensifierDistortion::create(int cols, int rows, double pincushion,
                                                            double sDistortion_deg) {
  if (cols <= 0 || rows <= 0) return fail(fmt::format("detector size must be positive, got {}x{}", cols, rows));
  if (!(std::abs(pincushion) <= 0.1)) {
    return fail(fmt::format("pincushion coefficient must be within -0.1..0.1, got {}", pincushion));
  }
  if (!(std::abs(sDistortion_deg) <= 10.0)) {
    return fail(fmt::format("S-distortion must be within -10..10 degrees, got {}", sDistortion_deg));
  }
  IntensifierDistortion d;
  d.m_cols = cols;
  d.m_rows = rows;
  d.m_centre_px = Eigen::Vector2d(0.5 * (cols - 1), 0.5 * (rows - 1));
  d.m_radius_px = 0.5 * std::min(cols, rows);
  d.m_pincushion = pincushion;
  d.m_sDistortion_rad = sDistortion_deg * M_PI / 180.0;
  return d;
}

Eigen::Vector2d IntensifierDistortion::distort(const Eigen::Vector2d& uv_ideal_px) const {
  const Eigen::Vector2d v = uv_ideal_px - m_centre_px;
  const double rho2 = v.squaredNorm() / (m_radius_px * m_radius_px);
  const double phi = m_sDistortion_rad * rho2;
  const double c = std::cos(phi), s = std::sin(phi), scale = 1.0 + m_pincushion * rho2;
  return m_centre_px + scale * Eigen::Vector2d(c * v.x() - s * v.y(), s * v.x() + c * v.y());
}

Eigen::Vector2d IntensifierDistortion::undistort(const Eigen::Vector2d& uv_observed_px) const {
  Eigen::Vector2d u = uv_observed_px;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::Vector2d residual = distort(u) - uv_observed_px;
    if (residual.norm() < 1e-9) break;
    // Jacobian by central differences (the map is smooth; 1e-3 px steps are exact to ~1e-9).
    constexpr double h = 1e-3;
    Eigen::Matrix2d J;
    J.col(0) = (distort(u + Eigen::Vector2d(h, 0)) - distort(u - Eigen::Vector2d(h, 0))) / (2 * h);
    J.col(1) = (distort(u + Eigen::Vector2d(0, h)) - distort(u - Eigen::Vector2d(0, h))) / (2 * h);
    u -= J.inverse() * residual;
  }
  return u;
}

Result<FloatImage> IntensifierDistortion::warp(const FloatImage& ideal) const {
  if (ideal.cols != m_cols || ideal.rows != m_rows || ideal.pixels.size() != std::size_t(m_cols) * m_rows) {
    return fail(fmt::format("image is {}x{} but the distortion is for a {}x{} detector", ideal.cols, ideal.rows,
                            m_cols, m_rows));
  }
  cv::Mat mapCol(m_rows, m_cols, CV_32F), mapRow(m_rows, m_cols, CV_32F);
  tbb::parallel_for(0, m_rows, [&](int row) {
    for (int col = 0; col < m_cols; ++col) {
      const Eigen::Vector2d u = undistort(Eigen::Vector2d(col, row));
      mapCol.at<float>(row, col) = static_cast<float>(u.x());
      mapRow.at<float>(row, col) = static_cast<float>(u.y());
    }
  });
  return remap(ideal, mapCol, mapRow);
}

DisplacementField IntensifierDistortion::field() const {
  DisplacementField f{FloatImage::filled(m_cols, m_rows), FloatImage::filled(m_cols, m_rows)};
  tbb::parallel_for(0, m_rows, [&](int row) {
    for (int col = 0; col < m_cols; ++col) {
      const Eigen::Vector2d d = distort(Eigen::Vector2d(col, row));
      f.dcol_px.at(col, row) = static_cast<float>(d.x() - col);
      f.drow_px.at(col, row) = static_cast<float>(d.y() - row);
    }
  });
  return f;
}

Result<FloatImage> IntensifierDistortion::dewarp(const FloatImage& observed, const DisplacementField& field) {
  const FloatImage& dc = field.dcol_px;
  const FloatImage& dr = field.drow_px;
  if (observed.empty() || observed.pixels.size() != std::size_t(observed.cols) * observed.rows) {
    return fail("cannot dewarp an empty or inconsistent image");
  }
  if (dc.cols != observed.cols || dc.rows != observed.rows || dr.cols != observed.cols || dr.rows != observed.rows ||
      dc.pixels.size() != observed.pixels.size() || dr.pixels.size() != observed.pixels.size()) {
    return fail(fmt::format("displacement field ({}x{} and {}x{}) does not match the {}x{} image", dc.cols, dc.rows,
                            dr.cols, dr.rows, observed.cols, observed.rows));
  }
  cv::Mat mapCol(observed.rows, observed.cols, CV_32F), mapRow(observed.rows, observed.cols, CV_32F);
  for (int row = 0; row < observed.rows; ++row) {
    for (int col = 0; col < observed.cols; ++col) {
      mapCol.at<float>(row, col) = static_cast<float>(col) + dc.at(col, row);
      mapRow.at<float>(row, col) = static_cast<float>(row) + dr.at(col, row);
    }
  }
  return remap(observed, mapCol, mapRow);
}

}  // namespace fct
