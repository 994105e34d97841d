#pragma once
// RgbImage: an 8-bit colour image (row-major, row 0 = top, 3 bytes per pixel in R, G, B order), e.g. an overlay.

#include <array>
#include <cstdint>
#include <vector>

namespace fct {

/// A row-major 8-bit RGB image.
struct RgbImage {
  int cols = 0;
  int rows = 0;
  std::vector<std::uint8_t> pixels;  ///< rows*cols*3 bytes: R, G, B of (0,0), then (1,0), ...

  /// The colour at (col,row); no bounds check.
  std::array<std::uint8_t, 3> at(int col, int row) const {
    const std::size_t o = 3 * (static_cast<std::size_t>(row) * cols + col);
    return {pixels[o], pixels[o + 1], pixels[o + 2]};
  }
  /// True when the image has no pixels.
  bool empty() const { return pixels.empty(); }
};

}  // namespace fct
