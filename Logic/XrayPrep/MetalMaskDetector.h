#pragma once
// MetalMaskDetector: finds the shadows of metal (K-wires, screws, plates, instruments) in an X-ray so they can be
// excluded from the comparison with the DRR, which the CT cannot explain.
//
// Method, on the image in the line-integral sense (XrayIntensityModel: p = -ln(I/I0), bone bright), over the valid
// pixels only; every length is in mm on the detector (pixel counts follow the pixel spacing):
// - a tool adds a step of line integral over its surroundings on both sides. Two grey-level openings estimate the
//   surroundings: a wide one (backgroundWindow_mm, wider than any wire, screw or plate shadow) and a narrow one
//   (narrowWindow_mm, a little wider than a wire or a screw shaft); a candidate pixel stands more than minExcess above
//   both. Bone seen edge-on (the skull's tangent rim, a cortex) can stand as high, but it is one-sided: the
//   surroundings are the bone on one side and the soft tissue beyond it on the other. The local bone contrast is the
//   narrow opening minus the erosion over a disc of contrastWindow_mm; a candidate's bone contrast is at most
//   maxContrastRatio times its narrow excess. The contrast bounds (maxContrastRatio, seedContrastRatio) are loose
//   enough for a K-wire crossing the skull base, whose surroundings vary more than the wire stands out; the anatomy
//   they also let through is the metal review's to give back once a DRR near the pose is at hand (MetalMaskReview);
// - the candidates' connected pieces are tested as shapes. A piece seeds the metal when it is very dense (mean wide
//   excess >= veryDenseExcess, length >= minVeryDenseLength_mm); when it is a compact two-sided blob (mean wide excess
//   >= compactExcess, at least minCompactWidth_mm across its shorter side, mean contrast ratio < compactContrastRatio:
//   a screw seen nearly end-on, its head and a short stub of shaft; bone's compact dense spots stand on a slope of
//   bone and have ratios of 0.35 and more, and a short thin mark is not a blob); or when it is straight (the sagitta of a parabola
//   fitted across the piece's axis is at most maxSagitta_mm: a rim is an arc) and either long with little bone
//   contrast (length >= minLength_mm, mean contrast / narrow excess < seedContrastRatio) or dense (mean wide excess
//   >= denseExcess, length >= minDenseLength_mm, mean ratio < denseContrastRatio). A piece that reaches the edge of
//   the valid pixels is cut by it (a K-wire entering the field): only its visible part can be measured, so it counts
//   as long from minClippedLength_mm on. A piece that is not straight as a whole (a wire crossing a screw or a bone
//   rim) seeds where a probabilistic Hough transform finds a straight bar of it at least minLength_mm long whose
//   pixels have the long piece's low mean contrast ratio;
// - the seeds grow along connected pixels still minExcess above the wide and growExcess above the narrow surroundings
//   for up to growDistance_mm (the rest of a wire over dense bone, a screw head), and the result is dilated by
//   dilation_mm (at least 3 px) to cover the blurred edge of the shadow and the glare around it.
// Not found: objects wider than the wide window; curved metal that is not very dense and has no straight bar of
// minLength_mm; a screw seen exactly end-on whose magnified head is wider than the narrow window (only the shaft's
// core then stands out, and is found when very dense); metal that stands less than minExcess above its surroundings (contrast-processed images;
// thin wires over thick anatomy at coarse pixels).

#include <cstddef>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// Settings of the metal detection (lengths in mm on the detector; excesses in line-integral units).
struct MetalMaskOptions {
  double backgroundWindow_mm = 30.0;  ///< side of the wide square opening window (plate shadow ~20 mm)
  double narrowWindow_mm = 10.0;      ///< side of the narrow square opening window (screw shaft ~7 mm)
  double contrastWindow_mm = 30.0;    ///< diameter of the erosion disc that finds the low side of the surroundings
  double assumedPixelSpacing_mm = 0.4;  ///< pixel spacing used when the image's is unknown
  double minExcess = 1.0;             ///< a candidate stands this far above the wide and the narrow opening
  double maxContrastRatio = 1.5;      ///< a candidate's bone contrast is below this multiple of its narrow excess
  double maxSagitta_mm = 1.5;         ///< a piece bends at most this much from a straight line
  double minLength_mm = 15.0;         ///< a long piece seeds metal when its mean contrast ratio is below ...
  double seedContrastRatio = 0.8;     ///< ... this
  double minClippedLength_mm = 4.0;   ///< the length that counts as long for a piece reaching the valid pixels' edge
  double denseExcess = 2.3;           ///< a piece with this mean wide excess seeds metal when ...
  double minDenseLength_mm = 10.0;    ///< ... at least this long and ...
  double denseContrastRatio = 0.6;    ///< ... its mean contrast ratio is below this
  double veryDenseExcess = 3.0;       ///< a piece with this mean wide excess seeds metal when ...
  double minVeryDenseLength_mm = 2.0;  ///< ... at least this long
  double compactExcess = 1.5;         ///< a piece with this mean wide excess seeds metal when ...
  double minCompactWidth_mm = 4.0;    ///< ... at least this wide across its shorter side and ...
  double compactContrastRatio = 0.25;  ///< ... its mean contrast ratio is below this (a two-sided blob)
  double growExcess = 0.5;            ///< seeds grow into pixels this far above the narrow opening ...
  double growDistance_mm = 25.0;      ///< ... up to this far
  double dilation_mm = 2.7;          ///< metal pixels are grown by this radius (square, at least 3 px) before exclusion
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
  /// the detector pixel size (0 = unknown: assumedPixelSpacing_mm). Fails on a size mismatch, bad options or
  /// spacing, non-finite pixels, or an OpenCV error.
  Result<MetalMask> detect(const FloatImage& lineIntegrals, const ValidMask& mask, double pixelSpacing_mm = 0.0) const;

 private:
  MetalMaskOptions m_options;
};

}  // namespace fct
