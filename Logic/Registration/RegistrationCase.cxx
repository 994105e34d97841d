#include "Registration/RegistrationCase.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "Drr/CutFaceRayMask.h"
#include "Geometry/RigidPose.h"
#include "Search/PoseOptimizer.h"
#include "XrayPrep/MetalMaskReview.h"
#include "XrayPrep/XrayHazeCorrector.h"

namespace fct {

namespace {

/// The options of the exact renderer: the method's own, or Siddon under the per-view Transgraphs.
DrrRendererOptions exactRendererOptions(DrrRendererOptions options) {
  if (options.method == DrrMethod::Transgraph) options.method = DrrMethod::Siddon;
  return options;
}

}  // namespace

Result<RegistrationCase> RegistrationCase::create(const Volume& ct, const std::vector<RegistrationView>& views,
                                                  const RegistrationCaseOptions& options,
                                                  const ProgressMonitor& monitor) {
  if (views.empty()) return fail("registration needs at least one X-ray view; the view list is empty");
  RegistrationCase result;
  // One report per step (the CT, each view, the bone surface); a cancel between steps stops the preparation.
  const double steps = static_cast<double>(views.size() + 2);
  const auto cancelled = [&] { return monitor.cancelled(); };
  monitor.report("CT", 0.0, "preparing the CT for DRRs");

  DrrValueOptions values;
  values.boneContrast = options.boneContrast;
  auto drrVolume = DrrVolume::create(ct, values);
  if (!drrVolume) return fail("CT: " + drrVolume.error());
  result.m_drrVolume = std::make_shared<const DrrVolume>(std::move(drrVolume).value());
  result.m_drrOptions = options.drr;
  auto renderer = DrrRendererFactory::create(result.m_drrVolume, exactRendererOptions(options.drr));
  if (!renderer) return fail(renderer.error());
  result.m_renderer = std::move(renderer).value();
  result.m_viewRenderersReady = options.drr.method != DrrMethod::Transgraph;
  if (!(options.cutFaceMargin_mm <= RegistrationCaseOptions::kMaxCutFaceMargin_mm)) {  // also NaN
    return fail(fmt::format("cut-face margin must be at most {} mm (negative: off), got {}",
                            RegistrationCaseOptions::kMaxCutFaceMargin_mm, options.cutFaceMargin_mm));
  }
  if (options.cutFaceMargin_mm >= 0.0) {
    auto cutFaces = CutFaceRayMask::create(*result.m_drrVolume, options.cutFaceMargin_mm);
    if (!cutFaces) return fail(cutFaces.error());
    result.m_cutFaces = std::move(cutFaces).value();
  }

  for (std::size_t v = 0; v < views.size(); ++v) {
    const RegistrationView& view = views[v];
    if (cancelled()) return fail(kCancelledError);
    monitor.report("views", static_cast<double>(v + 1) / steps, fmt::format("preparing the X-ray of view '{}'", view.name));
    XrayPreparationOptions preparation = options.preparation;
    preparation.spheres.insert(preparation.spheres.end(), view.spheres.begin(), view.spheres.end());
    auto prepared = prepareXray(view.name, view.camera, view.xray, preparation);
    if (!prepared) return fail(prepared.error());
    result.m_views.push_back(
        View{view.name, view.camera, std::move(preparation), std::move(prepared).value(), std::nullopt, {},
             result.m_renderer, nullptr, std::nullopt});
  }

  if (cancelled()) return fail(kCancelledError);
  monitor.report("bone", static_cast<double>(views.size() + 1) / steps, "extracting the bone surface");
  auto bone = BoneSurface::extract(ct, options.boneThreshold_hu);
  if (bone) {
    result.m_centre_ct_mm = bone.value().centroid_ct_mm();
    result.m_boneRadius_mm = bone.value().radius_mm();
    result.m_bone = std::move(bone).value();
  } else {
    const Eigen::Vector3d extent_mm = ct.dims().cast<double>().cwiseProduct(ct.spacing_mm());
    result.m_centre_ct_mm = ct.centre_lps_mm();
    result.m_boneRadius_mm = 0.25 * extent_mm.norm();
  }
  auto scales = PoseOptimizer::scalesForBoneRadius(result.m_boneRadius_mm);
  if (!scales) return fail("bone radius: " + scales.error());
  result.m_scales = scales.value();
  std::vector<std::string> warnings;
  if (options.T_expected_world_from_ct) {
    const Status tables = result.prepareViewRenderers(*options.T_expected_world_from_ct, monitor);
    if (!tables) return fail(tables.error());
    warnings = tables.warnings();
  }
  Result<RegistrationCase> out(std::move(result));
  for (std::string& warning : warnings) out.addWarning(std::move(warning));
  if (!bone) {
    out.addWarning(fmt::format("no bone surface at {} HU ({}); rotating about the volume centre", options.boneThreshold_hu,
                               bone.error()));
  }
  return out;
}

Result<PreparedXray> RegistrationCase::prepareXray(const std::string& name, const Camera& camera, XrayImage xray,
                                                  const XrayPreparationOptions& preparation) {
  const CameraIntrinsics& in = camera.intrinsics();
  if (in.cols != xray.cols || in.rows != xray.rows) {
    return fail(fmt::format("view '{}': the camera's detector is {}x{} pixels but the X-ray is {}x{}; fix the view "
                            "file's detector size",
                            name, in.cols, in.rows, xray.cols, xray.rows));
  }
  xray.camera = camera;
  auto prepared = XrayPreparation(preparation).prepare(xray);
  if (!prepared) return fail(fmt::format("view '{}': {}", name, prepared.error()));

  // A constant X-ray (over its valid pixels) carries no information to register against.
  const PyramidLevel& level0 = prepared.value().pyramid.level(0);
  float lo = std::numeric_limits<float>::infinity();
  float hi = -lo;
  for (std::size_t i = 0; i < level0.image.pixels.size(); ++i) {
    if (!level0.mask.valid[i]) continue;
    lo = std::min(lo, level0.image.pixels[i]);
    hi = std::max(hi, level0.image.pixels[i]);
  }
  if (!(hi > lo)) {
    return fail(fmt::format("view '{}': the X-ray is constant ({}) over its {} valid pixels; there is nothing to "
                            "register against (check the image file)",
                            name, lo, level0.mask.validCount()));
  }
  return prepared;
}

Status RegistrationCase::replaceXray(std::size_t v, const XrayImage& xray) {
  if (v >= m_views.size()) return fail(fmt::format("view index {} out of range (there are {})", v, m_views.size()));
  View& view = m_views[v];
  auto prepared = prepareXray(view.name, view.camera, xray, view.preparation);
  if (!prepared) return fail(prepared.error());
  view.prepared = std::move(prepared).value();
  view.preparedImage.reset();
  view.selectors.clear();
  return Ok{};
}

Result<HazeRemovalSummary> RegistrationCase::removeHaze(const Eigen::Isometry3d& T_world_from_ct,
                                                        double hazeSigma_mm) {
  if (!(hazeSigma_mm > 0.0) || !std::isfinite(hazeSigma_mm)) {
    return fail(fmt::format("haze removal: the haze's smoothness must be a positive number of mm, got {}", hazeSigma_mm));
  }
  auto cutFaces = CutFaceRayMask::create(*m_drrVolume, kHazeFitCutFaceMargin_mm);
  if (!cutFaces) return fail("haze removal: " + cutFaces.error());
  int rendered = 0;
  auto drrs = fullResolutionDrrs(T_world_from_ct, rendered);
  if (!drrs) return fail("haze removal: " + drrs.error());
  // Each view's fit, in parallel: a failed mask fails the call, a failed fit keeps that view's X-ray.
  std::vector<Status> statuses(m_views.size(), Ok{});
  std::vector<std::optional<Result<HazeCorrection>>> fits(m_views.size());
  tbb::parallel_for(std::size_t{0}, m_views.size(), [&](std::size_t v) {
    const View& view = m_views[v];
    const FloatImage& drr = (*drrs.value())[v];
    const PyramidLevel& full = view.prepared.pyramid.level(0);
    ValidMask fitMask = full.mask;
    if (const Status clear = fitMask.intersect(cutFaces.value().compute(view.camera, T_world_from_ct)); !clear) {
      statuses[v] = fail(fmt::format("view '{}': haze removal: {}", view.name, clear.error()));
      return;
    }
    fits[v] = XrayHazeCorrector::correct(view.preparedImage ? *view.preparedImage : full.image, drr, fitMask,
                                         hazeSigma_mm / view.camera.intrinsics().pixelSpacing_mm.mean());
  });
  HazeRemovalSummary summary;
  for (std::size_t v = 0; v < m_views.size(); ++v) {
    if (!statuses[v]) return fail(statuses[v].error());
  }
  summary.drrs = rendered;
  std::vector<std::optional<XrayPyramid>> pyramids(m_views.size());  // all built before any view changes
  for (std::size_t v = 0; v < m_views.size(); ++v) {
    const Result<HazeCorrection>& fit = *fits[v];
    if (!fit) {
      summary.viewsKept.push_back(fmt::format("view '{}': {}", m_views[v].name, fit.error()));
      continue;
    }
    auto pyramid = XrayPyramid::build(fit.value().lineIntegrals, m_views[v].prepared.pyramid.level(0).mask,
                                      m_views[v].camera, levelCount());
    if (!pyramid) return fail(fmt::format("view '{}': haze removal: pyramid: {}", m_views[v].name, pyramid.error()));
    pyramids[v] = std::move(pyramid).value();
    ++summary.viewsCorrected;
    summary.largestHazeFraction = std::max(summary.largestHazeFraction, fit.value().meanHazeFraction);
    summary.largestHardening = std::max(summary.largestHardening, fit.value().hardening);
  }
  for (std::size_t v = 0; v < m_views.size(); ++v) {
    if (!pyramids[v]) continue;
    View& view = m_views[v];
    if (!view.preparedImage) view.preparedImage = view.prepared.pyramid.level(0).image;
    view.prepared.pyramid = std::move(*pyramids[v]);
    view.selectors.clear();
  }
  return summary;
}

Result<int> RegistrationCase::weighWindowsWithDrr(const Eigen::Isometry3d& T_world_from_ct) {
  int rendered = 0;
  auto drrs = fullResolutionDrrs(T_world_from_ct, rendered);
  if (!drrs) return fail("window weights: " + drrs.error());
  std::vector<std::optional<XrayPyramid>> pyramids(m_views.size());  // all made before any view changes
  for (std::size_t v = 0; v < m_views.size(); ++v) {
    const View& view = m_views[v];
    auto pyramid = XrayPyramid::build((*drrs.value())[v], view.prepared.pyramid.level(0).mask, view.camera,
                                      levelCount());
    if (!pyramid) return fail(fmt::format("view '{}': window weights: pyramid: {}", view.name, pyramid.error()));
    pyramids[v] = std::move(pyramid).value();
  }
  for (std::size_t v = 0; v < m_views.size(); ++v) m_views[v].windowWeights = std::move(pyramids[v]);
  return rendered;
}

Result<const std::vector<FloatImage>*> RegistrationCase::fullResolutionDrrs(const Eigen::Isometry3d& T_world_from_ct,
                                                                           int& rendered) {
  rendered = 0;
  if (m_fullDrrPose && m_fullDrrPose->matrix() == T_world_from_ct.matrix()) return &m_fullDrrs;
  std::vector<Status> statuses(m_views.size(), Ok{});
  std::vector<FloatImage> drrs(m_views.size());
  tbb::parallel_for(std::size_t{0}, m_views.size(), [&](std::size_t v) {
    auto drr = m_renderer->render(m_views[v].camera, T_world_from_ct, 0);
    if (!drr) {
      statuses[v] = fail(fmt::format("view '{}': {}", m_views[v].name, drr.error()));
      return;
    }
    drrs[v] = std::move(drr).value();
  });
  for (const Status& status : statuses) {
    if (!status) return fail(status.error());
  }
  m_fullDrrs = std::move(drrs);
  m_fullDrrPose = T_world_from_ct;
  rendered = static_cast<int>(m_views.size());
  return &m_fullDrrs;
}

const FloatImage* RegistrationCase::windowWeightImage(std::size_t v, int level) const {
  if (v >= m_views.size() || !m_views[v].windowWeights || level < 0 ||
      level >= m_views[v].windowWeights->levelCount()) {
    return nullptr;
  }
  return &m_views[v].windowWeights->level(level).image;
}

Status RegistrationCase::restorePreparedXrays() {
  for (View& view : m_views) {
    view.windowWeights.reset();
    if (!view.preparedImage) continue;
    auto pyramid = XrayPyramid::build(*view.preparedImage, view.prepared.pyramid.level(0).mask, view.camera,
                                      levelCount());
    if (!pyramid) return fail(fmt::format("view '{}': restoring the prepared X-ray: {}", view.name, pyramid.error()));
    view.prepared.pyramid = std::move(pyramid).value();
    view.preparedImage.reset();
    view.selectors.clear();
  }
  return Ok{};
}

Result<MetalReviewSummary> RegistrationCase::reviewMetalMasks(const Eigen::Isometry3d& T_world_from_ct) {
  MetalReviewSummary summary;
  auto cutFaces = CutFaceRayMask::create(*m_drrVolume, kMetalReviewCutFaceMargin_mm);
  if (!cutFaces) return fail("metal mask review: " + cutFaces.error());
  for (View& view : m_views) {
    if (!view.preparation.excludeMetal || !(view.prepared.metalFraction > 0.0)) continue;
    auto drr = m_renderer->render(view.camera, T_world_from_ct, 0);
    if (!drr) return fail(fmt::format("view '{}': metal mask review: {}", view.name, drr.error()));
    ++summary.drrs;
    const PyramidLevel& full = view.prepared.pyramid.level(0);
    auto reviewed = MetalMaskReview(view.preparation.metal)
                        .review(view.prepared.fieldMask, full.mask, full.image, drr.value(),
                                cutFaces.value().compute(view.camera, T_world_from_ct),
                                view.camera.intrinsics().pixelSpacing_mm.mean());
    if (!reviewed) return fail(fmt::format("view '{}': {}", view.name, reviewed.error()));
    if (reviewed.value().piecesGivenBack == 0) continue;
    auto pyramid = XrayPyramid::build(full.image, reviewed.value().mask, view.camera, levelCount());
    if (!pyramid) return fail(fmt::format("view '{}': metal mask review: pyramid: {}", view.name, pyramid.error()));
    const ValidMask& mask = reviewed.value().mask;
    view.prepared.metalFraction = static_cast<double>(reviewed.value().metalPixelCount) /
                                  static_cast<double>(view.prepared.fieldMask.validCount());
    view.prepared.validFraction = static_cast<double>(mask.validCount()) / static_cast<double>(mask.valid.size());
    view.prepared.pyramid = std::move(pyramid).value();
    view.selectors.clear();
    summary.piecesGivenBack += reviewed.value().piecesGivenBack;
  }
  return summary;
}

Status RegistrationCase::prepareViewRenderers(const Eigen::Isometry3d& T_expected_world_from_ct,
                                              const ProgressMonitor& monitor) {
  if (m_viewRenderersReady) return Ok{};
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::shared_ptr<const DrrRenderer>> renderers;
  Status status = Ok{};
  for (const View& view : m_views) {
    auto created = DrrRendererFactory::createForView(m_drrVolume, m_drrOptions, view.camera, T_expected_world_from_ct,
                                                     monitor);
    if (!created) return fail(fmt::format("view '{}': {}", view.name, created.error()));
    for (const std::string& warning : created.warnings()) status.addWarning(fmt::format("view '{}': {}", view.name, warning));
    renderers.push_back(std::move(created).value());
  }
  for (std::size_t v = 0; v < m_views.size(); ++v) {
    m_views[v].renderer = renderers[v];
    m_views[v].transgraph = dynamic_cast<const TransgraphRenderer*>(renderers[v].get());
  }
  m_viewRenderersReady = true;
  m_viewRendererSetup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status;
}

Eigen::Vector3i RegistrationCase::ctBlockSize(std::size_t v, int level, const Eigen::Isometry3d& T_world_from_ct,
                                              int pixelStride) const {
  const Camera levelCamera = m_views[v].camera.downsampled(level);
  const CameraIntrinsics& in = levelCamera.intrinsics();
  const double depth_mm = (levelCamera.T_camera_from_world() * T_world_from_ct * m_centre_ct_mm).z();
  const double footprint_mm = pixelStride * in.pixelSpacing_mm.minCoeff() * depth_mm / in.sourceToDetector_mm;
  const Eigen::Vector3d& spacing_mm = m_drrVolume->values().spacing_mm();
  Eigen::Vector3i block;
  for (int a = 0; a < 3; ++a) block[a] = std::max(1, static_cast<int>(std::floor(footprint_mm / spacing_mm[a])));
  return block;
}

Result<const DrrRenderer*> RegistrationCase::levelRenderer(std::size_t v, int level,
                                                           const Eigen::Isometry3d& T_world_from_ct, int pixelStride,
                                                           std::optional<DrrMethod> method, double rayCastStep_voxels,
                                                           CtSliceModel slices) {
  if (Status valid = checkViewLevel(v, level); !valid) return fail(valid.error());
  const Eigen::Vector3i block = ctBlockSize(v, level, T_world_from_ct, std::max(1, pixelStride));
  const DrrMethod exactMethod = method.value_or(exactRendererOptions(m_drrOptions).method);
  if ((block.array() == 1).all()) return methodRenderer(exactMethod, rayCastStep_voxels, slices);
  if (exactMethod == DrrMethod::Transgraph) return fail("a coarsened CT is rendered with siddon or raycast, not transgraph");
  return keptRenderer(exactMethod, block, rayCastStep_voxels, slices);
}

Result<const DrrRenderer*> RegistrationCase::methodRenderer(DrrMethod method, double rayCastStep_voxels,
                                                            CtSliceModel slices) {
  if (method == exactRendererOptions(m_drrOptions).method && rayCastStep_voxels == 0.0 &&
      sliceModelFor(slices) == CtSliceModel::Samples) {
    return m_renderer.get();
  }
  if (method == DrrMethod::Transgraph) return fail("the transgraph is built per view, not as a CT renderer");
  return keptRenderer(method, Eigen::Vector3i::Ones(), rayCastStep_voxels, slices);
}

Result<const DrrRenderer*> RegistrationCase::keptRenderer(DrrMethod method, const Eigen::Vector3i& block,
                                                          double rayCastStep_voxels, CtSliceModel slices) {
  if (!(rayCastStep_voxels >= 0.0 && rayCastStep_voxels <= 10.0)) {  // also NaN
    return fail(fmt::format("ray-cast step must be 0 (the default) to 10 voxels, got {}", rayCastStep_voxels));
  }
  slices = sliceModelFor(slices);
  const RendererKey key{method, {block.x(), block.y(), block.z()}, rayCastStep_voxels, slices};
  auto found = m_keptRenderers.find(key);
  if (found != m_keptRenderers.end()) return found->second.get();
  if (slices == CtSliceModel::SlabAverages && !m_sliceAveragesVolume) {
    m_sliceAveragesVolume = std::make_shared<const DrrVolume>(m_drrVolume->sliceAveragesDeconvolved());
  }
  std::shared_ptr<const DrrVolume> volume = slices == CtSliceModel::SlabAverages ? m_sliceAveragesVolume : m_drrVolume;
  if ((block.array() != 1).any()) {
    auto coarse = volume->coarsened(block);
    if (!coarse) return fail(coarse.error());
    volume = std::make_shared<const DrrVolume>(std::move(coarse).value());
  }
  DrrRendererOptions options = m_drrOptions;
  options.method = method;
  if (rayCastStep_voxels > 0.0) options.rayCastStep_mm = rayCastStep_voxels * std::cbrt(volume->values().spacing_mm().prod());
  auto renderer = DrrRendererFactory::create(volume, options);
  if (!renderer) return fail(renderer.error());
  return m_keptRenderers.emplace(key, std::move(renderer).value()).first->second.get();
}

Status RegistrationCase::checkViewLevel(std::size_t v, int level) const {
  if (v >= m_views.size()) return fail(fmt::format("view index {} out of range (there are {})", v, m_views.size()));
  const int levels = m_views[v].prepared.pyramid.levelCount();
  if (level < 0 || level >= levels) {
    return fail(fmt::format("view '{}': pyramid level {} does not exist; use 0 to {}", m_views[v].name, level,
                            levels - 1));
  }
  return Ok{};
}

Result<const DynamicRoiSelector*> RegistrationCase::selector(std::size_t v, int level, int windowSize) {
  if (Status valid = checkViewLevel(v, level); !valid) return fail(valid.error());
  View& view = m_views[v];
  const auto key = std::make_pair(level, windowSize);
  auto found = view.selectors.find(key);
  if (found == view.selectors.end()) {
    const PyramidLevel& pyramidLevel = view.prepared.pyramid.level(level);
    auto created = DynamicRoiSelector::create(pyramidLevel.image, pyramidLevel.mask, windowSize);
    if (!created) return fail(fmt::format("view '{}', level {}: {}", view.name, level, created.error()));
    found = view.selectors.emplace(key, std::move(created).value()).first;
  }
  return &found->second;
}

Result<RoiSelection> RegistrationCase::rois(std::size_t v, int level, int windowSize, double targetFraction) {
  auto selector = this->selector(v, level, windowSize);
  if (!selector) return fail(selector.error());
  auto selection = selector.value()->selectFraction(targetFraction);
  if (!selection) return fail(fmt::format("view '{}', level {}: {}", m_views[v].name, level, selection.error()));
  return selection;
}

Result<RoiSelection> RegistrationCase::allWindows(std::size_t v, int level, int windowSize) {
  auto selector = this->selector(v, level, windowSize);
  if (!selector) return fail(selector.error());
  return selector.value()->selectAll();
}

Result<double> RegistrationCase::metalFractionOfCoveredField(std::size_t v,
                                                             const Eigen::Isometry3d& T_world_from_ct) const {
  auto covered = cutFaceMask(v, 0, T_world_from_ct);
  if (!covered) return fail(covered.error());
  const PreparedXray& prepared = m_views[v].prepared;
  return prepared.fieldMask.excludedFractionWithin(prepared.pyramid.level(0).mask, covered.value());
}

Result<ValidMask> RegistrationCase::cutFaceMask(std::size_t v, int level,
                                                const Eigen::Isometry3d& T_world_from_ct) const {
  if (Status valid = checkViewLevel(v, level); !valid) return fail(valid.error());
  const PyramidLevel& pyramidLevel = m_views[v].prepared.pyramid.level(level);
  if (!m_cutFaces) return ValidMask::allValid(pyramidLevel.image.cols, pyramidLevel.image.rows);
  if (!pyramidLevel.camera) return fail(fmt::format("view '{}', level {}: no camera", m_views[v].name, level));
  return m_cutFaces->compute(*pyramidLevel.camera, T_world_from_ct);
}

Status RegistrationCase::checkOverlap(const Eigen::Isometry3d& T_world_from_ct, int level) const {
  for (const View& view : m_views) {
    const int usedLevel = std::clamp(level, 0, view.prepared.pyramid.levelCount() - 1);
    const PixelIndexList pixels = view.prepared.pyramid.level(usedLevel).mask.pixelList();
    auto values = m_renderer->renderPixels(view.camera, T_world_from_ct, usedLevel, pixels);
    if (!values) return fail(fmt::format("view '{}': {}", view.name, values.error()));
    const bool empty = std::all_of(values.value().begin(), values.value().end(), [](float x) { return x == 0.0f; });
    if (empty) {
      return fail(fmt::format("view '{}': the CT at the initial pose projects outside the X-ray's {} valid pixels (the "
                              "DRR is empty there), so DRR and X-ray do not overlap; check the initial pose, the "
                              "landmarks or the view's camera",
                              view.name, pixels.size()));
    }
  }
  return Ok{};
}

Eigen::Isometry3d RegistrationCase::poseTransform(const PoseVector& params) const {
  return RigidPose::toTransform(PoseParameters::fromVector(params), m_centre_ct_mm);
}

}  // namespace fct
