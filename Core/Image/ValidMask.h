#pragma once
// ValidMask: which pixels of an X-ray (or of one pyramid level) take part in the comparison with the DRR.
// 1 = valid, 0 = excluded (outside the field of view, in the image margin, on a calibration sphere, ...).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "Base/Result.h"
#include "Geometry/PixelCircle.h"
#include "Image/FloatImage.h"

namespace fct {

/// A row-major byte mask of an image: 1 = the pixel is compared, 0 = excluded.
struct ValidMask {
  int cols = 0;
  int rows = 0;
  std::vector<std::uint8_t> valid;  ///< rows*cols bytes, 0 or 1

  /// A mask of the given size with every pixel valid.
  static ValidMask allValid(int cols, int rows);
  /// Wraps a byte mask (nonzero = valid), e.g. XrayImage::fovMask. Fails when its size is not cols*rows.
  static Result<ValidMask> fromBytes(int cols, int rows, const std::vector<std::uint8_t>& bytes);

  /// Pixel (col,row) is valid; no bounds check.
  bool isValid(int col, int row) const { return valid[static_cast<std::size_t>(row) * cols + col] != 0; }
  /// Excludes a band of `margin_px` pixels along all four image borders (margin_px <= 0 does nothing).
  void excludeMargin(int margin_px);
  /// Excludes every pixel whose centre lies outside `circle` (pixel coordinates of this mask).
  void excludeOutside(const PixelCircle& circle);
  /// Excludes every pixel whose centre lies inside `circle`, e.g. a calibration sphere's shadow.
  void excludeInside(const PixelCircle& circle);
  /// Keeps only pixels valid in both masks. Fails (mask unchanged) when the sizes differ.
  Status intersect(const ValidMask& other);
  /// Number of valid pixels.
  std::size_t validCount() const;
  /// Of the pixels valid here and in `region`, the fraction that `kept` excludes (e.g. of an X-ray's field, on the rays
  /// a CT covers, the share a metal mask takes out); 0 when no pixel is valid in both. Fails when the sizes differ.
  Result<double> excludedFractionWithin(const ValidMask& kept, const ValidMask& region) const;
  /// Linear indices (row * cols + col) of the valid pixels, in raster order.
  PixelIndexList pixelList() const;
};

}  // namespace fct
