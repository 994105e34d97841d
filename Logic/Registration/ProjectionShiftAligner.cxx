#include "Registration/ProjectionShiftAligner.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <optional>

#include "XrayPrep/XrayPyramid.h"

namespace fct {

namespace {

/// A DRR's best 2D shift against an X-ray of the same level: (col, row) in that level's pixels and its correlation.
struct LevelShift {
  Eigen::Vector2d shift_px = Eigen::Vector2d::Zero();
  double correlation = 0.0;
};

/// The offset of a parabola's vertex through (-1, a), (0, b), (1, c) from 0, within [-0.5, 0.5].
double parabolaPeak(double a, double b, double c) {
  const double curvature = a - 2.0 * b + c;
  if (!(curvature < 0.0)) return 0.0;
  return std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
}

/// The shift of the DRR that correlates best with `xray`: `grownDrr` is the DRR on the level's detector grown by
/// pad.x() columns and pad.y() rows on every side, so that it shows what every shift within the pad brings into the
/// field. The X-ray (its invalid pixels set to its valid mean) is the template, slid over the grown DRR; nullopt when
/// the X-ray has no valid pixel, the DRR is empty, or the best match lies on the border of the shift range.
std::optional<LevelShift> bestShift(const FloatImage& grownDrr, const Eigen::Vector2i& pad, const FloatImage& xray,
                                    const ValidMask& mask) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < xray.pixels.size(); ++i) {
    if (mask.valid[i]) {
      sum += xray.pixels[i];
      ++count;
    }
  }
  if (count == 0) return std::nullopt;
  if (!(*std::max_element(grownDrr.pixels.begin(), grownDrr.pixels.end()) > 0.0f)) return std::nullopt;
  const auto mean = static_cast<float>(sum / static_cast<double>(count));
  cv::Mat templ(xray.rows, xray.cols, CV_32F);
  for (int r = 0; r < xray.rows; ++r) {
    for (int c = 0; c < xray.cols; ++c) templ.at<float>(r, c) = mask.isValid(c, r) ? xray.at(c, r) : mean;
  }
  const cv::Mat drr(grownDrr.rows, grownDrr.cols, CV_32F, const_cast<float*>(grownDrr.pixels.data()));
  cv::Mat correlation;
  cv::matchTemplate(drr, templ, correlation, cv::TM_CCOEFF_NORMED);
  if (correlation.cols != 2 * pad.x() + 1 || correlation.rows != 2 * pad.y() + 1) return std::nullopt;
  double peak = 0.0;
  cv::Point at;
  cv::minMaxLoc(correlation, nullptr, &peak, nullptr, &at);
  if (!std::isfinite(peak)) return std::nullopt;
  // A peak on the border of the range is a cut-off slope, not a match.
  if (at.x == 0 || at.y == 0 || at.x == correlation.cols - 1 || at.y == correlation.rows - 1) return std::nullopt;
  const auto value = [&](int r, int c) { return static_cast<double>(correlation.at<float>(r, c)); };
  // The X-ray matches the DRR's content `offset` pixels away; the DRR moves by minus that offset.
  const Eigen::Vector2d offset(at.x - pad.x() + parabolaPeak(value(at.y, at.x - 1), peak, value(at.y, at.x + 1)),
                               at.y - pad.y() + parabolaPeak(value(at.y - 1, at.x), peak, value(at.y + 1, at.x)));
  LevelShift shift;
  shift.correlation = peak;
  shift.shift_px = -offset;
  return shift;
}

/// `camera` with its detector grown by pad_px pixels of pyramid `level` on every side: its level-`level` image is the
/// original level's image with that border around it (the same rays through the original pixels).
Result<Camera> grownDetector(const Camera& camera, const Eigen::Vector2i& pad_px, int level) {
  CameraIntrinsics grown = camera.intrinsics();
  const int scale = 1 << level;
  grown.cols += 2 * pad_px.x() * scale;
  grown.rows += 2 * pad_px.y() * scale;
  grown.principalPoint_px += Eigen::Vector2d(pad_px.x() * scale, pad_px.y() * scale);
  return Camera::create(grown, camera.T_world_from_camera());
}

/// The translation t (world mm) for which each camera projects centre + t nearest its target (full-resolution px):
/// damped Gauss-Newton from 0, the damping keeping the part of t that the views do not see (one view's depth) small.
Eigen::Vector3d triangulateTranslation(const std::vector<Camera>& cameras, const std::vector<Eigen::Vector2d>& targets,
                                       const Eigen::Vector3d& centre_world_mm) {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  constexpr double kStep_mm = 0.5;
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    for (std::size_t v = 0; v < cameras.size(); ++v) {
      const Eigen::Vector2d at = cameras[v].project(centre_world_mm + t);
      Eigen::Matrix<double, 2, 3> jacobian;
      for (int a = 0; a < 3; ++a) {
        jacobian.col(a) = (cameras[v].project(centre_world_mm + t + kStep_mm * Eigen::Vector3d::Unit(a)) - at) / kStep_mm;
      }
      normal += jacobian.transpose() * jacobian;
      gradient += jacobian.transpose() * (targets[v] - at);
    }
    const double damping = 1e-3 * normal.trace() / 3.0 + 1e-12;
    const Eigen::Vector3d step = (normal + damping * Eigen::Matrix3d::Identity()).ldlt().solve(gradient);
    if (!step.allFinite()) break;
    t += step;
    if (step.norm() < 0.01) break;
  }
  return t;
}

}  // namespace

Result<ShiftAlignment> ProjectionShiftAligner::align(RegistrationCase& registrationCase,
                                                     const Eigen::Isometry3d& T_world_from_ct, int level,
                                                     double maxShiftFraction, double minPeakCorrelation,
                                                     int coarsening) {
  if (level < 0 || level >= registrationCase.levelCount()) {
    return fail(fmt::format("shift alignment level {} is not one of the pyramid's levels 0 to {}", level,
                            registrationCase.levelCount() - 1));
  }
  if (!(maxShiftFraction > 0.0 && maxShiftFraction <= 1.0)) {
    return fail(fmt::format("shift alignment range must be a fraction of the image in (0, 1], got {}", maxShiftFraction));
  }
  if (coarsening < 0 || coarsening > 3) {
    return fail(fmt::format("shift alignment coarsening must be 0 to 3 halvings, got {}", coarsening));
  }
  ShiftAlignment out;
  out.T_world_from_ct = T_world_from_ct;
  const Eigen::Vector3d centre_world_mm = T_world_from_ct * registrationCase.rotationCentre_ct_mm();
  const int matchLevel = level + coarsening;
  const double levelScale = std::ldexp(1.0, matchLevel);
  std::vector<Camera> cameras;
  std::vector<Eigen::Vector2d> targets;
  for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) {
    const PyramidLevel& xray = registrationCase.prepared(v).pyramid.level(level);
    FloatImage coarseImage;
    ValidMask coarseMask;
    for (int k = 0; k < coarsening; ++k) {
      coarseImage = XrayPyramid::downsampleByTwo(k == 0 ? xray.image : coarseImage);
      coarseMask = XrayPyramid::downsampleByTwo(k == 0 ? xray.mask : coarseMask);
    }
    const FloatImage& xrayImage = coarsening > 0 ? coarseImage : xray.image;
    const ValidMask& xrayMask = coarsening > 0 ? coarseMask : xray.mask;
    auto renderer = registrationCase.levelRenderer(v, level, T_world_from_ct, 1 << coarsening);
    if (!renderer) return fail(fmt::format("view '{}': {}", registrationCase.viewName(v), renderer.error()));
    const Eigen::Vector2i pad(static_cast<int>(std::ceil(maxShiftFraction * xrayImage.cols)),
                              static_cast<int>(std::ceil(maxShiftFraction * xrayImage.rows)));
    auto camera = grownDetector(registrationCase.camera(v), pad, matchLevel);
    if (!camera) return fail(fmt::format("view '{}': {}", registrationCase.viewName(v), camera.error()));
    auto drr = renderer.value()->render(camera.value(), T_world_from_ct, matchLevel);
    if (!drr) return fail(fmt::format("view '{}': {}", registrationCase.viewName(v), drr.error()));
    if (drr.value().cols != xrayImage.cols + 2 * pad.x() || drr.value().rows != xrayImage.rows + 2 * pad.y()) {
      return fail(fmt::format("view '{}': the {}x{} DRR of the grown detector does not frame its {}x{} X-ray",
                              registrationCase.viewName(v), drr.value().cols, drr.value().rows, xrayImage.cols,
                              xrayImage.rows));
    }
    const std::optional<LevelShift> shift = bestShift(drr.value(), pad, xrayImage, xrayMask);
    out.shift_px.push_back(shift ? Eigen::Vector2d(levelScale * shift->shift_px) : Eigen::Vector2d::Zero());
    out.peakCorrelation.push_back(shift ? shift->correlation : 0.0);
    if (!shift || shift->correlation < minPeakCorrelation) continue;
    cameras.push_back(registrationCase.camera(v));
    targets.push_back(registrationCase.camera(v).project(centre_world_mm) + out.shift_px.back());
  }
  if (cameras.empty()) return out;
  out.translation_world_mm = triangulateTranslation(cameras, targets, centre_world_mm);
  out.T_world_from_ct = Eigen::Translation3d(out.translation_world_mm) * T_world_from_ct;
  return out;
}

}  // namespace fct
