#include "XrayPrep/MetalMaskDetector.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace fct {

Result<MetalMask> MetalMaskDetector::detect(const FloatImage& lineIntegrals, const ValidMask& mask,
                                            double pixelSpacing_mm) const {
  const MetalMaskOptions& o = m_options;
  const int cols = lineIntegrals.cols;
  const int rows = lineIntegrals.rows;
  if (cols <= 0 || rows <= 0 || lineIntegrals.pixels.size() != static_cast<std::size_t>(cols) * rows ||
      mask.cols != cols || mask.rows != rows || mask.valid.size() != lineIntegrals.pixels.size()) {
    return fail(fmt::format("metal detection: the image is {}x{} with {} values and the mask {}x{}; both must have "
                            "cols*rows pixels of the same size",
                            cols, rows, lineIntegrals.pixels.size(), mask.cols, mask.rows));
  }
  if (!(pixelSpacing_mm >= 0.0) || !std::isfinite(pixelSpacing_mm)) {
    return fail(fmt::format("metal detection: pixel spacing {} mm; give a positive spacing or 0 for unknown",
                            pixelSpacing_mm));
  }
  const int window_px = pixelSpacing_mm > 0.0
                            ? static_cast<int>(std::lround(o.backgroundWindow_mm / pixelSpacing_mm))
                            : o.backgroundWindow_px;
  if (window_px < 3 || !(o.minExcess > 0.0) || !std::isfinite(o.minExcess) || o.dilation_px < 0) {
    return fail(fmt::format("metal detection options: window {} px (>= 3; {} mm at {} mm pixels), minimum excess {} "
                            "(> 0), dilation {} px (>= 0); fix the settings",
                            window_px, o.backgroundWindow_mm, pixelSpacing_mm, o.minExcess, o.dilation_px));
  }
  for (float p : lineIntegrals.pixels) {
    if (!std::isfinite(p)) return fail("metal detection: the line-integral image has non-finite pixels");
  }
  try {
    // Opening over the valid pixels only: invalid pixels never win the erosion (+max) nor, where the whole erosion
    // window was invalid, the dilation (-max).
    constexpr float kHigh = std::numeric_limits<float>::max();
    cv::Mat p(rows, cols, CV_32F);
    for (std::size_t i = 0; i < mask.valid.size(); ++i) {
      p.ptr<float>()[i] = mask.valid[i] ? lineIntegrals.pixels[i] : kHigh;
    }
    const int side = window_px | 1;
    const cv::Mat window = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side));
    cv::Mat background;
    cv::erode(p, background, window, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(kHigh));
    background.setTo(cv::Scalar(-kHigh), background == kHigh);
    cv::dilate(background, background, window, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(-kHigh));

    cv::Mat metal = cv::Mat::zeros(rows, cols, CV_8U);
    for (std::size_t i = 0; i < mask.valid.size(); ++i) {
      if (mask.valid[i] && lineIntegrals.pixels[i] - background.ptr<float>()[i] > o.minExcess) metal.data[i] = 1;
    }
    if (o.dilation_px > 0) {
      const int grow = 2 * o.dilation_px + 1;
      cv::dilate(metal, metal, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(grow, grow)));
    }
    MetalMask result{mask, 0};
    for (std::size_t i = 0; i < mask.valid.size(); ++i) {
      if (metal.data[i] && result.mask.valid[i]) {
        result.mask.valid[i] = 0;
        ++result.metalPixelCount;
      }
    }
    return result;
  } catch (const cv::Exception& e) {
    return fail(fmt::format("metal detection: OpenCV error: {}", e.what()));
  }
}

}  // namespace fct
