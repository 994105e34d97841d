#pragma once
// RotationSweep: a coarse look around a far start's rotation before a stage's search. A start tens of degrees off
// (a rough manual placement, the clinical setup alone) lies outside the basin the stage's search can reach: the genetic
// search spreads its guesses a few degrees, and the shift pre-alignment corrects translation only. The sweep rotates
// the start about the bone centre by every offset of a cubic grid of rotation vectors (spacing `step_deg`, within
// `max_deg`), lines each up roughly in 2D with the ProjectionShiftAligner at a fraction of the level's resolution
// (a far start is off in translation too, and a rotation judged where the start puts it is judged on a misplaced
// outline), ranks them by the stage's similarity, lines the best few up again at the level itself, and returns those
// that then beat the start: the stage's search refines them beside its start.

#include <Eigen/Geometry>

#include <vector>

#include "Base/Result.h"
#include "Geometry/PoseVector.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationObjective.h"
#include "Registration/RegistrationSchedule.h"

namespace fct {

/// One pose the sweep found better than its start.
struct RotationSweepCandidate {
  PoseVector params = PoseVector::Zero();  ///< pose parameters (deg about the bone centre, mm)
  double similarity = 0.0;                 ///< the stage's similarity there
};

/// The rotation grid search of one stage.
class RotationSweep {
 public:
  /// Every grid pose is lined up before the ranking at up to kRoughAlignmentMaxHalvings halvings of the stage's level,
  /// as many as keep each view's image at least kRoughAlignmentMinSide_px on its shorter side (a 512^2 detector at
  /// level 2: 32^2).
  static constexpr int kRoughAlignmentMaxHalvings = 2;
  static constexpr int kRoughAlignmentMinSide_px = 32;
  /// The best `aligned` poses are lined up again at the level over shifts up to this fraction of the image per axis:
  /// the rough alignment has put them within a pixel or two of its coarser image (1/16 of the level's for two halvings
  /// at 0.5), and every fraction of the range costs rays on both sides of the detector.
  static constexpr double kFineAlignmentShiftFraction = 0.125;
  /// The halvings of `level` for the rough alignment of registrationCase's views (0 when the level is already small).
  static int roughAlignmentHalvings(const RegistrationCase& registrationCase, int level);
  /// The grid's rotation vectors (deg, world axes), zero excluded: every multiple of `step_deg` per axis whose length
  /// is at most `max_deg`. Empty when max_deg < step_deg.
  static std::vector<Eigen::Vector3d> offsets_deg(double max_deg, double step_deg);

  /// The sweep of `spec` around `start` (pose parameters about the case's bone centre) at pyramid `level`: every grid
  /// pose shift-aligned at roughAlignmentHalvings() of the level and ranked there by `gridObjective` (a sparser pixel
  /// set of the stage), the best spec.aligned shift-aligned again at the level and ranked by the stage's `objective`.
  /// Returns at most spec.seeds candidates whose similarity beats `startSimilarity` (the stage's), best first; empty
  /// when none does. Fails on a rendering error.
  static Result<std::vector<RotationSweepCandidate>> run(RegistrationCase& registrationCase,
                                                         RegistrationObjective& gridObjective,
                                                         RegistrationObjective& objective, const RotationSweepSpec& spec,
                                                         int level, const PoseVector& start, double startSimilarity);
};

}  // namespace fct
