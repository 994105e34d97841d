#pragma once
// RegistrationObjective: the similarity of one stage over all views of a RegistrationCase at a pose,
//     S(T) = (1/n) sum_v s_v(DRR_v(T), X-ray_v),
// s_v the stage's metric (NCC, VLNC or GC) over the stage's pixel set of view v at the stage's pyramid level. The
// optimizers minimize -S (the paper's sum over views, divided by n so that thresholds do not depend on n).
// Only the compared pixels are rendered (GC renders the whole level: its Sobel stencil needs the neighbours); the
// views are rendered in parallel, each into its own reused buffers, so an evaluation allocates nothing.

#include <Eigen/Geometry>

#include <cstddef>
#include <memory>
#include <vector>

#include "FloatImage.h"
#include "ImageSimilarity.h"
#include "RegistrationCase.h"
#include "RegistrationSchedule.h"
#include "Result.h"

namespace fct {

/// The per-stage similarity of all views at a pose.
class RegistrationObjective {
 public:
  /// Builds the pixel sets and the X-ray side of the metric of every view for `stage`. Fails, naming the stage and
  /// view, on a level the pyramid lacks or a pixel set that cannot be built (no complete valid window, ...).
  static Result<RegistrationObjective> create(RegistrationCase& registrationCase, const RegistrationStage& stage);

  /// S(T) in [-1, 1] for the CT at T_world_from_ct (see the file comment). Fails on a rendering or metric error.
  Result<double> similarity(const Eigen::Isometry3d& T_world_from_ct);
  /// The per-view similarities of the last successful similarity() call.
  const std::vector<double>& lastPerView() const { return m_lastPerView; }

  /// DRRs rendered so far (one per view per evaluation).
  long drrCount() const { return m_drrCount; }
  /// Per view: compared pixels / valid pixels of the level (the kept fraction of the dynamic ROIs).
  std::vector<double> keptFractions() const;
  /// Per view: number of pixels rendered per evaluation.
  std::vector<std::size_t> renderedPixelCounts() const;

 private:
  struct View {
    Camera camera;                                ///< full-resolution camera (the renderer derives the level)
    bool wholeLevel = false;                      ///< render every pixel (GC) instead of `pixels`
    PixelIndexList pixels;                        ///< pixels to render
    std::unique_ptr<ImageSimilarity> metric;      ///< X-ray side precomputed
    FloatImage drr;                               ///< level-sized buffer; only `pixels` are written
    std::vector<float> values;                    ///< rendered values in `pixels` order
    double keptFraction = 0.0;
    double score = 0.0;
    Status status = Ok{};
  };

  const DrrRenderer* m_renderer = nullptr;
  int m_level = 0;
  std::vector<View> m_views;
  std::vector<double> m_lastPerView;
  long m_drrCount = 0;
};

}  // namespace fct
