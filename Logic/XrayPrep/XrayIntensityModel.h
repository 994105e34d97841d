#pragma once
// XrayIntensityModel: converts X-ray intensities (MONOCHROME2: bright = more signal at the detector) to the
// line-integral sense of the DRR (sum of attenuation along the ray, >= 0, bright bone = large).
//
// Model (Beer-Lambert): I = I0 exp(-p), so p = -ln(max(I, floorFraction * I0) / I0), clamped to p >= 0.
// I0 is the reference (unattenuated) level: the referencePercentile-th percentile of the valid (in-field) pixels.
// Because I0 scales with the image, an unknown detector gain g (I -> g I) leaves p unchanged; the clamp floor caps
// p at -ln(floorFraction) (6.9 for 1e-3) where the detector saw almost nothing. Pixels brighter than I0 (at most
// 100 - referencePercentile % of the field) map to 0. An unknown dark offset is not modelled: subtract it first.

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// Settings of the log transform.
struct IntensityModelOptions {
  double referencePercentile = 99.5;  ///< percentile (0 < q <= 100) of the valid pixels taken as I0
  double floorFraction = 1e-3;        ///< intensities below floorFraction * I0 are clamped to it (0 < f < 1)
};

/// An X-ray in the line-integral sense and the reference level that was used.
struct LineIntegralImage {
  FloatImage lineIntegrals;        ///< p = -ln(I / I0) per pixel, dimensionless, >= 0
  double referenceIntensity = 0.0;  ///< I0, in the input's intensity units
};

/// The log transform of X-ray intensities to line integrals.
class XrayIntensityModel {
 public:
  explicit XrayIntensityModel(IntensityModelOptions options = {}) : m_options(options) {}

  /// Converts intensities to line integrals; I0 is taken over the pixels valid in `mask`. Fails on a size mismatch,
  /// bad options, no valid pixel, non-finite pixels, or a reference level <= 0 (a black or negative image).
  Result<LineIntegralImage> toLineIntegrals(const FloatImage& intensities, const ValidMask& mask) const;

 private:
  IntensityModelOptions m_options;
};

}  // namespace fct
