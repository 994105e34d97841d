#include "XrayPrep/GridBeadDetector.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace fct {

namespace {

/// Darkness-weighted centroid of `darkness` over the disc of `radius` about `centre`, after subtracting the median
/// darkness of the ring radius+1 .. radius+3; the centre unchanged when the disc has no weight.
Eigen::Vector2d weightedCentroid(const cv::Mat& darkness, const Eigen::Vector2d& centre, double radius) {
  const double outer = radius + 3.0;
  const int row0 = std::max(0, static_cast<int>(std::floor(centre.y() - outer)));
  const int row1 = std::min(darkness.rows - 1, static_cast<int>(std::ceil(centre.y() + outer)));
  const int col0 = std::max(0, static_cast<int>(std::floor(centre.x() - outer)));
  const int col1 = std::min(darkness.cols - 1, static_cast<int>(std::ceil(centre.x() + outer)));
  std::vector<float> ring;
  for (int row = row0; row <= row1; ++row) {
    for (int col = col0; col <= col1; ++col) {
      const double d = std::hypot(col - centre.x(), row - centre.y());
      if (d > radius + 1.0 && d <= outer) ring.push_back(darkness.at<float>(row, col));
    }
  }
  float level = 0.0f;
  if (!ring.empty()) {
    std::nth_element(ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(ring.size() / 2), ring.end());
    level = ring[ring.size() / 2];
  }
  double sum = 0.0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (int row = row0; row <= row1; ++row) {
    for (int col = col0; col <= col1; ++col) {
      if (std::hypot(col - centre.x(), row - centre.y()) > radius) continue;
      const double w = std::max(0.0, double(darkness.at<float>(row, col)) - level);
      sum += w;
      weighted += w * Eigen::Vector2d(col, row);
    }
  }
  return sum > 0.0 ? Eigen::Vector2d(weighted / sum) : centre;
}

}  // namespace

Result<std::vector<PixelCircle>> GridBeadDetector::detect(const FloatImage& image, const ValidMask& mask) const {
  const GridBeadOptions& o = m_options;
  if (!(o.minRadius_px > 0.0 && o.maxRadius_px >= o.minRadius_px && o.maxRadius_px <= 100.0) ||
      !(o.minContrast > 0.0 && o.minContrast < 1.0)) {
    return fail(fmt::format("bead detection options out of range: radii {}..{} px (0 < min <= max <= 100), contrast "
                            "{} (0..1)",
                            o.minRadius_px, o.maxRadius_px, o.minContrast));
  }
  if (image.empty() || image.pixels.size() != std::size_t(image.cols) * image.rows || mask.cols != image.cols ||
      mask.rows != image.rows || mask.valid.size() != image.pixels.size()) {
    return fail(fmt::format("mask is {}x{} but the grid image is {}x{}; build the mask for this image", mask.cols,
                            mask.rows, image.cols, image.rows));
  }
  std::vector<PixelCircle> beads;
  try {
    const cv::Mat raw(image.rows, image.cols, CV_32F, const_cast<float*>(image.pixels.data()));
    cv::Mat smooth;
    cv::GaussianBlur(raw, smooth, cv::Size(0, 0), 1.0, 1.0, cv::BORDER_REPLICATE);
    const int kernel = 2 * static_cast<int>(std::ceil(1.5 * o.maxRadius_px + 2.0)) + 1;
    cv::Mat background;
    cv::morphologyEx(smooth, background, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(kernel, kernel)), cv::Point(-1, -1), 1,
                     cv::BORDER_REPLICATE);
    cv::Mat darkSmooth(image.rows, image.cols, CV_32F), dark(image.rows, image.cols, CV_32F);
    std::vector<float> valid;
    for (int row = 0; row < image.rows; ++row) {
      for (int col = 0; col < image.cols; ++col) {
        const float b = background.at<float>(row, col);
        if (!mask.isValid(col, row)) {
          darkSmooth.at<float>(row, col) = dark.at<float>(row, col) = 0.0f;
          continue;
        }
        if (!(b > 0.0f) || !std::isfinite(b)) {
          return fail(fmt::format("the grid image's background is {} at pixel ({}, {}); give the X-ray's intensities "
                                  "(bright where the beam is unattenuated, beads dark)",
                                  b, col, row));
        }
        darkSmooth.at<float>(row, col) = (b - smooth.at<float>(row, col)) / b;
        dark.at<float>(row, col) = (b - raw.at<float>(row, col)) / b;
        valid.push_back(darkSmooth.at<float>(row, col));
      }
    }
    if (valid.empty()) return beads;
    const auto high = valid.begin() + static_cast<std::ptrdiff_t>(0.995 * double(valid.size() - 1));
    std::nth_element(valid.begin(), high, valid.end());
    const float threshold = std::max(static_cast<float>(o.minContrast), 0.35f * *high);
    cv::Mat spots = darkSmooth > threshold;
    cv::Mat labels, stats, centroids;
    const int count = cv::connectedComponentsWithStats(spots, labels, stats, centroids, 8, CV_32S);
    // Pixels within 2 px of an invalid pixel or the border: a bead touching them is cut off.
    cv::Mat invalid(image.rows, image.cols, CV_8U);
    for (std::size_t i = 0; i < mask.valid.size(); ++i) invalid.data[i] = mask.valid[i] ? 0 : 255;
    cv::dilate(invalid, invalid, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)), cv::Point(-1, -1), 1,
               cv::BORDER_CONSTANT, cv::Scalar(255));
    for (int label = 1; label < count; ++label) {
      const int left = stats.at<int>(label, cv::CC_STAT_LEFT), top = stats.at<int>(label, cv::CC_STAT_TOP);
      const int width = stats.at<int>(label, cv::CC_STAT_WIDTH), height = stats.at<int>(label, cv::CC_STAT_HEIGHT);
      const double radius = std::sqrt(stats.at<int>(label, cv::CC_STAT_AREA) / M_PI);
      if (radius < o.minRadius_px || radius > o.maxRadius_px) continue;
      if (std::max(width, height) > 3 * std::min(width, height)) continue;
      // The centroid's disc and ring must lie on the image, or the border cuts the bead's weight off one side.
      const double window = 1.6 * radius + 1.5;
      const Eigen::Vector2d start(centroids.at<double>(label, 0), centroids.at<double>(label, 1));
      const double reach = window + 4.0;
      if (start.x() < reach || start.y() < reach || start.x() > image.cols - 1 - reach ||
          start.y() > image.rows - 1 - reach) {
        continue;
      }
      bool nearInvalid = false;
      for (int row = top; row < top + height && !nearInvalid; ++row) {
        for (int col = left; col < left + width; ++col) {
          if (labels.at<int>(row, col) == label && invalid.at<std::uint8_t>(row, col)) {
            nearInvalid = true;
            break;
          }
        }
      }
      if (nearInvalid) continue;
      Eigen::Vector2d centre = start;
      for (int pass = 0; pass < 2; ++pass) centre = weightedCentroid(dark, centre, window);
      beads.push_back({centre, radius});
    }
  } catch (const cv::Exception& e) {
    return fail(fmt::format("bead detection failed in OpenCV: {}", e.what()));
  }
  return beads;
}

}  // namespace fct
