#pragma once
// RegistrationCase: everything about one registration problem that is computed once and reused by every stage and
// every pose: the CT prepared for DRRs and its renderer, each view's prepared X-ray (masks, line integrals, pyramid
// with exact cameras), the dynamic-ROI statistics per view, level and window size (selections are then instant),
// and the bone's centre (the rotation centre of the pose parameters) and radius (the parameter scales).

#include <Eigen/Geometry>

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "BoneSurface.h"
#include "Camera.h"
#include "DrrRenderer.h"
#include "DrrRendererFactory.h"
#include "DynamicRoiSelector.h"
#include "PixelCircle.h"
#include "PoseOptimizer.h"
#include "Result.h"
#include "Volume.h"
#include "XrayImage.h"
#include "XrayPreparation.h"

namespace fct {

/// One view as registration takes it: the X-ray intensities (MONOCHROME2 sense), its calibrated camera (same
/// detector size) and the calibration-sphere shadows to exclude (level-0 pixels).
struct RegistrationView {
  std::string name;
  XrayImage xray;
  Camera camera;
  std::vector<PixelCircle> spheres;
};

/// How a case is prepared.
struct RegistrationCaseOptions {
  DrrRendererOptions drr;                  ///< DRR method ("siddon", "raycast", ...)
  XrayPreparationOptions preparation;      ///< masks, intensity model, pyramid levels (spheres come per view)
  double boneThreshold_hu = 250.0;         ///< iso-value of the bone surface giving the rotation centre and radius
};

/// A prepared registration problem: CT, renderer and views.
class RegistrationCase {
 public:
  /// Prepares the CT and every view. Fails, naming the view, on no view, a camera whose detector differs from its
  /// image, a failed X-ray preparation, or an X-ray constant over its valid pixels (nothing to register against).
  /// A CT without bone above the threshold uses the volume centre and a quarter of its diagonal (with a warning).
  static Result<RegistrationCase> create(const Volume& ct, const std::vector<RegistrationView>& views,
                                         const RegistrationCaseOptions& options = {});

  /// The DRR renderer of the CT.
  const DrrRenderer& renderer() const { return *m_renderer; }
  /// Number of views.
  std::size_t viewCount() const { return m_views.size(); }
  /// Name of view v.
  const std::string& viewName(std::size_t v) const { return m_views[v].name; }
  /// The prepared X-ray of view v (pyramid levels with images, masks and cameras).
  const PreparedXray& prepared(std::size_t v) const { return m_views[v].prepared; }
  /// The full-resolution camera of view v.
  const Camera& camera(std::size_t v) const { return m_views[v].camera; }
  /// Number of pyramid levels of every view.
  int levelCount() const { return m_views.front().prepared.pyramid.levelCount(); }

  /// The bone iso-surface of the CT, if the CT has bone above the threshold.
  const std::optional<BoneSurface>& bone() const { return m_bone; }
  /// Rotation centre of the pose parameters, CT frame (LPS mm): the bone surface's centroid.
  const Eigen::Vector3d& rotationCentre_ct_mm() const { return m_centre_ct_mm; }
  /// Bone radius in mm used for the parameter scales.
  double boneRadius_mm() const { return m_boneRadius_mm; }
  /// Parameter scales (deg, mm per scaled unit) for the bone radius (PoseOptimizer::scalesForBoneRadius).
  const PoseVector& scales() const { return m_scales; }

  /// Dynamic ROIs of view v at `level`: the highest-variance windowSize^2 windows covering `targetFraction` of the
  /// valid pixels (see DynamicRoiSelector). Window statistics are computed on first use and kept. Fails, naming the
  /// view and level, on a bad level, window or fraction, or when no complete valid window exists.
  Result<RoiSelection> rois(std::size_t v, int level, int windowSize, double targetFraction);
  /// Every complete valid windowSize^2 window of view v at `level` (VLNC without dynamic ROIs); fails as rois().
  Result<RoiSelection> allWindows(std::size_t v, int level, int windowSize);

  /// Checks that the CT at `T_world_from_ct` projects onto the valid pixels of every view at `level`: fails, naming
  /// the view, when the DRR is empty (zero) over all of them, i.e. the DRR and the X-ray do not overlap.
  Status checkOverlap(const Eigen::Isometry3d& T_world_from_ct, int level) const;

  /// T_world_from_ct of pose parameters about rotationCentre_ct_mm().
  Eigen::Isometry3d poseTransform(const PoseVector& params) const;

 private:
  struct View {
    std::string name;
    Camera camera;
    PreparedXray prepared;
    std::map<std::pair<int, int>, DynamicRoiSelector> selectors;  ///< by (level, window size)
  };
  /// The ROI statistics of view v at (level, window), computed on first use.
  Result<const DynamicRoiSelector*> selector(std::size_t v, int level, int windowSize);

  std::shared_ptr<const DrrVolume> m_drrVolume;
  std::shared_ptr<const DrrRenderer> m_renderer;
  std::vector<View> m_views;
  std::optional<BoneSurface> m_bone;
  Eigen::Vector3d m_centre_ct_mm = Eigen::Vector3d::Zero();
  double m_boneRadius_mm = 0.0;
  PoseVector m_scales = PoseVector::Ones();
};

}  // namespace fct
