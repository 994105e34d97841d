#include "XrayPrep/XrayDewarper.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core/utility.hpp>

namespace fct {

Result<XrayImage> XrayDewarper::apply(const XrayImage& distorted, const DewarpField& field) {
  const int cols = distorted.cols, rows = distorted.rows;
  const std::size_t count = static_cast<std::size_t>(cols) * rows;
  if (cols <= 0 || rows <= 0 || distorted.pixels.size() != count ||
      (!distorted.fovMask.empty() && distorted.fovMask.size() != count)) {
    return fail(fmt::format("cannot dewarp X-ray '{}': it is {}x{} with {} pixel values", distorted.sourcePath, cols,
                            rows, distorted.pixels.size()));
  }
  if (cols != field.cols() || rows != field.rows()) {
    return fail(fmt::format("the dewarp was calibrated for {}x{} images but X-ray '{}' is {}x{}; calibrate with a grid "
                            "image of this detector format",
                            field.cols(), field.rows(), distorted.sourcePath, cols, rows));
  }
  // A source is usable when its four bilinear neighbours are on the image and inside its field-of-view mask.
  const auto inField = [&](int col, int row) {
    return distorted.fovMask.empty() || distorted.fovMask[static_cast<std::size_t>(row) * cols + col] != 0;
  };
  XrayImage out = distorted;
  out.fovMask.assign(count, 0);
  try {
    cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
      for (int row = range.start; row < range.end; ++row) {
        for (int col = 0; col < cols; ++col) {
          const std::size_t index = static_cast<std::size_t>(row) * cols + col;
          out.pixels[index] = 0.0f;
          const auto source = field.distorted(Eigen::Vector2d(col, row));
          if (!source || !(source->x() >= 0.0 && source->y() >= 0.0 && source->x() <= cols - 1 &&
                           source->y() <= rows - 1)) {
            continue;
          }
          const int c0 = std::max(0, std::min(static_cast<int>(source->x()), cols - 2));
          const int r0 = std::max(0, std::min(static_cast<int>(source->y()), rows - 2));
          const int c1 = std::min(c0 + 1, cols - 1), r1 = std::min(r0 + 1, rows - 1);
          if (!inField(c0, r0) || !inField(c1, r0) || !inField(c0, r1) || !inField(c1, r1)) continue;
          const double fc = source->x() - c0, fr = source->y() - r0;
          const double top = (1.0 - fc) * distorted.at(c0, r0) + fc * distorted.at(c1, r0);
          const double bottom = (1.0 - fc) * distorted.at(c0, r1) + fc * distorted.at(c1, r1);
          out.pixels[index] = static_cast<float>((1.0 - fr) * top + fr * bottom);
          out.fovMask[index] = 1;
        }
      }
    });
  } catch (const cv::Exception& e) {
    return fail(fmt::format("dewarping X-ray '{}' failed in OpenCV: {}", distorted.sourcePath, e.what()));
  }
  return out;
}

std::vector<PixelCircle> XrayDewarper::mapCircles(const std::vector<PixelCircle>& circles, const DewarpField& field) {
  std::vector<PixelCircle> mapped;
  for (const PixelCircle& circle : circles) {
    const double scale = std::sqrt(std::abs(field.jacobian(circle.centre_px).determinant()));
    mapped.push_back({field.ideal(circle.centre_px), circle.radius_px * scale});
  }
  return mapped;
}

}  // namespace fct
