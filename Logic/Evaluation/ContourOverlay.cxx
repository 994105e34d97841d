#include "Evaluation/ContourOverlay.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "Drr/DrrRendererFactory.h"
#include "Drr/DrrVolume.h"
#include "IO/Xray/ImageFileWriter.h"

namespace fct {

namespace {

/// Outlines with fewer points than this are specks (a voxel grazed by a ray) and are not drawn.
constexpr std::size_t kMinContourPoints = 6;

/// The X-ray as an 8-bit grey image: window 0.5..99.5 percentile (inside the field of view when known), then CLAHE.
cv::Mat displayGrey(const XrayImage& xray) {
  std::vector<float> values;
  values.reserve(xray.pixels.size());
  for (std::size_t n = 0; n < xray.pixels.size(); ++n) {
    if (std::isfinite(xray.pixels[n]) && (xray.fovMask.empty() || xray.fovMask[n] != 0)) values.push_back(xray.pixels[n]);
  }
  float lo = 0.0f, hi = 1.0f;
  if (!values.empty()) {
    const auto quantile = [&](double q) {
      auto it = values.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
      std::nth_element(values.begin(), it, values.end());
      return *it;
    };
    lo = quantile(0.005);
    hi = quantile(0.995);
    if (!(hi > lo)) hi = lo + 1.0f;
  }
  cv::Mat windowed(xray.rows, xray.cols, CV_16U);
  const float scale = 65535.0f / (hi - lo);
  for (int r = 0; r < xray.rows; ++r) {
    auto* out = windowed.ptr<std::uint16_t>(r);
    for (int c = 0; c < xray.cols; ++c) {
      const float v = xray.at(c, r);
      out[c] = std::isfinite(v) ? static_cast<std::uint16_t>(std::clamp((v - lo) * scale, 0.0f, 65535.0f)) : 0;
    }
  }
  cv::Mat equalized, grey;
  cv::createCLAHE(2.0, cv::Size(8, 8))->apply(windowed, equalized);
  equalized.convertTo(grey, CV_8U, 1.0 / 257.0);
  return grey;
}

cv::Scalar scalar(const std::array<std::uint8_t, 3>& rgb) { return cv::Scalar(rgb[0], rgb[1], rgb[2]); }

void drawContours(cv::Mat& rgb, const std::vector<PixelContour>& contours, const std::array<std::uint8_t, 3>& colour,
                  int thickness) {
  std::vector<std::vector<cv::Point>> polylines;
  for (const PixelContour& contour : contours) {
    std::vector<cv::Point> points;
    points.reserve(contour.size());
    for (const Eigen::Vector2i& p : contour) points.emplace_back(p.x(), p.y());
    polylines.push_back(std::move(points));
  }
  cv::polylines(rgb, polylines, true, scalar(colour), thickness, cv::LINE_AA);
}

/// A legend box in the top-left corner: a dark translucent panel with a coloured line per label.
void drawLegend(cv::Mat& rgb, int thickness) {
  const double fontScale = std::clamp(rgb.rows / 1200.0, 0.3, 1.0);
  const int line = static_cast<int>(std::lround(26 * fontScale / 0.6));
  const int pad = line / 3, swatch = 2 * line;
  int baseline = 0;
  const cv::Size text = cv::getTextSize("initial", cv::FONT_HERSHEY_SIMPLEX, fontScale, 1, &baseline);
  const cv::Rect panel(pad, pad, std::min(rgb.cols - pad, 3 * pad + swatch + text.width + pad),
                       std::min(rgb.rows - pad, 2 * line + 2 * pad));
  if (panel.width <= 0 || panel.height <= 0) return;
  cv::Mat roi = rgb(panel);
  roi.convertTo(roi, -1, 0.35, 0.0);
  const std::array<std::pair<const char*, std::array<std::uint8_t, 3>>, 2> entries{
      {{"initial", ContourOverlay::kInitialColour}, {"final", ContourOverlay::kFinalColour}}};
  for (std::size_t n = 0; n < entries.size(); ++n) {
    const int y = panel.y + pad + static_cast<int>(n) * line + line / 2;
    cv::line(rgb, {panel.x + pad, y}, {panel.x + pad + swatch, y}, scalar(entries[n].second), thickness, cv::LINE_AA);
    cv::putText(rgb, entries[n].first, {panel.x + 2 * pad + swatch, y + text.height / 2}, cv::FONT_HERSHEY_SIMPLEX,
                fontScale, cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  }
}

}  // namespace

Result<ContourOverlay> ContourOverlay::create(const Volume& ct, double boneThreshold_hu) {
  if (ct.voxelCount() == 0) return fail("cannot draw bone outlines of an empty CT volume");
  if (!std::isfinite(boneThreshold_hu)) return fail("bone threshold must be a finite HU value");
  auto mask = Volume::create(ct.dims(), ct.spacing_mm(), ct.origin_lps_mm(), ct.direction_lps(), 0.0f);
  if (!mask.ok()) return fail(mask.error());
  const float threshold = static_cast<float>(boneThreshold_hu);
  std::size_t boneVoxels = 0;
  std::vector<float>& out = mask.value().voxels();
  const std::vector<float>& in = ct.voxels();
  for (std::size_t n = 0; n < in.size(); ++n) {
    if (in[n] >= threshold) {
      out[n] = 1.0f;
      ++boneVoxels;
    }
  }
  if (boneVoxels == 0) {
    const auto [lo, hi] = ct.valueRange();
    return fail(fmt::format("no CT voxel reaches the bone threshold {:g} HU (the CT's values span {:g}..{:g}); "
                            "lower the bone threshold or check that the CT is in Hounsfield units",
                            boneThreshold_hu, lo, hi));
  }
  DrrValueOptions valueOptions;
  valueOptions.kind = DrrValueKind::Raw;
  auto drrVolume = DrrVolume::create(mask.value(), valueOptions);
  if (!drrVolume.ok()) return fail(drrVolume.error());
  auto renderer = DrrRendererFactory::create(std::make_shared<const DrrVolume>(std::move(drrVolume).value()));
  if (!renderer.ok()) return fail(renderer.error());
  ContourOverlay overlay;
  overlay.m_renderer = std::move(renderer).value();
  overlay.m_outlineLevel_mm = 0.5 * ct.spacing_mm().minCoeff();
  return overlay;
}

Result<FloatImage> ContourOverlay::bonePathLength_mm(const Camera& camera,
                                                     const Eigen::Isometry3d& T_world_from_ct) const {
  return m_renderer->render(camera, T_world_from_ct, 0);
}

Result<std::vector<PixelContour>> ContourOverlay::contours(const Camera& camera,
                                                           const Eigen::Isometry3d& T_world_from_ct) const {
  auto pathLength = bonePathLength_mm(camera, T_world_from_ct);
  if (!pathLength.ok()) return fail(pathLength.error());
  const FloatImage& L = pathLength.value();
  cv::Mat inside(L.rows, L.cols, CV_8U);
  for (int r = 0; r < L.rows; ++r) {
    auto* row = inside.ptr<std::uint8_t>(r);
    for (int c = 0; c < L.cols; ++c) row[c] = L.at(c, r) > m_outlineLevel_mm ? 255 : 0;
  }
  std::vector<std::vector<cv::Point>> found;
  cv::findContours(inside, found, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  std::vector<PixelContour> result;
  for (const auto& contour : found) {
    if (contour.size() < kMinContourPoints) continue;
    PixelContour pixels;
    pixels.reserve(contour.size());
    for (const cv::Point& p : contour) pixels.emplace_back(p.x, p.y);
    result.push_back(std::move(pixels));
  }
  return result;
}

Result<RgbImage> ContourOverlay::render(const XrayImage& xray, const Camera& camera,
                                        const Eigen::Isometry3d& T_world_from_ct_initial,
                                        const Eigen::Isometry3d& T_world_from_ct_final) const {
  const CameraIntrinsics& detector = camera.intrinsics();
  if (xray.cols <= 0 || xray.rows <= 0 || xray.pixels.size() != static_cast<std::size_t>(xray.cols) * xray.rows) {
    return fail("cannot draw an overlay on an empty or inconsistent X-ray image");
  }
  if (xray.cols != detector.cols || xray.rows != detector.rows) {
    return fail(fmt::format("X-ray is {} x {} pixels but the camera's detector is {} x {}; use the view's own camera",
                            xray.cols, xray.rows, detector.cols, detector.rows));
  }
  auto initial = contours(camera, T_world_from_ct_initial);
  if (!initial.ok()) return fail(fmt::format("initial pose: {}", initial.error()));
  auto final = contours(camera, T_world_from_ct_final);
  if (!final.ok()) return fail(fmt::format("final pose: {}", final.error()));

  try {
    cv::Mat rgb;
    cv::cvtColor(displayGrey(xray), rgb, cv::COLOR_GRAY2RGB);
    const int thickness = std::max(1, static_cast<int>(std::lround(std::min(xray.cols, xray.rows) / 320.0)));
    drawContours(rgb, initial.value(), kInitialColour, thickness);
    drawContours(rgb, final.value(), kFinalColour, thickness);
    drawLegend(rgb, thickness + 1);
    RgbImage image;
    image.cols = rgb.cols;
    image.rows = rgb.rows;
    image.pixels.assign(rgb.data, rgb.data + rgb.total() * 3);
    return image;
  } catch (const cv::Exception& e) {
    return fail(fmt::format("drawing the overlay failed: {}", e.what()));
  }
}

Status ContourOverlay::writeOverlayPng(const XrayImage& xray, const Camera& camera,
                                       const Eigen::Isometry3d& T_world_from_ct_initial,
                                       const Eigen::Isometry3d& T_world_from_ct_final,
                                       const std::filesystem::path& path) const {
  auto image = render(xray, camera, T_world_from_ct_initial, T_world_from_ct_final);
  if (!image.ok()) return fail(image.error());
  return ImageFileWriter::writePngRgb(image.value(), path);
}

}  // namespace fct
