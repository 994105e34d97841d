#pragma once
// XrayPyramid: the multiresolution levels of one prepared X-ray view. Level k has 1/4^k of the pixels: each level
// halves both axes (floor), every pixel is the mean of a 2x2 block of the level below, and a pixel is valid only
// when its whole block is valid. The camera of level k is Camera::downsampled(k) (exact principal point and pixel
// size), so a DRR rendered with it lines up with the level's pixels.

#include <optional>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// One level of the pyramid.
struct PyramidLevel {
  int level = 0;                 ///< 0 = full resolution; each pixel covers a 2^level x 2^level block of level 0
  FloatImage image;              ///< the X-ray at this level (same sense as the input, e.g. line integrals)
  ValidMask mask;                ///< valid pixels at this level
  std::optional<Camera> camera;  ///< the level's camera, if the view's camera is known
};

/// Levels 0..levelCount-1 of one view.
class XrayPyramid {
 public:
  /// Builds `levelCount` levels (1..8) from a full-resolution image and mask; `camera`, if given, must have the image's
  /// size. Fails on size mismatches, a bad level count, or a top level smaller than 1x1.
  static Result<XrayPyramid> build(const FloatImage& image, const ValidMask& mask, const std::optional<Camera>& camera,
                                   int levelCount = 3);

  /// Halves an image per axis (floor) by 2x2 block means.
  static FloatImage downsampleByTwo(const FloatImage& image);
  /// Halves a mask per axis (floor): valid only when all four pixels of the block are valid.
  static ValidMask downsampleByTwo(const ValidMask& mask);

  /// Number of levels.
  int levelCount() const { return static_cast<int>(m_levels.size()); }
  /// Level k (0 <= k < levelCount()); no bounds check.
  const PyramidLevel& level(int k) const { return m_levels[static_cast<std::size_t>(k)]; }

 private:
  std::vector<PyramidLevel> m_levels;
};

}  // namespace fct
