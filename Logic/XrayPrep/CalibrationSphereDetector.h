#pragma once
// CalibrationSphereDetector: finds the shadows of calibration-grid spheres (small dark discs in MONOCHROME2
// intensities) so they can be excluded from the comparison with the DRR.
//
// Method: the image is scaled to 8 bits over its valid pixels' range, smoothed (Gaussian, sigma 1 px), and
// candidate circles with radii in [minRadius_px, maxRadius_px] come from OpenCV's gradient Hough transform.
// A candidate is kept when it is dark: the mean of the disc of 0.7 r is below the mean of the ring 1.3 r .. 1.8 r
// by at least minContrast of the image's valid range, and its centre pixel is valid.

#include <vector>

#include "Base/Result.h"
#include "Geometry/PixelCircle.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// Settings of the sphere detection.
struct CalibrationSphereOptions {
  double minRadius_px = 3.0;         ///< smallest sphere shadow radius
  double maxRadius_px = 15.0;        ///< largest sphere shadow radius
  double minContrast = 0.1;          ///< disc darker than its surround by this fraction of the valid range
  double houghThreshold = 12.0;      ///< Hough accumulator threshold (lower finds more, and more false circles)
};

/// Detects calibration-sphere shadows in one X-ray.
class CalibrationSphereDetector {
 public:
  explicit CalibrationSphereDetector(CalibrationSphereOptions options = {}) : m_options(options) {}

  /// The dark discs found in `intensities` (MONOCHROME2) among the pixels valid in `mask`, as circles in pixels.
  /// Fails on a size mismatch, bad options, or an OpenCV error.
  Result<std::vector<PixelCircle>> detect(const FloatImage& intensities, const ValidMask& mask) const;

 private:
  CalibrationSphereOptions m_options;
};

}  // namespace fct
