#include "Registration/Registration.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "Geometry/RigidPose.h"
#include "Registration/RegistrationObjective.h"
#include "Search/CmaEsOptimizer.h"
#include "Search/GeneticSearchOptimizer.h"
#include "Search/NelderMeadOptimizer.h"

namespace fct {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The stage's search strategy with the stage's evaluation cap applied.
std::unique_ptr<PoseOptimizer> makeOptimizer(const RegistrationStage& stage) {
  switch (stage.search) {
    case SearchStrategy::Genetic: {
      GeneticSearchOptions o = stage.genetic;
      o.local = stage.simplex;
      o.maxEvaluations = stage.maxEvaluations;
      return std::make_unique<GeneticSearchOptimizer>(o);
    }
    case SearchStrategy::CmaEs: {
      CmaEsOptions o = stage.cmaes;
      o.maxEvaluations = std::min(o.maxEvaluations, stage.maxEvaluations);
      return std::make_unique<CmaEsOptimizer>(o);
    }
    case SearchStrategy::Local: break;
  }
  NelderMeadOptions o = stage.simplex;
  o.maxEvaluations = std::min(o.maxEvaluations, stage.maxEvaluations);
  return std::make_unique<NelderMeadOptimizer>(o);
}

}  // namespace

Result<RegistrationResult> Registration::run(RegistrationCase& registrationCase, const Eigen::Isometry3d& T_initial,
                                             const RegistrationOptions& options,
                                             const RegistrationProgressCallback& onProgress,
                                             const std::atomic<bool>* cancel) {
  const auto runStart = Clock::now();
  RegistrationResult result;
  result.schedule = options.schedule.withAblation(options.ablation).withSeed(options.seed);
  const RegistrationSchedule& schedule = result.schedule;
  if (schedule.stages.empty()) return fail(fmt::format("registration schedule '{}' has no stage", schedule.name));
  auto initialParams = RigidPose::fromTransform(T_initial, registrationCase.rotationCentre_ct_mm());
  if (!initialParams) return fail("initial pose: " + initialParams.error());
  if (auto overlap = registrationCase.checkOverlap(T_initial, schedule.stages.front().level); !overlap) {
    return fail(overlap.error());
  }
  const ProgressMonitor monitor(ProgressMonitor::Callback{}, cancel);
  const bool useViewRenderers = !options.ablation.noTransgraph;
  if (useViewRenderers && !registrationCase.viewRenderersReady()) {
    const auto setupStart = Clock::now();
    const Status tables = registrationCase.prepareViewRenderers(T_initial, monitor);
    if (!tables) {
      if (monitor.cancelled()) {
        result.cancelled = true;
        result.T_initial = result.T_world_from_ct = T_initial;
        result.totalSeconds = secondsSince(runStart);
        return result;
      }
      return fail(tables.error());
    }
    result.viewRendererSetupSeconds = secondsSince(setupStart);
  }
  result.T_initial = T_initial;
  result.rotationCentre_ct_mm = registrationCase.rotationCentre_ct_mm();
  for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) result.viewNames.push_back(registrationCase.viewName(v));

  // Every stage's pixel sets and metrics are built before the first search, so a stage that cannot run fails the
  // registration at once instead of after the earlier stages' work.
  std::vector<RegistrationObjective> objectives;
  for (const RegistrationStage& stage : schedule.stages) {
    auto created = RegistrationObjective::create(registrationCase, stage, useViewRenderers && !stage.exactDrr,
                                                 options.ablation.noCtPyramid ? std::nullopt
                                                                              : std::optional(T_initial));
    if (!created) return fail(created.error());
    objectives.push_back(std::move(created).value());
  }
  result.drrMethod = std::string(objectives.front().drrMethodName());
  PoseVector current = initialParams.value().asVector();
  const int stageCount = static_cast<int>(schedule.stages.size());

  for (int s = 0; s < stageCount; ++s) {
    const RegistrationStage& stage = schedule.stages[static_cast<std::size_t>(s)];
    if (monitor.cancelled()) {
      result.cancelled = true;
      break;
    }
    const auto stageStart = Clock::now();
    RegistrationObjective& objective = objectives[static_cast<std::size_t>(s)];
    auto startValue = objective.similarity(registrationCase.poseTransform(current));
    if (!startValue) return fail(fmt::format("stage '{}': {}", stage.name, startValue.error()));

    StageReport report;
    report.name = stage.name;
    report.metric = stage.metric;
    report.level = stage.level;
    report.search = stage.search;
    report.startSimilarity = startValue.value();
    report.keptFraction = objective.keptFractions();

    RegistrationProgress progress;
    progress.stageIndex = s;
    progress.stageCount = stageCount;
    progress.stage = stage.name;
    progress.maxIterations = stage.maxEvaluations;
    progress.bestSimilarity = startValue.value();
    std::string renderError;
    const PoseObjective f = [&](const PoseVector& params) {
      auto value = objective.similarity(registrationCase.poseTransform(params));
      if (!value) {
        if (renderError.empty()) renderError = value.error();
        return std::numeric_limits<double>::quiet_NaN();
      }
      ++progress.iteration;
      progress.drrs = result.totalDrrs + objective.drrCount();
      progress.bestSimilarity = std::max(progress.bestSimilarity, value.value());
      progress.fraction = (s + std::min(1.0, static_cast<double>(progress.iteration) / progress.maxIterations)) /
                          stageCount;
      if (onProgress) onProgress(progress);
      return -value.value();
    };

    const std::unique_ptr<PoseOptimizer> optimizer = makeOptimizer(stage);
    auto found = optimizer->minimize(f, current, registrationCase.scales(), monitor);
    if (!renderError.empty()) return fail(fmt::format("stage '{}': {}", stage.name, renderError));
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
      return fail(fmt::format("stage '{}': {}", stage.name, found.error()));
    }
    report.drrs = objective.drrCount();
    report.fallbackRays = objective.fallbackRayCount();
    report.seconds = secondsSince(stageStart);
    result.totalDrrs += report.drrs;
    result.stages.push_back(std::move(report));
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
