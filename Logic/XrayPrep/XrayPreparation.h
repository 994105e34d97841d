#pragma once
// XrayPreparation: turns one X-ray view into what the comparison with the DRR needs: a validity mask (field of view,
// image margin, calibration spheres, metal shadows, and the image's own fovMask if it has one), the image in the DRR's
// line-integral sense (XrayIntensityModel), and the pyramid of levels 0..levelCount-1 with their cameras.

#include <optional>
#include <vector>

#include "Base/Result.h"
#include "Geometry/PixelCircle.h"
#include "Image/XrayImage.h"
#include "XrayPrep/CalibrationSphereDetector.h"
#include "XrayPrep/FieldOfViewDetector.h"
#include "XrayPrep/MetalMaskDetector.h"
#include "XrayPrep/XrayIntensityModel.h"
#include "XrayPrep/XrayPyramid.h"

namespace fct {

/// Settings of the X-ray preparation (all masks are full-resolution pixels).
struct XrayPreparationOptions {
  bool detectFieldOfView = true;              ///< detect the circular / collimated field automatically
  FieldOfViewOptions fieldOfView;             ///< settings of the detection
  int margin_px = 8;                          ///< band along the image borders excluded (0 = none)
  std::vector<PixelCircle> spheres;           ///< calibration-sphere shadows given by the view file
  bool detectSpheres = false;                 ///< also detect sphere shadows as small dark discs
  CalibrationSphereOptions sphereDetection;   ///< settings of the detection
  double sphereMargin_px = 2.0;               ///< added to each sphere's radius when excluding it
  IntensityModelOptions intensity;            ///< log transform settings
  bool excludeMetal = true;                   ///< exclude metal shadows (K-wires, screws, plates) found in the image
  MetalMaskOptions metal;                     ///< settings of the metal detection
  int levelCount = 3;                         ///< pyramid levels: 3 = 1, 1:4, 1:16 pixels
};

/// A prepared view.
struct PreparedXray {
  XrayPyramid pyramid;                     ///< line-integral image, mask and camera per level
  std::optional<PixelCircle> fieldOfView;  ///< the detected circular field boundary (level 0 px), if circular
  std::vector<PixelCircle> spheres;        ///< excluded sphere shadows, given and detected (level 0 px, no margin)
  double referenceIntensity = 0.0;         ///< I0 of the log transform, in the input's intensity units
  double validFraction = 0.0;              ///< fraction of level-0 pixels valid
  double metalFraction = 0.0;              ///< fraction of the otherwise valid level-0 pixels excluded as metal
  /// Level-0 valid pixels before the metal exclusion (field of view, margin, spheres): what a metal-mask review
  /// (MetalMaskReview) may give back.
  ValidMask fieldMask;
};

/// Prepares X-ray views for registration.
class XrayPreparation {
 public:
  explicit XrayPreparation(XrayPreparationOptions options = {}) : m_options(std::move(options)) {}

  /// Prepares one view. Fails on an empty or inconsistent image, a mask that leaves no pixel, or any failure of the
  /// steps (the message names the step).
  Result<PreparedXray> prepare(const XrayImage& xray) const;

 private:
  XrayPreparationOptions m_options;
};

}  // namespace fct
