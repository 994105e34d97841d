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
//
// minimize() is the one entry point: it checks the inputs and the variant's options once, runs the variant's search
// and turns its best into the result. A variant implements validateOptions() and search() only.

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
  /// Fails, before any evaluation, on an empty objective, a non-finite start or a non-positive or non-finite scale
  /// (naming the parameter) or invalid options (naming the option); fails after the run when every evaluated pose
  /// gave NaN/infinity. Progress goes to `monitor`; see the file comment for cancelling.
  Result<OptimizationResult> minimize(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales,
                                      const ProgressMonitor& monitor = ProgressMonitor()) const;

  /// Checks the variant's options; the error names the bad option and its value.
  virtual Status validateOptions() const = 0;

  /// Scales for a bone of radius `radius_mm`: 1 deg moves its surface by radius_mm * pi / 180 mm, so the rotation
  /// scales are 180 / (pi * radius_mm) deg and the translation scales 1 mm. Fails for a non-positive radius.
  static Result<PoseVector> scalesForBoneRadius(double radius_mm);

 protected:
  /// The variant's search, on inputs and options that minimize() has checked: returns the best pose found with its
  /// value, evaluation count and flags (ObjectiveEvaluator::result); minimize() turns it into the final result.
  virtual OptimizationResult search(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales,
                                    const ProgressMonitor& monitor) const = 0;

 private:
  /// Checks the inputs common to every strategy; the error names the bad parameter.
  static Status validateInputs(const PoseObjective& objective, const PoseVector& start, const PoseVector& scales);
};

}  // namespace fct
