#include "XrayPrep/FieldOfViewDetector.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace fct {
namespace {

/// Background pixels: at or below `threshold` and 4-connected to the image border through such pixels.
std::vector<std::uint8_t> borderConnectedBackground(const FloatImage& image, float threshold) {
  const int cols = image.cols;
  const int rows = image.rows;
  std::vector<std::uint8_t> background(image.pixels.size(), 0);
  std::vector<std::int32_t> stack;
  auto push = [&](int col, int row) {
    const std::size_t i = static_cast<std::size_t>(row) * cols + col;
    if (!background[i] && image.pixels[i] <= threshold) {
      background[i] = 1;
      stack.push_back(static_cast<std::int32_t>(i));
    }
  };
  for (int col = 0; col < cols; ++col) {
    push(col, 0);
    push(col, rows - 1);
  }
  for (int row = 0; row < rows; ++row) {
    push(0, row);
    push(cols - 1, row);
  }
  while (!stack.empty()) {
    const std::int32_t i = stack.back();
    stack.pop_back();
    const int col = i % cols;
    const int row = i / cols;
    if (col > 0) push(col - 1, row);
    if (col + 1 < cols) push(col + 1, row);
    if (row > 0) push(col, row - 1);
    if (row + 1 < rows) push(col, row + 1);
  }
  return background;
}

/// Least-squares circle through points (Kasa: x^2 + y^2 + D x + E y + F = 0); nullopt if degenerate.
std::optional<PixelCircle> fitCircle(const std::vector<Eigen::Vector2d>& points) {
  if (points.size() < 3) return std::nullopt;
  Eigen::MatrixXd A(points.size(), 3);
  Eigen::VectorXd b(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    A(i, 0) = points[i].x();
    A(i, 1) = points[i].y();
    A(i, 2) = 1.0;
    b(i) = -points[i].squaredNorm();
  }
  const Eigen::Vector3d def = A.colPivHouseholderQr().solve(b);
  const Eigen::Vector2d centre(-0.5 * def(0), -0.5 * def(1));
  const double r2 = centre.squaredNorm() - def(2);
  if (!(r2 > 0.0) || !std::isfinite(r2)) return std::nullopt;
  return PixelCircle{centre, std::sqrt(r2)};
}

double medianOf(std::vector<double> values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

/// Fits a circle and refits twice without outliers; returns the circle and the median residual in px.
std::optional<std::pair<PixelCircle, double>> robustCircle(std::vector<Eigen::Vector2d> points) {
  std::optional<PixelCircle> circle;
  double medianResidual = 0.0;
  for (int pass = 0; pass < 3; ++pass) {
    circle = fitCircle(points);
    if (!circle) return std::nullopt;
    std::vector<double> residuals(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      residuals[i] = std::abs((points[i] - circle->centre_px).norm() - circle->radius_px);
    }
    medianResidual = medianOf(residuals);
    const double cutoff = 3.0 * medianResidual + 1.0;
    std::vector<Eigen::Vector2d> inliers;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (residuals[i] <= cutoff) inliers.push_back(points[i]);
    }
    points.swap(inliers);
  }
  return std::make_pair(*circle, medianResidual);
}

}  // namespace

Result<FieldOfView> FieldOfViewDetector::detect(const FloatImage& image) const {
  const FieldOfViewOptions& o = m_options;
  if (image.cols < 3 || image.rows < 3 || image.pixels.size() != static_cast<std::size_t>(image.cols) * image.rows) {
    return fail(fmt::format("cannot detect a field of view in a {}x{} image with {} pixels; need at least 3x3",
                            image.cols, image.rows, image.pixels.size()));
  }
  if (!(o.backgroundLevel > 0.0 && o.backgroundLevel < 1.0) || o.inset_px < 0 || !(o.maxCircleResidual_px > 0.0) ||
      o.edgeWidth_px < 1 || !(o.minEdgeStep >= 1.0)) {
    return fail(fmt::format("field-of-view options out of range: backgroundLevel {} (0..1), inset {} px (>= 0), "
                            "max circle residual {} px (> 0), edge width {} px (>= 1), min edge step {} (>= 1)",
                            o.backgroundLevel, o.inset_px, o.maxCircleResidual_px, o.edgeWidth_px, o.minEdgeStep));
  }
  if (!std::all_of(image.pixels.begin(), image.pixels.end(), [](float v) { return std::isfinite(v); })) {
    return fail("X-ray has non-finite pixel values (NaN or infinity); cannot detect its field of view");
  }

  std::vector<float> sorted = image.pixels;
  const auto p90 = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() * 9 / 10);
  std::nth_element(sorted.begin(), p90, sorted.end());
  const float bright = *p90;
  const float minimum = *std::min_element(image.pixels.begin(), image.pixels.end());
  const auto threshold = static_cast<float>(minimum + o.backgroundLevel * (bright - minimum));

  if (bright <= minimum) {
    return fail(fmt::format("X-ray is at its minimum value {} over at least 90 % of its pixels; no field of view "
                            "found (is the image blank?)",
                            minimum));
  }
  const int cols = image.cols;
  const int rows = image.rows;
  FieldOfView result;
  result.mask = ValidMask::allValid(cols, rows);
  const std::vector<std::uint8_t> background = borderConnectedBackground(image, threshold);
  const std::size_t backgroundCount = static_cast<std::size_t>(std::count(background.begin(), background.end(), 1));
  result.backgroundFraction = static_cast<double>(backgroundCount) / static_cast<double>(background.size());
  if (result.backgroundFraction < o.minBackgroundFraction) return result;

  // A collimator or image-intensifier edge is a step: the field pixels next to the background are well above the
  // threshold. Anatomy reaching the border of a collimator-free image (e.g. a simulated lateral pelvis) only fades
  // through the threshold: then the dark region is not background and the whole image is field.
  cv::Mat backgroundImage(rows, cols, CV_8U);
  std::copy(background.begin(), background.end(), backgroundImage.data);
  cv::Mat near;
  const int band = 2 * o.edgeWidth_px + 1;
  cv::dilate(backgroundImage, near, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(band, band)));
  std::vector<double> edgeLevels;
  for (std::size_t i = 0; i < background.size(); ++i) {
    if (near.data[i] && !background[i]) edgeLevels.push_back((image.pixels[i] - minimum) / (threshold - minimum));
  }
  result.edgeStep = edgeLevels.empty() ? 0.0 : medianOf(std::move(edgeLevels));
  if (result.edgeStep < o.minEdgeStep) {
    result.backgroundFraction = 0.0;
    return result;
  }

  std::vector<Eigen::Vector2d> boundary;
  for (int row = 1; row + 1 < rows; ++row) {
    for (int col = 1; col + 1 < cols; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * cols + col;
      if (background[i]) continue;
      if (background[i - 1] || background[i + 1] || background[i - cols] || background[i + cols]) {
        boundary.emplace_back(col, row);
      }
    }
  }
  const auto fit = robustCircle(boundary);
  if (fit && fit->second <= o.maxCircleResidual_px && fit->first.radius_px > o.inset_px) {
    result.circle = fit->first;
    PixelCircle usable = fit->first;
    usable.radius_px -= o.inset_px;
    result.mask.excludeOutside(usable);
    return result;
  }

  // Not circular: the field region, eroded by the inset.
  cv::Mat field(rows, cols, CV_8U);
  for (std::size_t i = 0; i < background.size(); ++i) field.data[i] = background[i] ? 0 : 1;
  if (o.inset_px > 0) {
    const int k = 2 * o.inset_px + 1;
    cv::erode(field, field, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)), cv::Point(-1, -1), 1,
              cv::BORDER_CONSTANT, cv::Scalar(1));
  }
  std::copy(field.data, field.data + result.mask.valid.size(), result.mask.valid.begin());
  return result;
}

}  // namespace fct
