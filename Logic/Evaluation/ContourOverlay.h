#pragma once
// ContourOverlay: the projected bone outlines of a CT at one or two poses drawn over an X-ray (like Fig. 2 of Knaan &
// Joskowicz 2003), to judge a registration by eye. The outline is that of the bone's DRR: a renderer integrates a
// 0/1 bone mask ({HU >= threshold}) along each ray, giving the bone path length in mm per pixel; its contours at a
// level of half a voxel are the projected bone outlines (outer silhouette and holes, e.g. foramina).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "Base/Result.h"
#include "Drr/DrrRenderer.h"
#include "Geometry/Camera.h"
#include "Image/RgbImage.h"
#include "Image/Volume.h"
#include "Image/XrayImage.h"

namespace fct {

/// One closed outline on the detector: pixel positions (col,row) in order.
using PixelContour = std::vector<Eigen::Vector2i>;

/// Projects a CT's bone outline and draws it over X-ray images.
class ContourOverlay {
 public:
  /// Colour of outlines at the initial pose (orange-red) and at the final pose (green), RGB.
  static constexpr std::array<std::uint8_t, 3> kInitialColour{255, 70, 40};
  static constexpr std::array<std::uint8_t, 3> kFinalColour{40, 235, 90};

  /// Prepares the bone mask {HU >= boneThreshold_hu} of `ct` for projection. Fails on an empty CT, a non-finite
  /// threshold, or no voxel at or above it (the message gives the CT's value range).
  static Result<ContourOverlay> create(const Volume& ct, double boneThreshold_hu = 250.0);

  /// Bone path length in mm per pixel of camera's detector at pose T_world_from_ct (CT LPS mm -> world LPS mm);
  /// 0 where a ray misses the bone. Fails on an invalid camera or pose.
  Result<FloatImage> bonePathLength_mm(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct) const;

  /// The projected bone outlines at pose T_world_from_ct on camera's detector; empty (not an error) when the bone
  /// is out of view. Fails on an invalid camera or pose.
  Result<std::vector<PixelContour>> contours(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct) const;

  /// The X-ray as a contrast-enhanced grey background (robust window, then local histogram equalization) with the
  /// outlines at `initial` in kInitialColour and at `final` in kFinalColour (drawn on top) and a small legend.
  /// The X-ray's size must equal the camera's detector. Fails on a size mismatch, an empty image, or a DRR error.
  Result<RgbImage> render(const XrayImage& xray, const Camera& camera, const Eigen::Isometry3d& T_world_from_ct_initial,
                          const Eigen::Isometry3d& T_world_from_ct_final) const;

  /// render() written as an 8-bit RGB PNG to `path` (atomically). Fails as render() or on an unwritable path.
  Status writeOverlayPng(const XrayImage& xray, const Camera& camera, const Eigen::Isometry3d& T_world_from_ct_initial,
                         const Eigen::Isometry3d& T_world_from_ct_final, const std::filesystem::path& path) const;

 private:
  ContourOverlay() = default;

  std::shared_ptr<const DrrRenderer> m_renderer;  ///< integrates the 0/1 bone mask (raw values, so path length in mm)
  double m_outlineLevel_mm = 0.5;                 ///< path length at which the outline is drawn: half a voxel
};

}  // namespace fct
