#pragma once
// RunTimeEstimator: how long a registration preset can take on a prepared case, told before the run. A quick
// calibration renders one full DRR of every view at each pyramid level a preset uses, at the initial pose, with the
// renderer the registration uses there (the CT coarsened to the level); that gives seconds per rendered pixel per
// level. A stage's budget is its evaluation cap times the pixels it renders per evaluation (every valid pixel of a
// whole-image stage, capped by its max_pixels for NCC and GC; the target fraction of them for ROIs); the preset's
// estimate is the sum over its stages. A search usually stops before its cap, but the comparison and the sparse
// renders of ROI pixels cost more per pixel than the calibration's full DRRs: on the built-in case the two roughly
// cancel (docs/studio.md gives a measured pair).

#include <Eigen/Geometry>

#include <vector>

#include "Base/Result.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationSchedule.h"

namespace fct {

/// Time estimates of registration presets from a measured DRR speed.
class RunTimeEstimator {
 public:
  /// Seconds per rendered DRR pixel at each pyramid level 0..levelCount-1 of `registrationCase` (summed over the
  /// views), measured at T_world_from_ct (CT LPS mm -> world LPS mm). Not thread-safe with other users of the case
  /// (it makes the coarse CTs the registration would make). Fails as the level renderers or the renders.
  static Result<std::vector<double>> measureSecondsPerPixel(RegistrationCase& registrationCase,
                                                            const Eigen::Isometry3d& T_world_from_ct);
  /// Estimated run time of `schedule` on `registrationCase`, seconds, from measureSecondsPerPixel()'s figures;
  /// fails on a stage level without a figure.
  static Result<double> budgetSeconds(const RegistrationSchedule& schedule, const RegistrationCase& registrationCase,
                                      const std::vector<double>& secondsPerPixel);
};

}  // namespace fct
