#pragma once
// RegistrationView: one view as registration takes it, the input of a RegistrationCase.

#include <string>
#include <vector>

#include "Geometry/Camera.h"
#include "Geometry/PixelCircle.h"
#include "Image/XrayImage.h"

namespace fct {

/// One view as registration takes it: the X-ray intensities (MONOCHROME2 sense), its calibrated camera (same
/// detector size) and the calibration-sphere shadows to exclude (level-0 pixels).
struct RegistrationView {
  std::string name;
  XrayImage xray;
  Camera camera;
  std::vector<PixelCircle> spheres;
};

}  // namespace fct
