#pragma once
// GridBeadDetector: finds the bead shadows of a dewarp calibration plate (small dark discs in MONOCHROME2
// intensities) with sub-pixel centres.
//
// Method: the image is smoothed (Gaussian, sigma 1 px); its background is the morphological closing with a disc
// larger than the biggest bead (which removes every dark spot smaller than the disc); the relative darkness is
// (background − smoothed) / background. Pixels darker than max(minContrast, 0.35 × the darkness's 99.5th percentile)
// form 8-connected candidates; a candidate is kept when its equivalent radius is within minRadius_px..maxRadius_px,
// it is not elongated (bounding box sides within 3:1), it keeps 2 px away from invalid pixels, and its centroid's
// disc and ring (below) lie on the image. Its centre is the darkness-weighted centroid of the unsmoothed image over a
// disc of 1.6 × its radius + 1.5 px, after subtracting the median darkness of the ring 1..3 px outside it (twice,
// re-centred).

#include <vector>

#include "Base/Result.h"
#include "Geometry/PixelCircle.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// Settings of the bead detection.
struct GridBeadOptions {
  double minRadius_px = 0.8;   ///< smallest bead shadow radius (equivalent radius of the thresholded spot)
  double maxRadius_px = 12.0;  ///< largest bead shadow radius
  double minContrast = 0.03;   ///< a bead is darker than its background by at least this fraction
};

/// Detects the beads of a calibration grid image.
class GridBeadDetector {
 public:
  explicit GridBeadDetector(GridBeadOptions options = {}) : m_options(options) {}

  /// The beads found among the pixels valid in `mask` (same size as the image): centres (px, sub-pixel) and
  /// equivalent radii. An image with no dark spot gives an empty list. Fails on bad options, a size mismatch, a
  /// non-positive or non-finite background (the image must be MONOCHROME2 intensities), or an OpenCV error.
  Result<std::vector<PixelCircle>> detect(const FloatImage& image, const ValidMask& mask) const;

 private:
  GridBeadOptions m_options;
};

}  // namespace fct
