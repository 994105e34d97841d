#pragma once
// DynamicRoiSelector: the paper's dynamic regions of interest. The image (one X-ray at one pyramid level) is tiled
// by non-overlapping w x w windows starting at pixel (0,0); partial windows at the right and bottom edges and every
// window with an excluded (masked) pixel are dropped. Each remaining window gets
//     normalized variance  nv_w = var_w / var_valid,
// var_w the population variance of its w*w pixels and var_valid the population variance of all valid pixels of the
// image (so nv does not change with a gain or offset of the image; nv = 1 is "as varied as the image"). Windows
// with high nv sit on edges (bone contours, tools); flat background has nv near 0.
// The variances are computed once in create(); selections by threshold or by target fraction are then instant.

#include <cstddef>
#include <vector>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// One w x w window: its top-left pixel and its statistics in the image it was chosen on.
struct RoiWindow {
  int col0 = 0;                    ///< column of the top-left pixel
  int row0 = 0;                    ///< row of the top-left pixel
  float variance = 0.0f;           ///< population variance of its pixels, in image units squared
  float normalizedVariance = 0.0f; ///< variance / variance of all valid pixels
};

/// A set of kept windows and their pixels.
struct RoiSelection {
  int windowSize = 0;               ///< w
  std::vector<RoiWindow> windows;   ///< kept windows in raster order of their top-left pixel
  PixelIndexList pixels;            ///< their pixels, window by window: pixels[i*w*w .. (i+1)*w*w) is windows[i]
  double threshold = 0.0;           ///< normalized-variance threshold in effect (kept windows have nv >= it)
  double keptFraction = 0.0;        ///< kept pixels / valid pixels of the image
};

/// Precomputed window variances of one image, re-thresholded on demand.
class DynamicRoiSelector {
 public:
  /// Computes the window statistics of `image` with `mask` (same size) and w = windowSize (2..64). Fails on size
  /// mismatch, a bad window size, no complete valid window, or an image constant over its valid pixels.
  static Result<DynamicRoiSelector> create(const FloatImage& image, const ValidMask& mask, int windowSize = 7);

  /// Windows with normalized variance >= threshold. Fails when none reaches it (names the highest nv present).
  Result<RoiSelection> selectAboveThreshold(double normalizedVarianceThreshold) const;
  /// The highest-variance windows covering round(targetFraction * valid pixels) pixels, at least one window.
  /// Fails unless 0 < targetFraction <= 1. The paper uses 0.10 to 0.15.
  Result<RoiSelection> selectFraction(double targetFraction) const;
  /// Every complete valid window (VLNC without dynamic ROIs).
  RoiSelection selectAll() const;

  /// Window size w.
  int windowSize() const { return m_windowSize; }
  /// Number of complete valid windows.
  std::size_t candidateCount() const { return m_byVariance.size(); }

 private:
  RoiSelection selectTop(std::size_t count) const;

  int m_imageCols = 0;
  int m_windowSize = 0;
  std::size_t m_validPixelCount = 0;
  std::vector<RoiWindow> m_byVariance;  ///< candidates, normalized variance descending (ties: raster order)
};

}  // namespace fct
