#include "Simulation/StandardViews.h"

#include <fmt/core.h>

#include <cmath>
#include <numbers>

namespace fct {

std::vector<StandardViewAngles> StandardViews::angles(int count, double obliqueTilt_deg) {
  const std::vector<StandardViewAngles> all = {{"ap", 0.0, 0.0},
                                               {"lateral", 90.0, 0.0},
                                               {"oblique45", 45.0, obliqueTilt_deg},
                                               {"oblique30", 30.0, -obliqueTilt_deg},
                                               {"oblique60", 60.0, obliqueTilt_deg}};
  if (count < 1 || count > static_cast<int>(all.size())) return {};
  return {all.begin(), all.begin() + count};
}

Result<std::vector<ViewSpec>> StandardViews::build(const Eigen::Vector3d& isocentre_world_mm,
                                                   const StandardViewOptions& options) {
  if (options.count < 1 || options.count > 5) {
    return fail(fmt::format("view count must be 1..5 (AP, lateral and up to three obliques), got {}", options.count));
  }
  if (!isocentre_world_mm.allFinite()) return fail("isocentre contains NaN or infinity");
  if (!std::isfinite(options.sourceToIsocentre_mm) || !std::isfinite(options.sourceToDetector_mm) ||
      options.sourceToIsocentre_mm <= 0.0 || options.sourceToIsocentre_mm >= options.sourceToDetector_mm) {
    return fail(fmt::format("source-to-isocentre distance ({} mm) must be positive and below the source-to-detector "
                            "distance ({} mm)",
                            options.sourceToIsocentre_mm, options.sourceToDetector_mm));
  }
  if (options.cols <= 0 || options.rows <= 0) {
    return fail(fmt::format("detector size must be positive, got {} x {} pixels", options.cols, options.rows));
  }
  if (!std::isfinite(options.pixelSpacing_mm) || options.pixelSpacing_mm <= 0.0) {
    return fail(fmt::format("detector pixel spacing must be positive, got {} mm", options.pixelSpacing_mm));
  }
  if (!std::isfinite(options.obliqueTilt_deg) || std::abs(options.obliqueTilt_deg) > 45.0) {
    return fail(fmt::format("oblique tilt must be within ±45°, got {}°", options.obliqueTilt_deg));
  }

  // AP camera: columns toward the patient's left (+x), rows toward the feet (-z), beam anterior -> posterior (+y).
  Eigen::Matrix3d R_world_from_ap;
  R_world_from_ap.col(0) = Eigen::Vector3d::UnitX();
  R_world_from_ap.col(1) = -Eigen::Vector3d::UnitZ();
  R_world_from_ap.col(2) = Eigen::Vector3d::UnitY();
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;

  std::vector<ViewSpec> views;
  for (const StandardViewAngles& view : angles(options.count, options.obliqueTilt_deg)) {
    // Entries that are zero up to rounding (e.g. cos 90°) are written as exact zeros.
    const Eigen::Matrix3d R_world_from_camera =
        (Eigen::AngleAxisd(view.rotation_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
         R_world_from_ap * Eigen::AngleAxisd(view.tilt_deg * kRadPerDeg, Eigen::Vector3d::UnitX()).toRotationMatrix())
            .unaryExpr([](double v) { return std::abs(v) < 1e-12 ? 0.0 : v; });
    const Camera looking = Camera::lookingAt(isocentre_world_mm, R_world_from_camera, options.sourceToIsocentre_mm,
                                             options.sourceToDetector_mm, options.cols, options.rows,
                                             options.pixelSpacing_mm);
    auto camera = Camera::create(looking.intrinsics(), looking.T_world_from_camera());
    if (!camera.ok()) return fail(fmt::format("view '{}': {}", view.name, camera.error()));
    ViewSpec spec;
    spec.name = view.name;
    spec.camera = std::move(camera).value();
    views.push_back(std::move(spec));
  }
  return views;
}

}  // namespace fct
