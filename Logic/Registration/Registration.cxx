#include "Registration/Registration.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Geometry/RigidPose.h"
#include "Registration/ProjectionShiftAligner.h"
#include "Registration/RegistrationObjective.h"
#include "Registration/RotationSweep.h"
#include "Search/CmaEsOptimizer.h"
#include "Search/GeneticSearchOptimizer.h"
#include "Search/LocalPoseOptimizer.h"


namespace fct {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Process CPU time (all threads) since `start` (a std::clock() reading), seconds.
double cpuSecondsSince(std::clock_t start) { return static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC; }

/// The stage's search strategy with the stage's evaluation cap applied; a genetic search also refines `extraSeeds`
/// (the other strategies search from their start only).
std::unique_ptr<PoseOptimizer> makeOptimizer(const RegistrationStage& stage, const std::vector<PoseVector>& extraSeeds) {
  switch (stage.search) {
    case SearchStrategy::Genetic: {
      GeneticSearchOptions o = stage.genetic;
      o.local = stage.simplex;
      o.maxEvaluations = stage.maxEvaluations;
      o.extraSeeds = extraSeeds;
      return std::make_unique<GeneticSearchOptimizer>(o);
    }
    case SearchStrategy::CmaEs: {
      CmaEsOptions o = stage.cmaes;
      o.maxEvaluations = std::min(o.maxEvaluations, stage.maxEvaluations);
      return std::make_unique<CmaEsOptimizer>(o);
    }
    case SearchStrategy::Local: break;
  }
  LocalSearchOptions o = stage.simplex;
  o.maxEvaluations = std::min(o.maxEvaluations, stage.maxEvaluations);
  return LocalPoseOptimizer::create(o);
}

/// The start pose as a pose vector (deg about the bone centre, mm). Fails on an empty schedule, a non-rigid
/// `T_initial`, or (with `checkOverlap`) DRR and X-ray not overlapping at it at the first stage's level.
Result<PoseVector> checkedStartPose(const RegistrationCase& registrationCase, const Eigen::Isometry3d& T_initial,
                                    const RegistrationSchedule& schedule, bool checkOverlap) {
  if (schedule.stages.empty()) return fail(fmt::format("registration schedule '{}' has no stage", schedule.name));
  auto initialParams = RigidPose::fromTransform(T_initial, registrationCase.rotationCentre_ct_mm());
  if (!initialParams) return fail("initial pose: " + initialParams.error());
  if (!checkOverlap) return initialParams.value().asVector();
  if (auto overlap = registrationCase.checkOverlap(T_initial, schedule.stages.front().level); !overlap) {
    return fail(overlap.error());
  }
  return initialParams.value().asVector();
}

/// What building the per-view Transgraph tables before the first stage came to.
struct TableSetup {
  double seconds = 0.0;    ///< time the tables took; 0 when none were built
  bool cancelled = false;  ///< the cancel flag stopped the build
};

/// Builds the case's per-view Transgraph tables around `T_initial` when the run renders with them and the case has
/// none yet. Fails with the table builder's message (a cancelled build is not a failure).
Result<TableSetup> prepareTransgraphTables(RegistrationCase& registrationCase, const Eigen::Isometry3d& T_initial,
                                           bool useViewRenderers, const ProgressMonitor& monitor) {
  TableSetup setup;
  if (!useViewRenderers || registrationCase.viewRenderersReady()) return setup;
  const auto setupStart = Clock::now();
  const Status tables = registrationCase.prepareViewRenderers(T_initial, monitor);
  if (!tables) {
    if (!monitor.cancelled()) return fail(tables.error());
    setup.cancelled = true;
    return setup;
  }
  setup.seconds = secondsSince(setupStart);
  return setup;
}

/// The result of a run cancelled while its tables were built: the start pose, no stage.
RegistrationResult cancelledBeforeFirstStage(RegistrationResult result, const Eigen::Isometry3d& T_initial,
                                             Clock::time_point runStart) {
  result.cancelled = true;
  result.T_initial = result.T_world_from_ct = T_initial;
  result.totalSeconds = secondsSince(runStart);
  return result;
}

/// The objective of `stage` (pixel sets, cut-face masks and coarse CT made at `T_at`, LPS mm). Fails with the
/// stage's message.
Result<RegistrationObjective> objectiveAt(RegistrationCase& registrationCase, const RegistrationStage& stage,
                                          const RegistrationAblation& ablation, bool useViewRenderers,
                                          const Eigen::Isometry3d& T_at) {
  return RegistrationObjective::create(registrationCase, stage, useViewRenderers && !stage.exactDrr,
                                       ablation.noCtPyramid ? std::nullopt : std::optional(T_at), std::optional(T_at));
}

/// Every stage's objective at the initial pose, built before the first search so that a stage that cannot run fails
/// the registration at once instead of after the earlier stages' work. Fails with the failing stage's message.
Result<std::vector<RegistrationObjective>> createObjectives(RegistrationCase& registrationCase,
                                                            const RegistrationSchedule& schedule,
                                                            const RegistrationAblation& ablation,
                                                            bool useViewRenderers, const Eigen::Isometry3d& T_initial) {
  std::vector<RegistrationObjective> objectives;
  for (const RegistrationStage& stage : schedule.stages) {
    auto created = objectiveAt(registrationCase, stage, ablation, useViewRenderers, T_initial);
    if (!created) return fail(created.error());
    objectives.push_back(std::move(created).value());
  }
  return objectives;
}

/// What every stage of one run shares.
struct StageContext {
  RegistrationCase& registrationCase;
  const ProgressMonitor& monitor;
  const RegistrationProgressCallback& onProgress;
  int stageCount = 0;
};

/// A stage's report before its search: the stage's settings, its start similarity and kept pixel fractions.
StageReport startReport(const RegistrationStage& stage, double startSimilarity, const RegistrationObjective& objective) {
  StageReport report;
  report.name = stage.name;
  report.metric = stage.metric;
  report.level = stage.level;
  report.search = stage.search;
  report.startSimilarity = startSimilarity;
  report.keptFraction = objective.keptFractions();
  return report;
}

/// The progress report of stage `stageIndex` before its first evaluation.
RegistrationProgress startProgress(const RegistrationStage& stage, int stageIndex, int stageCount,
                                   double startSimilarity) {
  RegistrationProgress progress;
  progress.stageIndex = stageIndex;
  progress.stageCount = stageCount;
  progress.stage = stage.name;
  progress.maxIterations = stage.maxEvaluations;
  progress.bestSimilarity = startSimilarity;
  return progress;
}

/// Takes the search's outcome into `report` and moves `current` to the found pose when it beats the stage's start
/// (otherwise the start pose is kept). Fails with the search's message unless the run was cancelled.
Status applySearchOutcome(const Result<OptimizationResult>& found, const ProgressMonitor& monitor, StageReport& report,
                          PoseVector& current) {
  report.similarity = report.startSimilarity;
  if (found) {
    report.evaluations = found.value().evaluations;
    report.cancelled = found.value().cancelled;
    if (-found.value().value > report.startSimilarity) {
      current = found.value().params;
      report.similarity = -found.value().value;
    }
  } else if (monitor.cancelled()) {
    report.cancelled = true;  // cancelled before anything was evaluated: keep the stage's start pose
  } else {
    return fail(found.error());
  }
  return Ok{};
}

/// A stage rebuilds its objective at its start pose when that pose moved the bone more than this from the run's initial
/// pose (boneMotionBound_mm): the cut-face margin of the studies, within which a mask made at the initial pose holds.
constexpr double kObjectiveRebuildDistance_mm = 5.0;

/// A bound on how far the bone surface moves between two poses, mm: the bone centre's displacement plus the bone
/// radius times the rotation angle between them.
double boneMotionBound_mm(const RegistrationCase& registrationCase, const Eigen::Isometry3d& T_a,
                          const Eigen::Isometry3d& T_b) {
  const Eigen::Vector3d centre_ct_mm = registrationCase.rotationCentre_ct_mm();
  const double angle_rad = Eigen::AngleAxisd(T_b.linear() * T_a.linear().transpose()).angle();
  return (T_b * centre_ct_mm - T_a * centre_ct_mm).norm() + registrationCase.boneRadius_mm() * angle_rad;
}

/// Rounds of shift pre-alignment at most.
constexpr int kShiftPrealignRounds = 3;

/// What a stage's shift pre-alignment did.
struct PrealignOutcome {
  Eigen::Vector3d shift_world_mm = Eigen::Vector3d::Zero();  ///< the translation added in all (LPS mm)
  double similarity = 0.0;                                   ///< the stage's similarity at the (moved) start
};

/// Shift pre-alignment of a stage (ProjectionShiftAligner at its level, repeated): moves `current` by each alignment
/// that raises the stage's similarity (`objective`). Returns the translation added in all (zero when the first did
/// not raise it) and the similarity at the resulting start. Fails, naming the stage, on a rendering error.
Result<PrealignOutcome> prealignByShift(RegistrationCase& registrationCase, const RegistrationStage& stage,
                                        RegistrationObjective& objective, PoseVector& current) {
  const auto failed = [&](const std::string& error) { return fail(fmt::format("stage '{}': {}", stage.name, error)); };
  Eigen::Isometry3d T_current = registrationCase.poseTransform(current);
  auto similarity = objective.similarity(T_current);
  if (!similarity) return failed(similarity.error());
  Eigen::Vector3d total_world_mm = Eigen::Vector3d::Zero();
  // A far start's DRR overlaps its X-ray only in part, so one alignment may bring it only part of the way: repeat
  // while the similarity rises and the move is more than a millimetre.
  for (int round = 0; round < kShiftPrealignRounds; ++round) {
    auto aligned = ProjectionShiftAligner::align(registrationCase, T_current, stage.level);
    if (!aligned) return failed(aligned.error());
    if (aligned.value().translation_world_mm.norm() < 1.0) break;
    auto after = objective.similarity(aligned.value().T_world_from_ct);
    if (!after) return failed(after.error());
    if (!(after.value() > similarity.value())) break;
    auto moved = RigidPose::fromTransform(aligned.value().T_world_from_ct, registrationCase.rotationCentre_ct_mm());
    if (!moved) return failed(moved.error());
    current = moved.value().asVector();
    T_current = aligned.value().T_world_from_ct;
    similarity = after;
    total_world_mm += aligned.value().translation_world_mm;
  }
  return PrealignOutcome{total_world_mm, similarity.value()};
}

/// What came before a stage's search: its shift pre-alignment and rotation sweep.
struct StageStart {
  Clock::time_point began = Clock::now();  ///< when the stage began, its pre-alignment and sweep included
  std::clock_t cpuBegan = std::clock();    ///< the process CPU clock then
  Eigen::Vector3d prealignShift_world_mm = Eigen::Vector3d::Zero();  ///< the pre-alignment's move (LPS mm)
  double similarity = std::numeric_limits<double>::quiet_NaN();      ///< at the start pose; NaN: not known yet
  std::vector<PoseVector> sweepSeeds;  ///< rotation sweep poses that beat the start (deg, mm), best first
  /// DRRs rendered before the search: the metal review's and the rotation sweep's grid ranking (its own objective)
  long preSearchDrrs = 0;
  int metalPiecesGivenBack = 0;  ///< metal-mask pieces the metal review gave back
  HazeRemovalSummary haze;       ///< what the haze removal did (nothing without one)
};

/// The stage's similarity at `current` (pose parameters), or `known` when that is not NaN. Fails, naming the stage.
Result<double> startSimilarityAt(RegistrationCase& registrationCase, const RegistrationStage& stage,
                                 RegistrationObjective& objective, const PoseVector& current, double known) {
  if (!std::isnan(known)) return known;
  auto value = objective.similarity(registrationCase.poseTransform(current));
  if (!value) return fail(fmt::format("stage '{}': {}", stage.name, value.error()));
  return value.value();
}

/// Makes `objective` again at T_at when T_at lies more than kObjectiveRebuildDistance_mm of bone motion from
/// T_objective (where it was made): its cut-face masks and coarse CT then belong to T_at. Moves T_objective there and
/// returns true when it did. Fails, naming the stage, when the objective cannot be made.
Result<bool> remakeObjectiveIfFar(RegistrationCase& registrationCase, const RegistrationStage& stage,
                                  const RegistrationAblation& ablation, bool useViewRenderers,
                                  const Eigen::Isometry3d& T_at, RegistrationObjective& objective,
                                  Eigen::Isometry3d& T_objective) {
  if (!(boneMotionBound_mm(registrationCase, T_objective, T_at) > kObjectiveRebuildDistance_mm)) return false;
  auto remade = objectiveAt(registrationCase, stage, ablation, useViewRenderers, T_at);
  if (!remade) return fail(fmt::format("stage '{}': {}", stage.name, remade.error()));
  objective = std::move(remade).value();
  T_objective = T_at;
  return true;
}

/// Makes the objectives of stages `first` onward again at T_at (after their X-rays or masks changed) and moves their
/// T_objectives there. Fails with the failing stage's message.
Status remakeObjectivesFrom(RegistrationCase& registrationCase, const RegistrationSchedule& schedule, std::size_t first,
                            const RegistrationAblation& ablation, bool useViewRenderers, const Eigen::Isometry3d& T_at,
                            std::vector<RegistrationObjective>& objectives,
                            std::vector<Eigen::Isometry3d>& T_objectives) {
  for (std::size_t j = first; j < schedule.stages.size(); ++j) {
    auto rebuilt = objectiveAt(registrationCase, schedule.stages[j], ablation, useViewRenderers, T_at);
    if (!rebuilt) return fail(rebuilt.error());
    objectives[j] = std::move(rebuilt).value();
    T_objectives[j] = T_at;
  }
  return Ok{};
}

/// The stage's rotation sweep from `current`: fills start.sweepSeeds for a genetic search, or moves `current` to the
/// sweep's best pose for the others. The grid is ranked on the stage's whole images at the sweep's pixel budget (made
/// like the stage's objective, at `current`). When the best pose lies far from `T_objective` (where `objective` was
/// made), the objective is made again there (its cut-face masks and coarse CT belong to the pose the search refines)
/// and T_objective moved. Fails, naming the stage, on a rendering error.
Status sweepRotations(RegistrationCase& registrationCase, const RegistrationStage& stage,
                      const RegistrationAblation& ablation, bool useViewRenderers, RegistrationObjective& objective,
                      Eigen::Isometry3d& T_objective, StageStart& start, PoseVector& current) {
  auto startSimilarity = startSimilarityAt(registrationCase, stage, objective, current, start.similarity);
  if (!startSimilarity) return fail(startSimilarity.error());
  start.similarity = startSimilarity.value();
  RegistrationStage gridStage = stage;
  gridStage.pixels = PixelSetSpec{PixelSetKind::WholeImage, stage.pixels.windowSize, 1.0, stage.rotationSweep.maxPixels};
  auto gridObjective =
      objectiveAt(registrationCase, gridStage, ablation, useViewRenderers, registrationCase.poseTransform(current));
  if (!gridObjective) return fail(fmt::format("stage '{}': rotation sweep: {}", stage.name, gridObjective.error()));
  auto found = RotationSweep::run(registrationCase, gridObjective.value(), objective, stage.rotationSweep, stage.level,
                                  current, start.similarity);
  start.preSearchDrrs += gridObjective.value().drrCount();
  if (!found) return fail(fmt::format("stage '{}': rotation sweep: {}", stage.name, found.error()));
  if (found.value().empty()) return Ok{};
  for (const RotationSweepCandidate& candidate : found.value()) start.sweepSeeds.push_back(candidate.params);
  if (stage.search != SearchStrategy::Genetic) {  // a single-start search starts from the best (its only seed)
    current = found.value().front().params;
    start.similarity = found.value().front().similarity;
    start.sweepSeeds.resize(1);
  }
  auto remade = remakeObjectiveIfFar(registrationCase, stage, ablation, useViewRenderers,
                                     registrationCase.poseTransform(found.value().front().params), objective,
                                     T_objective);
  if (!remade) return fail(remade.error());
  if (remade.value()) start.similarity = std::numeric_limits<double>::quiet_NaN();
  return Ok{};
}

/// The coordinates a stage's search moves in: the pose parameters (rotation about the bone centre, world translation)
/// in the case's scales, or, for a one-view local stage with depthScale > 1, the translation in the frame of the
/// viewing ray (z from the source through the bone centre at the stage's start, x across it along the detector's
/// columns, y = z x x) with the scale along z depthScale times the scale across it.
struct SearchFrame {
  Eigen::Matrix3d R_world_from_search = Eigen::Matrix3d::Identity();
  PoseVector scales;

  /// Search coordinates of pose parameters.
  PoseVector toSearch(const PoseVector& params) const {
    PoseVector q = params;
    q.tail<3>() = R_world_from_search.transpose() * params.tail<3>();
    return q;
  }
  /// Pose parameters of search coordinates.
  PoseVector toPose(const PoseVector& q) const {
    PoseVector params = q;
    params.tail<3>() = R_world_from_search * q.tail<3>();
    return params;
  }
};

/// The search frame of `stage` started at `current` (see SearchFrame). The case's translation scales are equal on
/// the three axes (PoseOptimizer::scalesForBoneRadius), so turning them does not change them.
SearchFrame searchFrameFor(const RegistrationCase& registrationCase, const RegistrationStage& stage,
                           const PoseVector& current) {
  SearchFrame frame;
  frame.scales = registrationCase.scales();
  if (stage.depthScale == 1.0 || registrationCase.viewCount() != 1 || stage.search != SearchStrategy::Local) {
    return frame;
  }
  const Camera& camera = registrationCase.camera(0);
  const Eigen::Vector3d centre_world_mm =
      registrationCase.poseTransform(current) * registrationCase.rotationCentre_ct_mm();
  const Eigen::Vector3d z = (centre_world_mm - camera.sourcePosition_world_mm()).normalized();
  const Eigen::Vector3d columns = camera.T_world_from_camera().linear().col(0);
  const Eigen::Vector3d x = (columns - columns.dot(z) * z).normalized();
  frame.R_world_from_search.col(0) = x;
  frame.R_world_from_search.col(1) = z.cross(x);
  frame.R_world_from_search.col(2) = z;
  frame.scales[5] *= stage.depthScale;
  return frame;
}

/// Runs stage `stageIndex` from `current` (pose parameters, deg and mm), moving `current` to the stage's best pose;
/// `drrsBefore` counts the earlier stages' DRRs for the progress reports; `start` is what its pre-alignment and
/// rotation sweep did. Returns the stage's report; fails, naming the stage, on a rendering or search error.
Result<StageReport> runStage(const StageContext& context, int stageIndex, const RegistrationStage& stage,
                             RegistrationObjective& objective, long drrsBefore, const StageStart& start,
                             PoseVector& current) {
  RegistrationCase& registrationCase = context.registrationCase;
  auto knownSimilarity = startSimilarityAt(registrationCase, stage, objective, current, start.similarity);
  if (!knownSimilarity) return fail(knownSimilarity.error());
  const double startSimilarity = knownSimilarity.value();
  StageReport report = startReport(stage, startSimilarity, objective);
  report.prealignShift_world_mm = start.prealignShift_world_mm;
  report.rotationSweepSeeds = static_cast<int>(start.sweepSeeds.size());
  report.metalPiecesGivenBack = start.metalPiecesGivenBack;
  report.hazeViewsCorrected = start.haze.viewsCorrected;
  report.hazeFraction = start.haze.largestHazeFraction;
  report.hazeHardening = start.haze.largestHardening;
  report.hazeViewsKept = start.haze.viewsKept;

  RegistrationProgress progress = startProgress(stage, stageIndex, context.stageCount, startSimilarity);
  std::string renderError;
  const SearchFrame searchFrame = searchFrameFor(registrationCase, stage, current);
  const PoseObjective f = [&](const PoseVector& searchParams) {
    auto value = objective.similarity(registrationCase.poseTransform(searchFrame.toPose(searchParams)));
    if (!value) {
      if (renderError.empty()) renderError = value.error();
      return std::numeric_limits<double>::quiet_NaN();
    }
    ++progress.iteration;
    progress.drrs = drrsBefore + start.preSearchDrrs + objective.drrCount();
    progress.bestSimilarity = std::max(progress.bestSimilarity, value.value());
    progress.fraction =
        (stageIndex + std::min(1.0, static_cast<double>(progress.iteration) / progress.maxIterations)) /
        context.stageCount;
    if (context.onProgress) context.onProgress(progress);
    return -value.value();
  };

  const std::unique_ptr<PoseOptimizer> optimizer = makeOptimizer(stage, start.sweepSeeds);
  auto found = optimizer->minimize(f, searchFrame.toSearch(current), searchFrame.scales, context.monitor);
  if (found) found.value().params = searchFrame.toPose(found.value().params);
  if (!renderError.empty()) return fail(fmt::format("stage '{}': {}", stage.name, renderError));
  if (const Status applied = applySearchOutcome(found, context.monitor, report, current); !applied) {
    return fail(fmt::format("stage '{}': {}", stage.name, applied.error()));
  }
  report.drrs = objective.drrCount() + start.preSearchDrrs;
  report.fallbackRays = objective.fallbackRayCount();
  report.seconds = secondsSince(start.began);
  report.cpuSeconds = cpuSecondsSince(start.cpuBegan);
  report.T_world_from_ct = registrationCase.poseTransform(current);
  return report;
}

}  // namespace

std::string stageStartNote(const StageReport& report) {
  std::vector<std::string> notes;
  if (!report.prealignShift_world_mm.isZero()) {
    notes.push_back(fmt::format("start moved {:.1f} mm by shift pre-alignment", report.prealignShift_world_mm.norm()));
  }
  if (report.rotationSweepSeeds > 0 && report.search == SearchStrategy::Genetic) {
    notes.push_back(fmt::format("{} rotation sweep pose{} searched beside the start", report.rotationSweepSeeds,
                                report.rotationSweepSeeds == 1 ? "" : "s"));
  } else if (report.rotationSweepSeeds > 0) {
    notes.emplace_back("start moved to the rotation sweep's best pose");
  }
  if (report.metalPiecesGivenBack > 0) {
    notes.push_back(fmt::format("{} metal-mask piece{} the DRR explains compared as anatomy",
                                report.metalPiecesGivenBack, report.metalPiecesGivenBack == 1 ? "" : "s"));
  }
  if (report.hazeViewsCorrected > 0) {
    notes.push_back(fmt::format("haze removed from {} view{} (up to {:.0f} % of a view's signal; beam hardening up to "
                                "{:.2f})",
                                report.hazeViewsCorrected, report.hazeViewsCorrected == 1 ? "" : "s",
                                100.0 * report.hazeFraction, report.hazeHardening));
  }
  for (const std::string& kept : report.hazeViewsKept) notes.push_back("haze not removed from " + kept);
  return fmt::format("{}", fmt::join(notes, "; "));
}

Result<RegistrationResult> Registration::run(RegistrationCase& registrationCase, const Eigen::Isometry3d& T_initial,
                                             const RegistrationOptions& options,
                                             const RegistrationProgressCallback& onProgress,
                                             const std::atomic<bool>* cancel,
                                             const RegistrationStageCallback& onStageEnd) {
  const auto runStart = Clock::now();
  RegistrationResult result;
  result.schedule = options.schedule.withAblation(options.ablation).withSeed(options.seed);
  const RegistrationSchedule& schedule = result.schedule;
  auto start = checkedStartPose(registrationCase, T_initial, schedule, options.checkOverlap);
  if (!start) return fail(start.error());

  const ProgressMonitor monitor(ProgressMonitor::Callback{}, cancel);
  const bool useViewRenderers = !options.ablation.noTransgraph;
  auto tables = prepareTransgraphTables(registrationCase, T_initial, useViewRenderers, monitor);
  if (!tables) return fail(tables.error());
  if (tables.value().cancelled) return cancelledBeforeFirstStage(std::move(result), T_initial, runStart);
  result.viewRendererSetupSeconds = tables.value().seconds;
  result.T_initial = T_initial;
  result.rotationCentre_ct_mm = registrationCase.rotationCentre_ct_mm();
  for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) result.viewNames.push_back(registrationCase.viewName(v));

  // A run compares the X-rays as prepared: an earlier run's haze removal does not carry over.
  if (const Status restored = registrationCase.restorePreparedXrays(); !restored) return fail(restored.error());
  auto objectives = createObjectives(registrationCase, schedule, options.ablation, useViewRenderers, T_initial);
  if (!objectives) return fail(objectives.error());
  std::vector<Eigen::Isometry3d> T_objectives(schedule.stages.size(), T_initial);  // where each objective was made
  result.drrMethod = std::string(objectives.value().front().drrMethodName());

  const StageContext context{registrationCase, monitor, onProgress, static_cast<int>(schedule.stages.size())};
  PoseVector current = start.value();
  for (int s = 0; s < context.stageCount; ++s) {
    if (monitor.cancelled()) {
      result.cancelled = true;
      break;
    }
    const auto i = static_cast<std::size_t>(s);
    const RegistrationStage& stage = schedule.stages[i];
    StageStart stageStart;
    if (stage.metalReview) {
      const Eigen::Isometry3d T_review = registrationCase.poseTransform(current);
      auto review = registrationCase.reviewMetalMasks(T_review);
      if (!review) return fail(fmt::format("stage '{}': {}", stage.name, review.error()));
      stageStart.metalPiecesGivenBack = review.value().piecesGivenBack;
      stageStart.preSearchDrrs += review.value().drrs;
      if (review.value().piecesGivenBack > 0) {  // the masks changed: the stages from here on select their pixels again
        const Status rebuilt = remakeObjectivesFrom(registrationCase, schedule, i, options.ablation, useViewRenderers,
                                                    T_review, objectives.value(), T_objectives);
        if (!rebuilt) return fail(rebuilt.error());
      }
    }
    // The haze removal and the DRR window weights change what the stage compares: its objectives (and the later
    // stages') are made again once, after both.
    const Eigen::Isometry3d T_stageStart = registrationCase.poseTransform(current);
    bool remake = false;
    if (stage.hazeSigma_mm > 0.0) {
      auto removed = registrationCase.removeHaze(T_stageStart, stage.hazeSigma_mm);
      if (!removed) return fail(fmt::format("stage '{}': {}", stage.name, removed.error()));
      stageStart.haze = removed.value();
      stageStart.preSearchDrrs += removed.value().drrs;
      remake = removed.value().viewsCorrected > 0;  // the X-rays changed: select the pixels again
    }
    if (stage.metric == SimilarityMetric::Vlnc && stage.vlncWeights == VlncWeightSource::Drr) {
      auto weighed = registrationCase.weighWindowsWithDrr(T_stageStart);
      if (!weighed) return fail(fmt::format("stage '{}': {}", stage.name, weighed.error()));
      stageStart.preSearchDrrs += weighed.value();
      remake = true;
    }
    if (remake) {
      const Status rebuilt = remakeObjectivesFrom(registrationCase, schedule, i, options.ablation, useViewRenderers,
                                                  T_stageStart, objectives.value(), T_objectives);
      if (!rebuilt) return fail(rebuilt.error());
    }
    if (stage.shiftPrealign) {
      auto outcome = prealignByShift(registrationCase, stage, objectives.value()[i], current);
      if (!outcome) return fail(outcome.error());
      stageStart.prealignShift_world_mm = outcome.value().shift_world_mm;
      stageStart.similarity = outcome.value().similarity;
    }
    // A stage whose start lies far from where its objective was made (after a far start's first stage, or its shift
    // pre-alignment) makes its pixel sets (cut-face masks) and coarse CT again at its own start pose; a similarity
    // made with the old ones no longer holds.
    auto remade = remakeObjectiveIfFar(registrationCase, stage, options.ablation, useViewRenderers,
                                       registrationCase.poseTransform(current), objectives.value()[i], T_objectives[i]);
    if (!remade) return fail(remade.error());
    if (remade.value()) stageStart.similarity = std::numeric_limits<double>::quiet_NaN();
    if (stage.rotationSweep.maxRotation_deg > 0.0) {
      const Status swept = sweepRotations(registrationCase, stage, options.ablation, useViewRenderers,
                                          objectives.value()[i], T_objectives[i], stageStart, current);
      if (!swept) return fail(swept.error());
    }
    auto report = runStage(context, s, stage, objectives.value()[i], result.totalDrrs, stageStart, current);
    if (!report) return fail(report.error());
    result.totalDrrs += report.value().drrs;
    result.stages.push_back(std::move(report).value());
    if (onStageEnd) onStageEnd(result.stages.back());
    if (result.stages.back().cancelled) {
      result.cancelled = true;
      break;
    }
  }
  result.T_world_from_ct = registrationCase.poseTransform(current);
  result.totalSeconds = secondsSince(runStart) - result.viewRendererSetupSeconds;
  return result;
}

}  // namespace fct
