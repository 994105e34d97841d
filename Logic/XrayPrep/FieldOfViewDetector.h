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
// A real field edge is a step, so the background must also pass an edge test: the median over the field pixels
// within edgeWidth_px of the background of (value - min) / (t - min) (the edge step) must be at least minEdgeStep.
// Anatomy that reaches the border of a collimator-free image (a simulated view) fades through t instead (measured
// edge step 1.1-1.2 on simulated lateral pelvis views, 3.3-9.3 on the real RF shoulder image and synthetic
// collimators); such an image is entirely field, like one without background.

#include <optional>

#include "Base/Result.h"
#include "Geometry/PixelCircle.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// Settings of the field-of-view detection.
struct FieldOfViewOptions {
  double backgroundLevel = 0.1;         ///< background threshold as a fraction of (p90 - min) above the minimum
  double minBackgroundFraction = 0.01;  ///< below this fraction of background pixels the whole image is field
  double maxCircleResidual_px = 2.0;    ///< median distance of boundary pixels to the circle for a circular field
  int inset_px = 12;                    ///< pixels removed inside the detected boundary (covers the edge blur)
  int edgeWidth_px = 4;                 ///< width of the field band next to the background used by the edge test
  double minEdgeStep = 2.0;             ///< least edge step (in units of the threshold above the minimum) of a field
};

/// What was found: the mask of usable pixels and, for a circular field, the fitted boundary circle.
struct FieldOfView {
  ValidMask mask;                     ///< 1 = inside the field, at least inset_px from its boundary
  std::optional<PixelCircle> circle;  ///< the fitted boundary (before the inset), if the field is circular
  double backgroundFraction = 0.0;    ///< fraction of the image found to be background (0 when none)
  double edgeStep = 0.0;              ///< the edge test's value (see the file comment); 0 without a dark border region
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
