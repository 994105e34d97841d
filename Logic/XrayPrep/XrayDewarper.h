#pragma once
// XrayDewarper: resamples a distorted image-intensifier X-ray onto the ideal (pinhole-camera) pixel grid of its
// DewarpField: ideal(u) = stored(d(u)), d the field's inverse (Newton), bilinear interpolation. Ideal pixels whose
// source lies off the stored image, outside its field-of-view mask, or where the inverse does not converge get
// value 0 and are marked invalid in the result's fovMask, so that X-ray preparation leaves them out.

#include <vector>

#include "Base/Result.h"
#include "Geometry/DewarpField.h"
#include "Geometry/PixelCircle.h"
#include "Image/XrayImage.h"

namespace fct {

/// Applies a dewarp to X-rays and to points on them.
class XrayDewarper {
 public:
  /// The X-ray on the ideal pixel grid (same size, same acquisition facts; fovMask = pixels with a source). Fails
  /// when the X-ray is empty or inconsistent or its size is not the one the field was calibrated for.
  static Result<XrayImage> apply(const XrayImage& distorted, const DewarpField& field);

  /// Circles on the stored image (e.g. calibration-sphere shadows) moved onto the ideal grid: centre through the
  /// field, radius scaled by the square root of the field's Jacobian determinant there.
  static std::vector<PixelCircle> mapCircles(const std::vector<PixelCircle>& circles, const DewarpField& field);
};

}  // namespace fct
