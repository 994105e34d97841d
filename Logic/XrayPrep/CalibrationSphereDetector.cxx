#include "XrayPrep/CalibrationSphereDetector.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace fct {
namespace {

/// Mean of the image over pixels whose centre lies at a distance in [inner, outer) from `centre`.
double ringMean(const FloatImage& image, const Eigen::Vector2d& centre, double inner, double outer) {
  const int row0 = std::max(0, static_cast<int>(std::floor(centre.y() - outer)));
  const int row1 = std::min(image.rows - 1, static_cast<int>(std::ceil(centre.y() + outer)));
  const int col0 = std::max(0, static_cast<int>(std::floor(centre.x() - outer)));
  const int col1 = std::min(image.cols - 1, static_cast<int>(std::ceil(centre.x() + outer)));
  double sum = 0.0;
  int count = 0;
  for (int row = row0; row <= row1; ++row) {
    for (int col = col0; col <= col1; ++col) {
      const double d = std::hypot(col - centre.x(), row - centre.y());
      if (d >= inner && d < outer) {
        sum += image.at(col, row);
        ++count;
      }
    }
  }
  return count ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

Result<std::vector<PixelCircle>> CalibrationSphereDetector::detect(const FloatImage& image,
                                                                   const ValidMask& mask) const {
  const CalibrationSphereOptions& o = m_options;
  if (!(o.minRadius_px >= 1.0 && o.maxRadius_px >= o.minRadius_px) || !(o.minContrast >= 0.0) ||
      !(o.houghThreshold > 0.0)) {
    return fail(fmt::format("sphere detection options out of range: radii {}..{} px (1 <= min <= max), contrast {} "
                            "(>= 0), Hough threshold {} (> 0)",
                            o.minRadius_px, o.maxRadius_px, o.minContrast, o.houghThreshold));
  }
  if (mask.cols != image.cols || mask.rows != image.rows || mask.valid.size() != image.pixels.size() ||
      image.pixels.empty()) {
    return fail(fmt::format("mask is {}x{} but the X-ray is {}x{}; build the mask for this image", mask.cols,
                            mask.rows, image.cols, image.rows));
  }
  float lo = std::numeric_limits<float>::max();
  float hi = std::numeric_limits<float>::lowest();
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    if (!mask.valid[i]) continue;
    lo = std::min(lo, image.pixels[i]);
    hi = std::max(hi, image.pixels[i]);
  }
  std::vector<PixelCircle> spheres;
  if (!(hi > lo)) return spheres;  // no valid pixel, or a flat image: no disc can stand out

  try {
    cv::Mat bytes(image.rows, image.cols, CV_8U);
    const float scale = 255.0f / (hi - lo);
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
      bytes.data[i] = cv::saturate_cast<std::uint8_t>((image.pixels[i] - lo) * scale);
    }
    cv::GaussianBlur(bytes, bytes, cv::Size(0, 0), 1.0);
    std::vector<cv::Vec3f> candidates;
    cv::HoughCircles(bytes, candidates, cv::HOUGH_GRADIENT, 1.0, 2.0 * o.minRadius_px, 100.0, o.houghThreshold,
                     static_cast<int>(std::floor(o.minRadius_px)), static_cast<int>(std::ceil(o.maxRadius_px)));
    const double contrast = o.minContrast * (hi - lo);
    for (const cv::Vec3f& c : candidates) {
      const PixelCircle circle{Eigen::Vector2d(c[0], c[1]), c[2]};
      const int col = static_cast<int>(std::lround(c[0]));
      const int row = static_cast<int>(std::lround(c[1]));
      if (col < 0 || row < 0 || col >= image.cols || row >= image.rows || !mask.isValid(col, row)) continue;
      const double inside = ringMean(image, circle.centre_px, 0.0, 0.7 * circle.radius_px);
      const double around = ringMean(image, circle.centre_px, 1.3 * circle.radius_px, 1.8 * circle.radius_px);
      if (inside < around - contrast) spheres.push_back(circle);
    }
  } catch (const cv::Exception& e) {
    return fail(fmt::format("calibration sphere detection failed in OpenCV: {}", e.what()));
  }
  return spheres;
}

}  // namespace fct
