#pragma once
// PoseOptimizer: the common interface of the pose search strategies (Nelder–Mead, genetic search, CMA-ES).
//
// All strategies MINIMIZE an objective over the 6 pose parameters (rx, ry, rz in degrees, tx, ty, tz in mm; the
// PoseParameters vector form). A similarity to maximize (NCC, VLNC) is passed negated.
//
// Scaled units: each strategy works on y_i = p_i / scale_i. A scale is the parameter step (deg or mm) that moves the
// bone surface by about 1 mm, so a scaled unit means "about 1 mm of surface motion" for every parameter and the step
// sizes and tolerances of the options are in those units. scalesForBoneRadius() gives the usual choice.
//
// An objective value that is NaN (or the objective of a pose outside the images) counts as +infinity, the worst.
// The ProgressMonitor's cancel flag is checked before every evaluation; a cancelled run returns the best pose found so
// far with `cancelled` set (a Result that is ok()).

#include <Eigen/Core>

#include <functional>
#include <string>
#include <vector>

#include "Base/ProgressMonitor.h"
#include "Base/Result.h"
#include "Geometry/PoseVector.h"

namespace fct {

/// The function to minimize; NaN means "worst possible".
using PoseObjective = std::function<double(const PoseVector&)>;

/// One generation of a global search, for progress displays and reports.
struct GenerationRecord {
  int generation = 0;          ///< 0 = the initial population
  int evaluations = 0;         ///< objective evaluations so far (cumulative)
  double bestValue = 0.0;      ///< best objective value so far
  int populationSize = 0;      ///< guesses alive in this generation
};

/// What a strategy found.
struct OptimizationResult {
  PoseVector params = PoseVector::Zero();  ///< best parameters found (deg, mm)
  double value = 0.0;                      ///< objective at params
  int evaluations = 0;                     ///< number of objective evaluations made
  bool converged = false;                  ///< the tolerance was reached (false: an evaluation/generation limit hit)
  bool cancelled = false;                  ///< the cancel flag stopped the run; params/value are the best so far
  std::vector<GenerationRecord> generations;  ///< per generation (global strategies only)
};

/// Abstract pose search strategy; implementations are stateless apart from their options.
class PoseOptimizer {
 public:
  virtual ~PoseOptimizer() = default;

  /// Short name for reports ("nelder-mead", "genetic", "cma-es").
  virtual std::string name() const = 0;

  /// Minimizes `objective` from `start` (deg, mm) with per-parameter `scales` (deg or mm per scaled unit).
  /// Fails on an empty objective, a non-finite start, a non-positive or non-finite scale, invalid options, or when
  /// every evaluated pose gave NaN/infinity. Progress goes to `monitor`; see the file comment for cancelling.
  virtual Result<OptimizationResult> minimize(const PoseObjective& objective, const PoseVector& start,
                                              const PoseVector& scales,
                                              const ProgressMonitor& monitor = ProgressMonitor()) const = 0;

  /// Scales for a bone of radius `radius_mm`: 1 deg moves its surface by radius_mm * pi / 180 mm, so the rotation
  /// scales are 180 / (pi * radius_mm) deg and the translation scales 1 mm. Fails for a non-positive radius.
  static Result<PoseVector> scalesForBoneRadius(double radius_mm);

 protected:
  /// Checks the inputs common to every strategy; the error names the bad parameter.
  static Status validateInputs(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales);
  /// Turns the best of a finished run into the final result; fails if no evaluation gave a finite value.
  static Result<OptimizationResult> finish(OptimizationResult result, const std::string& strategy);
};

}  // namespace fct
