#pragma once
// RegistrationCase: everything about one registration problem that is computed once and reused by every stage and
// every pose: the CT prepared for DRRs and its renderers, each view's prepared X-ray (masks, line integrals, pyramid
// with exact cameras), the dynamic-ROI statistics per view, level and window size (selections are then instant),
// and the bone's centre (the rotation centre of the pose parameters) and radius (the parameter scales).
//
// Renderers: one per view. For the view-independent methods (siddon, raycast) every view shares the method's renderer.
// For the transgraph method each view gets its own Transgraph (a ray table of that view's detector, valid for poses
// near an expected pose, built or loaded from the disk cache) and the exact renderer is Siddon: it serves rays outside
// a table (counted per render), the overlap check, and runs with the Transgraph switched off (ablation). A table is
// read back at the pixel rays of any pyramid level: it stores rays, not pixels, and covers the full detector's extent.

#include <Eigen/Geometry>

#include <array>
#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "Base/ProgressMonitor.h"
#include "Base/Result.h"
#include "Drr/CutFaceRayMask.h"
#include "Drr/DrrRenderer.h"
#include "Drr/DrrRendererFactory.h"
#include "Drr/TransgraphRenderer.h"
#include "Geometry/Camera.h"
#include "Geometry/PoseVector.h"
#include "Image/BoneSurface.h"
#include "Image/Volume.h"
#include "Image/XrayImage.h"
#include "Registration/RegistrationView.h"
#include "Similarity/DynamicRoiSelector.h"
#include "XrayPrep/XrayPreparation.h"

namespace fct {

/// How a case is prepared.
struct RegistrationCaseOptions {
  DrrRendererOptions drr;                  ///< DRR method ("siddon", "raycast", ...)
  XrayPreparationOptions preparation;      ///< masks, intensity model, pyramid levels (spheres come per view)
  double boneThreshold_hu = 250.0;         ///< iso-value of the bone surface giving the rotation centre and radius
  /// The cut-face margin of a case unless told otherwise, and so of every evaluation study and tracking study (mm):
  /// the simulated patient continues beyond the CT's end faces, as a real one does.
  static constexpr double kDefaultCutFaceMargin_mm = 5.0;
  /// The largest cut-face margin a case takes (mm): beyond it the mask would leave out nearly every ray.
  static constexpr double kMaxCutFaceMargin_mm = 500.0;
  /// Pixels whose rays cross the patient beyond the CT's end faces along its slice axis, or pass within this many mm
  /// of them, at the initial pose, are left out of the comparison (CutFaceRayMask): the X-ray shows anatomy there
  /// that the CT lacks. Negative: off. The mask is made at the initial pose (and again at a stage's start when the
  /// bone moved more than 5 mm from it), so it is as right as that pose; a face with no tissue cuts nothing.
  double cutFaceMargin_mm = kDefaultCutFaceMargin_mm;
  /// The bone contrast of a case unless told otherwise: an 80 kVp fluoroscope against a 120 kVp CT. For ICRU cortical
  /// bone (NIST XCOM), µ_bone / µ_water - 1.1 is 2.5 at 50 keV, about the mean energy of an 80 kVp beam behind a
  /// patient, against 1.5 at 70 keV, a 120 kVp CT's (docs/registration.md, "Bone contrast").
  static constexpr double kDefaultBoneContrast = 1.6;
  /// The attenuation the DRRs give CT values above 100 HU is scaled by this factor (DrrValueOptions::boneContrast), in
  /// (0, 10]: how much more the X-ray's beam sees of bone than the CT's did. 1: the CT's own contrast.
  double boneContrast = kDefaultBoneContrast;
  /// Transgraph method: the pose (CT mm -> world mm, LPS) around which each view's table is built, e.g. the initial
  /// pose from landmarks. nullopt: the tables are built at the initial pose of the first Registration::run.
  std::optional<Eigen::Isometry3d> T_expected_world_from_ct;
};

/// What RegistrationCase::reviewMetalMasks did.
struct MetalReviewSummary {
  int piecesGivenBack = 0;  ///< metal-mask pieces given back as anatomy, all views
  int drrs = 0;             ///< full-resolution DRRs rendered (one per view with metal)
};

/// What RegistrationCase::removeHaze did.
struct HazeRemovalSummary {
  int viewsCorrected = 0;                  ///< views whose X-ray was corrected
  int drrs = 0;                            ///< full-resolution DRRs rendered (one per view)
  double largestHazeFraction = 0.0;        ///< the largest mean share of a view's signal the haze term changed
  double largestHardening = 0.0;           ///< the largest beam hardening b (dmax - dmin) fitted (XrayHazeCorrector)
  std::vector<std::string> viewsKept;      ///< per view left as it was: "view 'NAME': why"
};

/// A prepared registration problem: CT, renderer and views.
class RegistrationCase {
 public:
  /// The error of a preparation that was cancelled (create() with a cancelling monitor, and the Studio's preparation).
  static constexpr const char* kCancelledError = "the case preparation was cancelled";

  /// Prepares the CT and every view, and for the transgraph method with an expected pose each view's table (the
  /// monitor gets one report per step, CT, each view, bone surface, and the table builds, and can cancel between
  /// steps: the error then says the preparation was cancelled). Fails, naming the view, on no view, a camera whose detector differs
  /// from its image, a failed X-ray preparation, an X-ray constant over its valid pixels (nothing to register
  /// against), or a table that cannot be planned or built. A CT without bone above the threshold uses the volume
  /// centre and a quarter of its diagonal (with a warning); Transgraph cache problems are warnings too.
  static Result<RegistrationCase> create(const Volume& ct, const std::vector<RegistrationView>& views,
                                         const RegistrationCaseOptions& options = {},
                                         const ProgressMonitor& monitor = {});

  /// The CT as the DRRs see it: attenuation values with the case's bone contrast, on the CT's grid.
  const DrrVolume& drrVolume() const { return *m_drrVolume; }
  /// The exact DRR renderer shared by all views: the method's renderer, Siddon for the transgraph method.
  const DrrRenderer& renderer() const { return *m_renderer; }
  /// The exact renderer for view v at pyramid `level` with the CT near pose T_world_from_ct: renderer()'s method over
  /// the CT box-averaged to the level's pixel footprint (ctBlockSize()), so coarse levels traverse fewer, larger voxels
  /// and their DRRs carry the blur of their pixels; renderer() itself where the block is one voxel. `pixelStride` > 1:
  /// the rendered pixels are every pixelStride-th column and row of the level, so the footprint is that many pixels.
  /// Coarse CTs are made on first use and kept. Fails on a bad view or level.
  /// `method` (siddon or raycast) replaces renderer()'s method, e.g. for a stage that names its own DRR method, and
  /// `rayCastStep_voxels` > 0 the ray-cast step and `slices` the CT's slice model (see methodRenderer()).
  Result<const DrrRenderer*> levelRenderer(std::size_t v, int level, const Eigen::Isometry3d& T_world_from_ct,
                                           int pixelStride = 1, std::optional<DrrMethod> method = std::nullopt,
                                           double rayCastStep_voxels = 0.0,
                                           CtSliceModel slices = CtSliceModel::Samples);
  /// The exact renderer of the full CT with `method` (siddon or raycast): renderer() when that is its method and
  /// `rayCastStep_voxels` is 0, else made on first use and kept. `rayCastStep_voxels` > 0 sets the ray-cast step to that
  /// many voxels (a voxel: the cube root of the voxel volume); 0 keeps the case's step. `slices` SlabAverages renders
  /// a CT of thick slices (DrrVolume::hasThickSlices; others as samples) with its values deconvolved along them
  /// (DrrVolume::sliceAveragesDeconvolved, made on first use and kept).
  /// Fails for transgraph (built per view, not per method) and for a step outside 0 to 10 voxels.
  Result<const DrrRenderer*> methodRenderer(DrrMethod method, double rayCastStep_voxels = 0.0,
                                            CtSliceModel slices = CtSliceModel::Samples);
  /// The CT voxels per axis that levelRenderer() averages for view v at `level`: floor(pixel footprint / voxel
  /// spacing), at least 1, where the footprint is the level's smaller pixel side scaled to the depth of the rotation
  /// centre at T_world_from_ct (the pixel's size at the bone), times `pixelStride`. v and level must be valid
  /// (levelRenderer checks them).
  Eigen::Vector3i ctBlockSize(std::size_t v, int level, const Eigen::Isometry3d& T_world_from_ct,
                              int pixelStride = 1) const;
  /// The renderer of view v: its Transgraph once built (transgraph method), else renderer().
  const DrrRenderer& renderer(std::size_t v) const { return *m_views[v].renderer; }
  /// The Transgraph renderer of view v, or null (other method, or tables not built yet).
  const TransgraphRenderer* transgraph(std::size_t v) const { return m_views[v].transgraph; }
  /// The DRR method the case was prepared with.
  DrrMethod drrMethod() const { return m_drrOptions.method; }
  /// True when every view has its final renderer (always, except for the transgraph method before its tables exist).
  bool viewRenderersReady() const { return m_viewRenderersReady; }
  /// Transgraph method: builds (or loads from the cache) each view's table around T_expected_world_from_ct, unless
  /// they exist already (then nothing changes: tables are built once per case). Other methods: nothing to do. Fails,
  /// naming the view, when a table cannot be planned or built, or when the monitor cancels; cache problems are
  /// warnings of the result.
  Status prepareViewRenderers(const Eigen::Isometry3d& T_expected_world_from_ct, const ProgressMonitor& monitor = {});
  /// Wall time of the table builds or cache loads of prepareViewRenderers(), seconds (0 for other methods).
  double viewRendererSetupSeconds() const { return m_viewRendererSetup_s; }
  /// Number of views.
  std::size_t viewCount() const { return m_views.size(); }
  /// Name of view v.
  const std::string& viewName(std::size_t v) const { return m_views[v].name; }
  /// The prepared X-ray of view v (pyramid levels with images, masks and cameras).
  const PreparedXray& prepared(std::size_t v) const { return m_views[v].prepared; }
  /// Swaps the X-ray of view v for a new frame of the same detector (e.g. the next frame of a cine sequence): re-runs
  /// only that view's X-ray preparation (same options and spheres) and drops its ROI statistics; the CT, renderers,
  /// Transgraph tables and bone surface stay. Fails, naming the view and leaving it as it was, on a bad index, an
  /// image of another size than the view's detector, a failed preparation, or an X-ray constant over its valid pixels.
  Status replaceXray(std::size_t v, const XrayImage& xray);
  /// Gives back to the comparison the metal-mask pieces of every view that a DRR of the CT at T_world_from_ct (a pose
  /// near the truth, e.g. after the global stage) explains: anatomy the detector took for metal (MetalMaskReview).
  /// A view that changes gets its pyramid rebuilt, its metal fraction updated and its ROI statistics dropped. Returns
  /// the pieces given back (0: nothing changed) and the DRRs rendered (one per view with metal). Fails, naming the view
  /// and leaving it as it was, when its DRR cannot be rendered or the review fails.
  Result<MetalReviewSummary> reviewMetalMasks(const Eigen::Isometry3d& T_world_from_ct);
  /// Removes a smooth haze (scatter, glare) and gain from every view's X-ray (XrayHazeCorrector) with a DRR of the CT
  /// at T_world_from_ct (a pose near the truth, e.g. after the global stage), fitted over the valid pixels clear of the
  /// CT's cut faces; `hazeSigma_mm` is the haze's smoothness on the detector (Gaussian sigma, mm). A corrected view gets
  /// its pyramid rebuilt and its ROI statistics dropped. The correction is made from the X-ray as prepared, so a second
  /// call replaces the first; restorePreparedXrays() undoes it. A view whose fit fails (a pose far off) keeps its
  /// X-ray and is named in the summary. Fails, naming the view, when a DRR cannot be rendered or a pyramid rebuilt.
  Result<HazeRemovalSummary> removeHaze(const Eigen::Isometry3d& T_world_from_ct, double hazeSigma_mm);
  /// Renders a DRR of every view at T_world_from_ct (a pose near the truth; the case's renderer, full resolution) whose
  /// window variances weigh the views' VLNC windows from now on (windowWeightImage), the X-ray's own variances counting
  /// its noise too. A second call replaces the first; restorePreparedXrays() drops them. Returns the DRRs rendered.
  /// Fails, naming the view and leaving every view as it was, when a DRR cannot be rendered or its pyramid built.
  /// At the pose of a removeHaze() just before, it uses that call's DRRs (0 rendered).
  Result<int> weighWindowsWithDrr(const Eigen::Isometry3d& T_world_from_ct);
  /// View v's image at pyramid `level` whose window variances weigh its VLNC windows (weighWindowsWithDrr), or null
  /// when the X-ray's own do.
  const FloatImage* windowWeightImage(std::size_t v, int level) const;
  /// Gives every view corrected by removeHaze() its X-ray as prepared back (its current masks kept) and drops the DRRs
  /// of weighWindowsWithDrr(); nothing to do when there are none. Fails, naming the view, when a pyramid cannot be
  /// rebuilt.
  Status restorePreparedXrays();
  /// Rays passing within this distance of the CT's cut faces (mm) are not used by the haze fit: beyond them the X-ray
  /// shows anatomy the DRR lacks.
  static constexpr double kHazeFitCutFaceMargin_mm = 5.0;
  /// Rays passing within this distance of the CT's cut faces (mm) are not judged by the metal review: beyond them the
  /// X-ray shows anatomy the DRR lacks.
  static constexpr double kMetalReviewCutFaceMargin_mm = 5.0;
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

  /// The CutFaceRayMask of view v at `level` with the CT at T_world_from_ct and the case's cut-face margin; every
  /// pixel valid when the margin is negative (off). Fails on a bad view or level, or a view without a level camera.
  Result<ValidMask> cutFaceMask(std::size_t v, int level, const Eigen::Isometry3d& T_world_from_ct) const;

  /// The fraction of view v's field pixels (level 0, before the metal exclusion) whose rays clear the CT's cut faces
  /// with the CT at `T_world_from_ct` (LPS mm; the case's margin, every field pixel when it is off) that the metal mask
  /// excludes: what the mask takes from the pixels a comparison can use. 0 when no field pixel clears the cut faces.
  /// Fails on a bad view.
  Result<double> metalFractionOfCoveredField(std::size_t v, const Eigen::Isometry3d& T_world_from_ct) const;

  /// Checks that the CT at `T_world_from_ct` projects onto the valid pixels of every view at `level`: fails, naming
  /// the view, when the DRR is empty (zero) over all of them, i.e. the DRR and the X-ray do not overlap.
  Status checkOverlap(const Eigen::Isometry3d& T_world_from_ct, int level) const;

  /// T_world_from_ct of pose parameters about rotationCentre_ct_mm().
  Eigen::Isometry3d poseTransform(const PoseVector& params) const;

 private:
  struct View {
    std::string name;
    Camera camera;
    XrayPreparationOptions preparation;  ///< the case's options with the view's spheres
    PreparedXray prepared;
    std::optional<FloatImage> preparedImage;  ///< level 0 as prepared while removeHaze() has replaced it
    std::map<std::pair<int, int>, DynamicRoiSelector> selectors;  ///< by (level, window size)
    std::shared_ptr<const DrrRenderer> renderer;                  ///< the view's renderer (see renderer(v))
    const TransgraphRenderer* transgraph = nullptr;               ///< the same renderer when it is a Transgraph
    std::optional<XrayPyramid> windowWeights;  ///< the DRR pyramid of weighWindowsWithDrr(), if any
  };
  /// Prepares `xray` for the view `name` with `camera`: the preparation, and the checks of its size and contrast.
  /// Fails naming the view.
  static Result<PreparedXray> prepareXray(const std::string& name, const Camera& camera, XrayImage xray,
                                          const XrayPreparationOptions& preparation);
  /// Fails, naming the view, unless v is a view index and level one of its pyramid levels.
  Status checkViewLevel(std::size_t v, int level) const;
  /// The ROI statistics of view v at (level, window), computed on first use.
  Result<const DynamicRoiSelector*> selector(std::size_t v, int level, int windowSize);
  /// The full-resolution DRR of every view at T_world_from_ct (the case's exact renderer, views in parallel), or the
  /// previous call's when T_world_from_ct is the same pose: a stage's haze removal and DRR window weights share them.
  /// `rendered` gets the DRRs rendered (0 when kept). The pointer holds until the next call. Fails naming the view.
  Result<const std::vector<FloatImage>*> fullResolutionDrrs(const Eigen::Isometry3d& T_world_from_ct, int& rendered);

  std::shared_ptr<const DrrVolume> m_drrVolume;
  std::shared_ptr<const DrrVolume> m_sliceAveragesVolume;  ///< m_drrVolume deconvolved along k, made on first use
  std::shared_ptr<const DrrRenderer> m_renderer;
  /// What identifies a kept renderer: method, CT block size (the full CT: 1, 1, 1) and ray-cast step in voxels (0: the
  /// case's step).
  using RendererKey = std::tuple<DrrMethod, std::array<int, 3>, double, CtSliceModel>;
  /// The renderer of `method` over the CT (its slices read as `slices`) averaged in blocks of `block` voxels, made on
  /// first use and kept.
  Result<const DrrRenderer*> keptRenderer(DrrMethod method, const Eigen::Vector3i& block, double rayCastStep_voxels,
                                          CtSliceModel slices);
  /// The slice model the case renders for `requested`: slab averages only for a CT of thick slices
  /// (DrrVolume::hasThickSlices), samples otherwise.
  CtSliceModel sliceModelFor(CtSliceModel requested) const {
    return m_drrVolume->hasThickSlices() ? requested : CtSliceModel::Samples;
  }

  std::map<RendererKey, std::shared_ptr<const DrrRenderer>> m_keptRenderers;
  DrrRendererOptions m_drrOptions;
  bool m_viewRenderersReady = true;
  std::optional<CutFaceRayMask> m_cutFaces;  ///< the CT's cut faces with the margin; none when it is off
  double m_viewRendererSetup_s = 0.0;
  std::vector<View> m_views;
  std::optional<Eigen::Isometry3d> m_fullDrrPose;  ///< the pose of m_fullDrrs (fullResolutionDrrs)
  std::vector<FloatImage> m_fullDrrs;              ///< every view's full-resolution DRR at m_fullDrrPose
  std::optional<BoneSurface> m_bone;
  Eigen::Vector3d m_centre_ct_mm = Eigen::Vector3d::Zero();
  double m_boneRadius_mm = 0.0;
  PoseVector m_scales = PoseVector::Ones();
};

}  // namespace fct
