#pragma once
// FloatImage: a plain 2D float image (row-major, row 0 = top), the working image type of DRRs, prepared X-rays,
// pyramids and masks in Logic. Pixel lists address it by linear index row * cols + col.

#include <cstdint>
#include <vector>

namespace fct {

/// Linear pixel indices (row * cols + col) into a FloatImage of known size, e.g. the ROI pixels of a pyramid level.
using PixelIndexList = std::vector<std::int32_t>;

/// A row-major float image.
struct FloatImage {
  int cols = 0;
  int rows = 0;
  std::vector<float> pixels;  ///< rows*cols values

  /// An image of the given size filled with `value`.
  static FloatImage filled(int cols, int rows, float value = 0.0f) {
    return FloatImage{cols, rows, std::vector<float>(static_cast<std::size_t>(cols) * rows, value)};
  }
  /// Pixel value at (col,row); no bounds check.
  float at(int col, int row) const { return pixels[static_cast<std::size_t>(row) * cols + col]; }
  float& at(int col, int row) { return pixels[static_cast<std::size_t>(row) * cols + col]; }
  /// True when the image has no pixels.
  bool empty() const { return pixels.empty(); }
};

}  // namespace fct
