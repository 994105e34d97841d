#include "Drr/DrrRenderer.h"

#include <fmt/core.h>

#include <cmath>

#include "Geometry/RigidPose.h"

namespace fct {

DrrRenderer::DrrRenderer(std::shared_ptr<const DrrVolume> volume) : m_volume(std::move(volume)) {}

Result<Camera> DrrRenderer::levelCamera(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                                        int level) const {
  const Result<Camera> checked = Camera::create(camera.intrinsics(), camera.T_world_from_camera());
  if (!checked.ok()) return fail("cannot render a DRR for this view: " + checked.error());
  const Result<Eigen::Isometry3d> pose = RigidPose::validated(T_world_from_ct.matrix(), "T_world_from_ct");
  if (!pose.ok()) return fail("cannot render a DRR at this pose: " + pose.error());
  if (level < 0 || level > 16) return fail(fmt::format("pyramid level must be between 0 and 16, got {}", level));
  Camera scaled = camera.downsampled(level);
  if (scaled.intrinsics().cols <= 0 || scaled.intrinsics().rows <= 0) {
    return fail(fmt::format("pyramid level {} leaves no pixels of the {} x {} detector; use a lower level", level,
                            camera.intrinsics().cols, camera.intrinsics().rows));
  }
  return scaled;
}

Status DrrRenderer::render(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level,
                           FloatImage& image, DrrRenderStats* stats) const {
  const Result<Camera> scaled = levelCamera(camera, T_world_from_ct, level);
  if (!scaled.ok()) return fail(scaled.error());
  const CameraIntrinsics& in = scaled.value().intrinsics();
  image.cols = in.cols;
  image.rows = in.rows;
  image.pixels.resize(static_cast<std::size_t>(in.cols) * in.rows);
  const DrrRenderStats done =
      integratePixels(scaled.value(), T_world_from_ct, nullptr, image.pixels.size(), image.pixels.data());
  if (stats) *stats = done;
  return Ok{};
}

Result<FloatImage> DrrRenderer::render(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level,
                                       DrrRenderStats* stats) const {
  FloatImage image;
  const Status status = render(camera, T_world_from_ct, level, image, stats);
  if (!status.ok()) return fail(status.error());
  return image;
}

Status DrrRenderer::renderPixels(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, int level,
                                 const PixelIndexList& pixels, std::vector<float>& values,
                                 DrrRenderStats* stats) const {
  const Result<Camera> scaled = levelCamera(camera, T_world_from_ct, level);
  if (!scaled.ok()) return fail(scaled.error());
  const CameraIntrinsics& in = scaled.value().intrinsics();
  const std::int64_t pixelCount = static_cast<std::int64_t>(in.cols) * in.rows;
  for (std::size_t n = 0; n < pixels.size(); ++n) {
    if (pixels[n] < 0 || pixels[n] >= pixelCount) {
      return fail(fmt::format("pixel list entry {} is {}, outside the {} x {} detector of level {} (valid 0..{})", n,
                              pixels[n], in.cols, in.rows, level, pixelCount - 1));
    }
  }
  values.resize(pixels.size());
  DrrRenderStats done;
  if (!pixels.empty()) done = integratePixels(scaled.value(), T_world_from_ct, pixels.data(), pixels.size(), values.data());
  if (stats) *stats = done;
  return Ok{};
}

Result<std::vector<float>> DrrRenderer::renderPixels(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                                                     int level, const PixelIndexList& pixels,
                                                     DrrRenderStats* stats) const {
  std::vector<float> values;
  const Status status = renderPixels(camera, T_world_from_ct, level, pixels, values, stats);
  if (!status.ok()) return fail(status.error());
  return values;
}

}  // namespace fct
