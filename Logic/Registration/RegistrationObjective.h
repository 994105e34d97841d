#pragma once
// RegistrationObjective: the similarity of one stage over all views of a RegistrationCase at a pose,
//     S(T) = (1/n) sum_v s_v(DRR_v(T), X-ray_v),
// s_v the stage's metric (NCC, VLNC or GC) over the stage's pixel set of view v at the stage's pyramid level. The
// optimizers minimize -S (the paper's sum over views, divided by n so that thresholds do not depend on n).
// Only the compared pixels are rendered (GC renders the whole level: its Sobel stencil needs the neighbours); the
// views are rendered in parallel, each by its own renderer (RegistrationCase::renderer(v): the view's Transgraph, or
// the shared exact renderer) into its own reused buffers, so an evaluation allocates nothing.

#include <Eigen/Geometry>

#include <cstddef>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationSchedule.h"
#include "Similarity/ImageSimilarity.h"

namespace fct {

/// The per-stage similarity of all views at a pose.
class RegistrationObjective {
 public:
  /// Builds the pixel sets and the X-ray side of the metric of every view for `stage`. Fails, naming the stage and
  /// view, on a level the pyramid lacks or a pixel set that cannot be built (no complete valid window, ...).
  /// With useViewRenderers false every view uses the case's exact renderer (the Transgraph switched off). Exact
  /// renderers integrate the full CT, or, given T_coarseCt_world_from_ct, the CT coarsened to the stage level's pixel
  /// footprint at that pose (RegistrationCase::levelRenderer; the CT pyramid). Given T_cutFaces_world_from_ct, the
  /// pixels (VLNC: the windows with a pixel) whose rays at that pose cross the CT's cut faces are left out
  /// (RegistrationCase::cutFaceMask), unless that leaves a view no pixel (no complete window for VLNC): then that view
  /// keeps its unmasked set in that stage. A VLNC stage with DRR window weights weighs its windows with the case's
  /// windowWeightImage(), or with the X-ray's variances while the case has none.
  static Result<RegistrationObjective> create(
      RegistrationCase& registrationCase, const RegistrationStage& stage, bool useViewRenderers = true,
      const std::optional<Eigen::Isometry3d>& T_coarseCt_world_from_ct = std::nullopt,
      const std::optional<Eigen::Isometry3d>& T_cutFaces_world_from_ct = std::nullopt);

  /// S(T) in [-1, 1] for the CT at T_world_from_ct (see the file comment). Fails on a rendering or metric error.
  Result<double> similarity(const Eigen::Isometry3d& T_world_from_ct);
  /// DRRs rendered so far (one per view per evaluation).
  long drrCount() const { return m_drrCount; }
  /// Transgraph rays rendered so far that were outside their view's table and integrated exactly instead (0 for the
  /// other methods): a count well above 0 means the poses left the tables' range and the Transgraph saves little.
  long fallbackRayCount() const { return m_fallbackRays; }
  /// The name of the DRR method the views are rendered with ("siddon", "transgraph", ...).
  std::string_view drrMethodName() const;
  /// Per view: compared pixels / valid pixels of the level (the kept fraction of the dynamic ROIs).
  std::vector<double> keptFractions() const;
  /// Per view: number of pixels rendered per evaluation.
  std::vector<std::size_t> renderedPixelCounts() const;

 private:
  struct View {
    const DrrRenderer* renderer = nullptr;        ///< renders this view
    Camera camera;                                ///< full-resolution camera (the renderer derives the level)
    bool wholeLevel = false;                      ///< render every pixel (GC) instead of `pixels`
    PixelIndexList pixels;                        ///< pixels to render
    std::unique_ptr<ImageSimilarity> metric;      ///< X-ray side precomputed
    FloatImage drr;                               ///< level-sized buffer; only `pixels` are written
    std::vector<float> values;                    ///< rendered values in `pixels` order
    double keptFraction = 0.0;
    double score = 0.0;
    std::size_t fallbackRays = 0;                 ///< of the last render
    Status status = Ok{};
  };

  int m_level = 0;
  std::vector<View> m_views;
  long m_drrCount = 0;
  long m_fallbackRays = 0;
};

}  // namespace fct
