#include "XrayPrep/XrayPreparation.h"

#include <fmt/format.h>

namespace fct {

Result<PreparedXray> XrayPreparation::prepare(const XrayImage& xray) const {
  const XrayPreparationOptions& o = m_options;
  if (xray.cols <= 0 || xray.rows <= 0 || xray.pixels.size() != static_cast<std::size_t>(xray.cols) * xray.rows) {
    return fail(fmt::format("X-ray '{}' is {}x{} with {} pixel values; expected cols*rows values", xray.sourcePath,
                            xray.cols, xray.rows, xray.pixels.size()));
  }
  const FloatImage intensities{xray.cols, xray.rows, xray.pixels};
  ValidMask mask = ValidMask::allValid(xray.cols, xray.rows);
  PreparedXray prepared;

  if (!xray.fovMask.empty()) {
    auto given = ValidMask::fromBytes(xray.cols, xray.rows, xray.fovMask);
    if (!given) return fail("X-ray field-of-view mask: " + given.error());
    (void)mask.intersect(given.value());  // same size by construction
  }
  if (o.detectFieldOfView) {
    auto fov = FieldOfViewDetector(o.fieldOfView).detect(intensities);
    if (!fov) return fail("field-of-view detection: " + fov.error());
    prepared.fieldOfView = fov.value().circle;
    (void)mask.intersect(fov.value().mask);
  }
  mask.excludeMargin(o.margin_px);

  prepared.spheres = o.spheres;
  if (o.detectSpheres) {
    auto detected = CalibrationSphereDetector(o.sphereDetection).detect(intensities, mask);
    if (!detected) return fail("calibration sphere detection: " + detected.error());
    prepared.spheres.insert(prepared.spheres.end(), detected.value().begin(), detected.value().end());
  }
  for (PixelCircle sphere : prepared.spheres) {
    sphere.radius_px += o.sphereMargin_px;
    mask.excludeInside(sphere);
  }
  if (mask.validCount() == 0) {
    return fail(fmt::format("no pixel of the {}x{} X-ray is left after excluding the field-of-view border, a {} px "
                            "margin and {} spheres; reduce the margin or check the image",
                            xray.cols, xray.rows, o.margin_px, prepared.spheres.size()));
  }

  auto lineIntegrals = XrayIntensityModel(o.intensity).toLineIntegrals(intensities, mask);
  if (!lineIntegrals) return fail("intensity model: " + lineIntegrals.error());
  prepared.referenceIntensity = lineIntegrals.value().referenceIntensity;

  prepared.fieldMask = mask;
  if (o.excludeMetal) {
    const std::size_t fieldCount = mask.validCount();
    const double pixelSpacing_mm = xray.camera ? xray.camera->intrinsics().pixelSpacing_mm.mean() : 0.0;
    auto metal = MetalMaskDetector(o.metal).detect(lineIntegrals.value().lineIntegrals, mask, pixelSpacing_mm);
    if (!metal) return fail(metal.error());
    if (metal.value().metalPixelCount == fieldCount) {
      return fail(fmt::format("every valid pixel of the {}x{} X-ray looks like metal (line integral more than {} above "
                              "its surroundings); check the image or turn the metal exclusion off",
                              xray.cols, xray.rows, o.metal.minExcess));
    }
    prepared.metalFraction = static_cast<double>(metal.value().metalPixelCount) / static_cast<double>(fieldCount);
    mask = std::move(metal).value().mask;
  }
  prepared.validFraction = static_cast<double>(mask.validCount()) / static_cast<double>(mask.valid.size());

  auto pyramid = XrayPyramid::build(lineIntegrals.value().lineIntegrals, mask, xray.camera, o.levelCount);
  if (!pyramid) return fail("pyramid: " + pyramid.error());
  prepared.pyramid = std::move(pyramid).value();
  return prepared;
}

}  // namespace fct
