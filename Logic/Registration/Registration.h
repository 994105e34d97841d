#pragma once
// Registration: runs a RegistrationSchedule on a RegistrationCase from an initial pose: stage by stage, each stage's
// search (genetic, CMA-ES or the local simplex) maximizes the stage's similarity over all views
// (RegistrationObjective) starting from the previous stage's best pose. The pose parameters are rotations (deg) about
// the bone centre and translations (mm), scaled by the bone radius (RegistrationCase::scales).
// A stage never ends worse than it started: if its search finds nothing better, the start pose is kept.
// Cancelling (the flag is checked before every DRR set) ends the run at once with the best pose so far, marked.
// Transgraph method: a case whose tables do not exist yet gets them built around the initial pose first (timed apart
// from the registration, RegistrationResult::viewRendererSetupSeconds); the noTransgraph ablation renders every view
// with the case's exact (Siddon) renderer instead.

#include <Eigen/Geometry>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationSchedule.h"

namespace fct {

/// What a run does: the schedule (a preset), techniques switched off, and the random seed.
struct RegistrationOptions {
  RegistrationSchedule schedule;
  RegistrationAblation ablation;
  std::uint32_t seed = 1;  ///< seeds every stage's random search (stage i: seed + i); same seed, same result
  /// Check that DRR and X-ray overlap at the initial pose (a whole-level DRR); off for a start known to be good, e.g.
  /// a tracked pose.
  bool checkOverlap = true;
};

/// A live progress report, sent after every evaluation (one DRR per view).
struct RegistrationProgress {
  int stageIndex = 0;          ///< 0-based
  int stageCount = 0;
  std::string stage;           ///< the stage's name
  int iteration = 0;           ///< evaluations in this stage so far
  int maxIterations = 0;       ///< the stage's evaluation cap
  long drrs = 0;               ///< DRRs rendered in the whole run so far
  double bestSimilarity = 0.0; ///< best similarity of this stage so far (mean over views)
  double fraction = 0.0;       ///< rough overall progress 0..1 (stages count equally)
};
/// Receives progress reports (called on the registration's thread).
using RegistrationProgressCallback = std::function<void(const RegistrationProgress&)>;

/// What one stage did.
struct StageReport {
  std::string name;
  SimilarityMetric metric = SimilarityMetric::Ncc;
  int level = 0;                   ///< pyramid level: 0 = full resolution
  SearchStrategy search = SearchStrategy::Local;
  double seconds = 0.0;
  double cpuSeconds = 0.0;         ///< process CPU time (every thread) during the stage: less load-sensitive than seconds
  long drrs = 0;                   ///< DRRs rendered in the stage (its evaluations and its rotation sweep, x views)
  long fallbackRays = 0;           ///< Transgraph rays outside their table, integrated exactly (0 for other methods)
  int evaluations = 0;
  double startSimilarity = 0.0;    ///< at the stage's start pose
  double similarity = 0.0;         ///< at the stage's final pose (>= startSimilarity)
  std::vector<double> keptFraction;  ///< per view: compared pixels / valid pixels at the stage's level
  /// The translation its shift pre-alignment added to the stage's start (LPS mm); zero without one, or when the moved
  /// start did not raise the similarity (then the start is kept).
  Eigen::Vector3d prealignShift_world_mm = Eigen::Vector3d::Zero();
  /// Poses of its rotation sweep that beat the start: refined beside it (genetic), or the start moved to the best (1).
  int rotationSweepSeeds = 0;
  /// Metal-mask pieces its metal review gave back to the comparison as anatomy (0 without a review or when none).
  int metalPiecesGivenBack = 0;
  /// Views whose X-ray its haze removal corrected (0 without one), the largest mean share |s|/I of a view's signal
  /// its haze term changed, and the largest beam hardening it fitted (b (dmax - dmin), XrayHazeCorrector).
  int hazeViewsCorrected = 0;
  double hazeFraction = 0.0;
  double hazeHardening = 0.0;
  /// Per view its haze removal left as it was: "view 'NAME': why" (the fit failed: a pose far off).
  std::vector<std::string> hazeViewsKept;
  bool cancelled = false;
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();  ///< the stage's final pose (LPS mm)
};
/// What happened before a stage's search, "" when nothing did: "start moved N mm by shift pre-alignment",
/// "K rotation sweep poses searched beside the start" / "start moved to the rotation sweep's best pose", the metal
/// review's and the haze removal's outcome. One wording for the CLI and the Studio.
std::string stageStartNote(const StageReport& report);

/// Receives each stage's report as the stage ends (called on the registration's thread).
using RegistrationStageCallback = std::function<void(const StageReport&)>;

/// The outcome of a run.
struct RegistrationResult {
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();  ///< the registered pose (LPS mm)
  Eigen::Isometry3d T_initial = Eigen::Isometry3d::Identity();        ///< the initial pose
  Eigen::Vector3d rotationCentre_ct_mm = Eigen::Vector3d::Zero();
  std::vector<StageReport> stages;  ///< the stages run (up to the cancelled one)
  double totalSeconds = 0.0;       ///< the registration itself (stages), without viewRendererSetupSeconds
  long totalDrrs = 0;
  /// Transgraph tables built (or loaded from the cache) by this run before its first stage, seconds; 0 when the case
  /// had them already (RegistrationCase::viewRendererSetupSeconds() tells how long they took there).
  double viewRendererSetupSeconds = 0.0;
  bool cancelled = false;           ///< the run was cancelled; T_world_from_ct is the best pose so far
  RegistrationSchedule schedule;    ///< the schedule actually run (ablations and seed applied)
  std::string drrMethod;           ///< the DRR method the stages rendered with ("transgraph", "siddon", ...)
  std::vector<std::string> viewNames;
};

/// Runs registrations.
class Registration {
 public:
  /// Registers from `T_initial` (CT mm -> world mm). Fails, with a message naming the stage or view, on an empty
  /// schedule, a non-rigid initial pose, DRR and X-ray not overlapping at the initial pose (options.checkOverlap), a stage whose pixel set
  /// or metric cannot be built, or a rendering error. A cancelled run is a success with `cancelled` set.
  /// `onStageEnd` gets each stage's report (with its final pose) as the stage ends.
  static Result<RegistrationResult> run(RegistrationCase& registrationCase, const Eigen::Isometry3d& T_initial,
                                        const RegistrationOptions& options,
                                        const RegistrationProgressCallback& onProgress = {},
                                        const std::atomic<bool>* cancel = nullptr,
                                        const RegistrationStageCallback& onStageEnd = {});
};

}  // namespace fct
