#include "Registration/RegistrationObjective.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "Similarity/GradientCorrelationSimilarity.h"
#include "Similarity/NccSimilarity.h"
#include "Similarity/VlncSimilarity.h"

namespace fct {

namespace {

/// The smallest stride k such that every k-th column and row of `count` pixels keeps at most maxPixels of them
/// (approximately: the valid pixels are assumed evenly spread); 1 when maxPixels is 0 (no cap) or not exceeded.
int strideFor(std::size_t count, int maxPixels) {
  if (maxPixels <= 0 || count <= static_cast<std::size_t>(maxPixels)) return 1;
  return static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count) / maxPixels)));
}

/// The pixels of `pixels` (linear indices of a level `cols` wide) on every k-th column and row.
PixelIndexList everyKth(const PixelIndexList& pixels, int cols, int k) {
  if (k <= 1) return pixels;
  PixelIndexList kept;
  kept.reserve(pixels.size() / (static_cast<std::size_t>(k) * k) + 1);
  for (const std::int32_t index : pixels) {
    if ((index % cols) % k == 0 && (index / cols) % k == 0) kept.push_back(index);
  }
  return kept;
}

/// The pixels of `pixels` valid in `mask`.
PixelIndexList keepValid(const PixelIndexList& pixels, const ValidMask& mask) {
  PixelIndexList kept;
  kept.reserve(pixels.size());
  for (const std::int32_t index : pixels) {
    if (mask.valid[static_cast<std::size_t>(index)]) kept.push_back(index);
  }
  return kept;
}

/// The windows of `selection` whose every pixel is valid in `mask`, with their pixels.
RoiSelection keepValidWindows(const RoiSelection& selection, const ValidMask& mask) {
  RoiSelection kept = selection;
  kept.windows.clear();
  kept.pixels.clear();
  const std::size_t windowPixels = static_cast<std::size_t>(selection.windowSize) * selection.windowSize;
  for (std::size_t w = 0; w < selection.windows.size(); ++w) {
    const auto first = selection.pixels.begin() + static_cast<std::ptrdiff_t>(w * windowPixels);
    const auto last = first + static_cast<std::ptrdiff_t>(windowPixels);
    if (!std::all_of(first, last, [&](std::int32_t index) { return mask.valid[static_cast<std::size_t>(index)] != 0; })) {
      continue;
    }
    kept.windows.push_back(selection.windows[w]);
    kept.pixels.insert(kept.pixels.end(), first, last);
  }
  return kept;
}

/// The highest-variance windows of `selection` covering round(targetFraction × validPixels) pixels (at least one
/// window, if any), in raster order — DynamicRoiSelector::selectFraction over a reduced candidate set.
RoiSelection strongestWindows(const RoiSelection& selection, double targetFraction, std::size_t validPixels) {
  const std::size_t windowPixels = static_cast<std::size_t>(selection.windowSize) * selection.windowSize;
  const auto wanted = static_cast<std::size_t>(std::lround(targetFraction * validPixels / double(windowPixels)));
  const std::size_t count = std::min(std::max<std::size_t>(wanted, 1), selection.windows.size());
  std::vector<std::size_t> order(selection.windows.size());
  for (std::size_t w = 0; w < order.size(); ++w) order[w] = w;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return selection.windows[a].normalizedVariance > selection.windows[b].normalizedVariance;
  });
  order.resize(count);
  std::sort(order.begin(), order.end());  // back to raster order
  RoiSelection kept = selection;
  kept.windows.clear();
  kept.pixels.clear();
  for (const std::size_t w : order) {
    kept.windows.push_back(selection.windows[w]);
    const auto first = selection.pixels.begin() + static_cast<std::ptrdiff_t>(w * windowPixels);
    kept.pixels.insert(kept.pixels.end(), first, first + static_cast<std::ptrdiff_t>(windowPixels));
  }
  if (!kept.windows.empty()) {
    kept.threshold = kept.windows.front().normalizedVariance;
    for (const RoiWindow& window : kept.windows) kept.threshold = std::min<double>(kept.threshold, window.normalizedVariance);
  }
  kept.keptFraction = validPixels ? static_cast<double>(kept.pixels.size()) / static_cast<double>(validPixels) : 0.0;
  return kept;
}

}  // namespace

Result<RegistrationObjective> RegistrationObjective::create(RegistrationCase& registrationCase,
                                                            const RegistrationStage& stage, bool useViewRenderers,
                                                            const std::optional<Eigen::Isometry3d>& T_coarseCt_world_from_ct,
                                                            const std::optional<Eigen::Isometry3d>& T_cutFaces_world_from_ct) {
  RegistrationObjective objective;
  objective.m_level = stage.level;
  const int level = stage.level;
  auto where = [&](std::size_t v) { return fmt::format("stage '{}', view '{}'", stage.name, registrationCase.viewName(v)); };
  if (level < 0 || level >= registrationCase.levelCount()) {
    return fail(fmt::format("stage '{}' uses pyramid level {} but the X-rays have levels 0 to {}; change the preset or "
                            "prepare more levels",
                            stage.name, level, registrationCase.levelCount() - 1));
  }
  for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) {
    const PyramidLevel& pyramidLevel = registrationCase.prepared(v).pyramid.level(level);
    View view;
    // A stage that names its DRR method renders exactly with it (not the case's tables or renderer; set below).
    const bool viewRenderers = useViewRenderers && !stage.drrMethod;
    view.renderer = viewRenderers ? &registrationCase.renderer(v) : &registrationCase.renderer();
    const bool tableRenderer = viewRenderers && registrationCase.transgraph(v) != nullptr;
    view.camera = registrationCase.camera(v);
    std::optional<ValidMask> cutFaces;
    if (T_cutFaces_world_from_ct) {
      auto mask = registrationCase.cutFaceMask(v, level, *T_cutFaces_world_from_ct);
      if (!mask) return fail(fmt::format("{}: {}", where(v), mask.error()));
      cutFaces = std::move(mask).value();
    }
    // The pixels the comparison may use: valid, and clear of the cut faces when those are left out.
    std::size_t validCount =
        cutFaces ? keepValid(pyramidLevel.mask.pixelList(), *cutFaces).size() : pyramidLevel.mask.validCount();

    // The pixel set: windows for VLNC and for ROIs, the valid pixels otherwise.
    const bool windows = stage.metric == SimilarityMetric::Vlnc || stage.pixels.kind == PixelSetKind::Rois;
    RoiSelection selection;
    int stride = 1;  // a capped whole-image set keeps every stride-th column and row
    if (windows) {
      const bool rois = stage.pixels.kind == PixelSetKind::Rois;
      // With cut faces, the ROIs are the strongest of the windows clear of them.
      auto selected = rois && !cutFaces
                          ? registrationCase.rois(v, level, stage.pixels.windowSize, stage.pixels.targetFraction)
                          : registrationCase.allWindows(v, level, stage.pixels.windowSize);
      if (!selected) return fail(fmt::format("stage '{}': {}", stage.name, selected.error()));
      selection = std::move(selected).value();
      if (cutFaces) {
        RoiSelection clear = keepValidWindows(selection, *cutFaces);
        if (clear.windows.empty()) {  // no window clear of the cut faces at this level: keep the unmasked ROIs
          auto unmasked = rois ? registrationCase.rois(v, level, stage.pixels.windowSize, stage.pixels.targetFraction)
                               : Result<RoiSelection>(selection);
          if (!unmasked) return fail(fmt::format("stage '{}': {}", stage.name, unmasked.error()));
          selection = std::move(unmasked).value();
          validCount = pyramidLevel.mask.validCount();
        } else {
          selection = rois ? strongestWindows(clear, stage.pixels.targetFraction, validCount) : std::move(clear);
        }
      }
      view.pixels = selection.pixels;
    } else {
      view.pixels = pyramidLevel.mask.pixelList();
      if (cutFaces) {
        PixelIndexList clear = keepValid(view.pixels, *cutFaces);
        if (!clear.empty()) {
          view.pixels = std::move(clear);
        } else {  // every valid ray crosses them: keep all
          validCount = pyramidLevel.mask.validCount();
        }
      }
      stride = strideFor(view.pixels.size(), stage.pixels.maxPixels);
      view.pixels = everyKth(view.pixels, pyramidLevel.image.cols, stride);
    }
    if (view.pixels.empty()) {
      return fail(fmt::format("{}: the pixel set is empty (no valid pixel at level {}, or every ray crosses the CT's "
                              "cut faces); reduce the masks, the cut-face margin, or use a finer level",
                              where(v), level));
    }
    // Each kept pixel of a capped NCC set stands for stride x stride pixels: the CT is coarsened to that footprint
    // (fewer, larger voxels per ray), as the level's own pixels are. (GC renders the whole level: no coarsening.)
    if (!tableRenderer && T_coarseCt_world_from_ct) {
      const int footprintStride = stage.metric == SimilarityMetric::Ncc ? stride : 1;
      auto levelRenderer = registrationCase.levelRenderer(v, level, *T_coarseCt_world_from_ct, footprintStride,
                                                          stage.drrMethod, stage.drrStep_voxels, stage.drrSlices);
      if (!levelRenderer) return fail(fmt::format("{}: {}", where(v), levelRenderer.error()));
      view.renderer = levelRenderer.value();
    } else if (stage.drrMethod) {
      auto methodRenderer = registrationCase.methodRenderer(*stage.drrMethod, stage.drrStep_voxels, stage.drrSlices);
      if (!methodRenderer) return fail(fmt::format("{}: {}", where(v), methodRenderer.error()));
      view.renderer = methodRenderer.value();
    }
    view.keptFraction = validCount ? static_cast<double>(view.pixels.size()) / static_cast<double>(validCount) : 0.0;

    switch (stage.metric) {
      case SimilarityMetric::Ncc: {
        auto metric = NccSimilarity::create(pyramidLevel.image, view.pixels);
        if (!metric) return fail(fmt::format("{}: {}", where(v), metric.error()));
        view.metric = std::make_unique<NccSimilarity>(std::move(metric).value());
        break;
      }
      case SimilarityMetric::Vlnc: {
        // A stage weighing its windows with a DRR uses the X-ray's variances until its start has rendered that DRR
        // (Registration makes the stage's objective again there).
        const FloatImage* weightImage =
            stage.vlncWeights == VlncWeightSource::Drr ? registrationCase.windowWeightImage(v, level) : nullptr;
        auto metric = VlncSimilarity::create(pyramidLevel.image, selection, stage.vlncDomain, weightImage);
        if (!metric) return fail(fmt::format("{}: {}", where(v), metric.error()));
        view.metric = std::make_unique<VlncSimilarity>(std::move(metric).value());
        break;
      }
      case SimilarityMetric::GradientCorrelation: {
        auto metric = GradientCorrelationSimilarity::create(pyramidLevel.image, view.pixels);
        if (!metric) return fail(fmt::format("{}: {}", where(v), metric.error()));
        view.metric = std::make_unique<GradientCorrelationSimilarity>(std::move(metric).value());
        view.wholeLevel = true;
        break;
      }
    }
    view.drr = FloatImage::filled(pyramidLevel.image.cols, pyramidLevel.image.rows, 0.0f);
    view.values.reserve(view.pixels.size());
    objective.m_views.push_back(std::move(view));
  }
  return objective;
}

Result<double> RegistrationObjective::similarity(const Eigen::Isometry3d& T_world_from_ct) {
  tbb::parallel_for(std::size_t{0}, m_views.size(), [&](std::size_t v) {
    View& view = m_views[v];
    DrrRenderStats stats;
    if (view.wholeLevel) {
      view.status = view.renderer->render(view.camera, T_world_from_ct, m_level, view.drr, &stats);
    } else {
      view.status =
          view.renderer->renderPixels(view.camera, T_world_from_ct, m_level, view.pixels, view.values, &stats);
      if (view.status) {
        for (std::size_t i = 0; i < view.pixels.size(); ++i) view.drr.pixels[view.pixels[i]] = view.values[i];
      }
    }
    if (!view.status) return;
    view.fallbackRays = stats.fallbackRays;
    auto score = view.metric->evaluate(view.drr);
    if (!score) {
      view.status = fail(score.error());
      return;
    }
    view.score = score.value();
  });
  m_drrCount += static_cast<long>(m_views.size());
  double sum = 0.0;
  for (std::size_t v = 0; v < m_views.size(); ++v) {
    if (!m_views[v].status) return fail(m_views[v].status.error());
    m_fallbackRays += static_cast<long>(m_views[v].fallbackRays);
    sum += m_views[v].score;
  }
  return sum / static_cast<double>(m_views.size());
}

std::string_view RegistrationObjective::drrMethodName() const {
  return m_views.empty() ? std::string_view() : m_views.front().renderer->methodName();
}

std::vector<double> RegistrationObjective::keptFractions() const {
  std::vector<double> fractions;
  for (const View& view : m_views) fractions.push_back(view.keptFraction);
  return fractions;
}

std::vector<std::size_t> RegistrationObjective::renderedPixelCounts() const {
  std::vector<std::size_t> counts;
  for (const View& view : m_views) {
    counts.push_back(view.wholeLevel ? view.drr.pixels.size() : view.pixels.size());
  }
  return counts;
}

}  // namespace fct
