#pragma once
// StudyRunner: runs the trials of a StudyDefinition that a TrialStore does not hold yet, and stores each one as soon
// as it ends (resume). For every CT it fixes a true pose (the bone turned by (4, -3, 6) deg about its centre, the
// centre at world (2, -3, 1.5) mm near the views' isocentre at the origin), builds the standard views and, for every
// (CT, slice spacing, view count), prepares one RegistrationCase on the registration CT. The X-rays come from the
// original CT (StudyXraySource). With setup.xraysPerTrial (the default) every trial simulates its own: the bone at
// trialTruthPose (the true pose moved within +-kTrialSpread_mm and +-kTrialSpread_deg about its centre), its own
// foreign objects and noise, swapped into the worker's case (RegistrationCase::replaceXray); otherwise all trials of a
// CT share one set simulated at the true pose. Trial t of a condition starts at a random pose whose mean sTRE from its
// truth is drawn in the condition's initial range; its truth, X-rays and start all come from seed = setup.seed + t (so
// conditions see the same bone poses, noise and start directions: paired comparisons), and it registers with that
// seed. Trials run on `jobs` threads (each registration is itself threaded).
// Transgraph method: each trial gets a fresh copy of the case, so its tables are built around that trial's START pose
// (the truth is unknown at run time), or loaded from setup.transgraphCacheDir when another condition with the same
// registration CT, views and start (same trial index) built them; the time goes to TrialRecord::setupSeconds.
// With a StudyShard only that shard's trials are run (and only the CTs and cases they need are prepared).

#include <Eigen/Geometry>

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/StudyDefinition.h"
#include "Evaluation/StudyShard.h"
#include "Evaluation/TrialStore.h"
#include "Image/BoneSurface.h"
#include "Image/Volume.h"
#include "Registration/RegistrationSchedule.h"

namespace fct {

/// A CT of a study and its label (the "ct" of conditions and trials).
struct StudyCt {
  std::string label;
  Volume volume;
};

/// Reported after every finished trial.
struct StudyProgress {
  int finished = 0;      ///< trials finished in this run
  int toRun = 0;         ///< trials this run has to do
  TrialRecord record;    ///< the trial just finished
};

/// How to run a study.
struct StudyRunOptions {
  int jobs = 1;                                                  ///< trials in parallel (1..StudyRunner::kMaxJobs)
  std::function<void(const StudyProgress&)> onTrial;             ///< after each trial (serialized)
  std::function<void(const std::string&)> onMessage;             ///< preparation steps (serialized)
  const std::atomic<bool>* cancel = nullptr;                     ///< set to stop: running trials end as Cancelled
  const StudyShard* shard = nullptr;                             ///< run only this shard's trials (null: all)
};

/// What a run did.
struct StudyRunSummary {
  int ran = 0;           ///< trials run now (any status)
  int skipped = 0;       ///< trials already in the store (of this run's shard)
  int failed = 0;        ///< trials whose registration returned an error
  bool cancelled = false;
};

/// Runs studies.
class StudyRunner {
 public:
  /// The most trials run in parallel.
  static constexpr int kMaxJobs = 64;

  /// Runs the missing trials of `study` on `cts`, adding each to `store`. Fails before any trial on jobs outside
  /// 1..kMaxJobs, a condition naming a CT not in `cts`, a view count outside 1..5, no trials, a bad initial range, an
  /// unknown preset, a CT without bone, or a simulation or case preparation error; fails after a trial when the
  /// store cannot be written (the trials so far stay in the file). A registration error is a Failed trial.
  static Result<StudyRunSummary> run(const StudyDefinition& study, const std::vector<StudyCt>& cts, TrialStore& store,
                                     const StudyRunOptions& options = {});
  /// Notes for the report: the X-ray forward model, and each condition whose registration CT is the original although
  /// its scenario asks for coarser slices (the CT's own slices are already that coarse).
  static std::vector<std::string> notes(const StudyDefinition& study, const std::vector<StudyCt>& cts);
  /// Sets every condition's usedSliceSpacing_mm: the slice spacing of the CT it registers on (its scenario's spacing,
  /// or the CT's own when that is already as coarse). Conditions naming a CT not in `cts` are left at 0.
  static void resolveSliceSpacings(StudyDefinition& study, const std::vector<StudyCt>& cts);
  /// The start pose of a trial of condition `c` (its StudyStart) for the bone at T_truth seen by `cameras`, from the
  /// trial's seed; initialTarget_mm gets the mean surface distance asked for (NaN for rotation and setup starts).
  static Result<Eigen::Isometry3d> startPose(const StudyCondition& c, const BoneSurface& bone,
                                             const Eigen::Isometry3d& T_truth, const std::vector<Camera>& cameras,
                                             std::uint32_t seed, double& initialTarget_mm);
  /// The true pose T_world_from_ct used for a CT with this bone (see the file comment).
  static Eigen::Isometry3d truthPose(const BoneSurface& bone);
  /// Bound of each translation (mm) and rotation (deg) parameter of a trial's bone pose about truthPose.
  static constexpr double kTrialSpread_mm = 10.0;
  static constexpr double kTrialSpread_deg = 5.0;
  /// The true pose of the trial with this seed when every trial has its own X-rays: truthPose moved about the bone
  /// centre by rotations about the world axes and a translation, each drawn uniformly within +-kTrialSpread_deg /
  /// +-kTrialSpread_mm from the seed.
  static Eigen::Isometry3d trialTruthPose(const BoneSurface& bone, std::uint32_t seed);
  /// The noise and foreign-object seed of the X-rays of the trial with this seed (view v adds v): a hash of it, so
  /// that neighbouring trials share no view's noise.
  static std::uint32_t trialXraySeed(std::uint32_t seed);
  /// `base` with every stage's metric set for `measures` (NCC only, VLNC only, or unchanged).
  static RegistrationSchedule scheduleFor(const RegistrationSchedule& base, StudyMeasures measures);
};

}  // namespace fct
