#pragma once
// MetalMaskDetector: finds the shadows of metal (K-wires, screws, plates, instruments) in an X-ray so they can be
// excluded from the comparison with the DRR, which the CT cannot explain.
//
// Method, on the image in the line-integral sense (XrayIntensityModel: p = -ln(I/I0), bone bright): metal is much
// more attenuating than bone and is thin, so it stands out as a narrow ridge of p far above its surroundings. The
// background is the grey-level opening of p over the valid pixels only (erosion then dilation with a square window
// wider than any wire, screw or plate shadow but narrower than bones: backgroundWindow_mm on the detector when the
// pixel spacing is known, else backgroundWindow_px); the excess p - opening(p) >= 0 is the attenuation
// a narrow object adds on top of its surroundings. A pixel is metal where the excess exceeds minExcess (dimensionless
// line-integral units: exp(-1.5) = 22 % of the neighbourhood's signal reaches the detector, which bone edges of a
// patient do not produce but steel and titanium of a few mm do). The metal pixels are dilated by dilation_px to
// cover the blurred edge of the shadow. Objects wider than the window are not found.

#include <cstddef>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// Settings of the metal detection (full-resolution pixels).
struct MetalMaskOptions {
  double backgroundWindow_mm = 30.0;  ///< side of the square opening window on the detector (plate shadow ~20 mm)
  int backgroundWindow_px = 75;       ///< the window side in pixels when the detector pixel spacing is unknown
  double minExcess = 1.5;        ///< line-integral excess over the local background above which a pixel is metal
  int dilation_px = 3;           ///< metal pixels are grown by this radius (square) before exclusion
};

/// What was found.
struct MetalMask {
  ValidMask mask;                  ///< 1 = not metal (or not valid in the input mask), 0 = metal or its dilation
  std::size_t metalPixelCount = 0;  ///< pixels excluded because of metal that were valid in the input mask
};

/// Detects metal shadows in one X-ray.
class MetalMaskDetector {
 public:
  explicit MetalMaskDetector(MetalMaskOptions options = {}) : m_options(options) {}

  /// The metal mask of `lineIntegrals` (p = -ln(I/I0), >= 0) over the pixels valid in `mask`; `pixelSpacing_mm` is
  /// the detector pixel size (0 = unknown: the window is backgroundWindow_px). Fails on a size mismatch, bad options
  /// or spacing, non-finite pixels, or an OpenCV error.
  Result<MetalMask> detect(const FloatImage& lineIntegrals, const ValidMask& mask, double pixelSpacing_mm = 0.0) const;

 private:
  MetalMaskOptions m_options;
};

}  // namespace fct
