#pragma once
// FieldOfViewDetector: finds the exposed field of view of an X-ray (the circular image-intensifier field or a
// collimated area) so that the dark background and the blurred collimator edge are excluded from comparison.
//
// Method: the background is every pixel at or below a low level, t = min + backgroundLevel * (p90 - min) of the
// image (p90 its 90th percentile, a level inside the field even when most of the image is collimated), that is connected (4-neighbourhood) to the image border; dark bone inside the field is not connected to the
// border through dark pixels and stays in the field. The field's boundary pixels (field pixels with a background
// 4-neighbour, not on the image border) are fitted by a circle (algebraic least squares, then twice refitted
// without outliers beyond 3 median residuals + 1 px). When the fit's median residual is within
// maxCircleResidual_px the mask is the disc of radius r - inset_px; otherwise (a rectangular or irregular
// collimator) the mask is the field region eroded by inset_px. An image with almost no background
// (below minBackgroundFraction) is entirely field: the mask is all valid and no circle is reported.

#include <optional>

#include "FloatImage.h"
#include "PixelCircle.h"
#include "Result.h"
#include "ValidMask.h"

namespace fct {

/// Settings of the field-of-view detection.
struct FieldOfViewOptions {
  double backgroundLevel = 0.1;         ///< background threshold as a fraction of (p90 - min) above the minimum
  double minBackgroundFraction = 0.01;  ///< below this fraction of background pixels the whole image is field
  double maxCircleResidual_px = 2.0;    ///< median distance of boundary pixels to the circle for a circular field
  int inset_px = 12;                    ///< pixels removed inside the detected boundary (covers the edge blur)
};

/// What was found: the mask of usable pixels and, for a circular field, the fitted boundary circle.
struct FieldOfView {
  ValidMask mask;                     ///< 1 = inside the field, at least inset_px from its boundary
  std::optional<PixelCircle> circle;  ///< the fitted boundary (before the inset), if the field is circular
  double backgroundFraction = 0.0;    ///< fraction of the image found to be background
};

/// Detects the field of view of one X-ray.
class FieldOfViewDetector {
 public:
  explicit FieldOfViewDetector(FieldOfViewOptions options = {}) : m_options(options) {}

  /// Detects the field of view in an intensity image (MONOCHROME2 sense: background dark). Fails on an empty image,
  /// non-finite pixels or nonsensical options.
  Result<FieldOfView> detect(const FloatImage& intensities) const;

 private:
  FieldOfViewOptions m_options;
};

}  // namespace fct
