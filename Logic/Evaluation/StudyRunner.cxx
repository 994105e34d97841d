#include "Evaluation/StudyRunner.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "Base/SeededRandom.h"
#include "Drr/DrrRendererFactory.h"
#include "Evaluation/PoseErrorMetrics.h"
#include "Evaluation/PoseOffset.h"
#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyXraySource.h"
#include "Geometry/RigidPose.h"
#include "InitialPose/SetupPose.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationCase.h"
#include "Simulation/StandardViews.h"

namespace fct {

namespace {

constexpr int kMaxViews = 5;

/// Everything about one CT that its trials share: error measures, truth, the views and the X-rays simulated at the
/// truth (all views), without and (when a scenario needs them and the trials share one set) with foreign objects. The
/// cases are prepared on those X-rays; with per-trial X-rays each trial then swaps in its own.
struct CtScene {
  const Volume* ct = nullptr;
  std::unique_ptr<PoseErrorMetrics> metrics;
  Eigen::Isometry3d T_truth = Eigen::Isometry3d::Identity();
  std::vector<ViewSpec> views;
  std::vector<RegistrationView> xrays;
  std::vector<RegistrationView> xraysWithObjects;
};

/// One trial to run.
struct PendingTrial {
  const StudyCondition* condition = nullptr;
  int trial = 0;
};

/// The scenes of a run, by CT label.
using CtScenes = std::map<std::string, CtScene>;

/// The prepared registration cases of a run, by caseKey.
using CasePrototypes = std::map<std::string, std::unique_ptr<RegistrationCase>>;

/// What the workers of a run share: its prepared inputs (read only) and its progress (`next`; the rest under `mutex`).
struct TrialWork {
  const StudyDefinition& study;
  const std::vector<PendingTrial>& pending;
  const CtScenes& scenes;
  const CasePrototypes& prototypes;
  std::map<StudyMeasures, RegistrationSchedule> schedules;  ///< by the conditions' measures
  const StudyRunOptions& options;
  TrialStore& store;
  StudyRunSummary& summary;
  std::mutex mutex{};
  std::atomic<std::size_t> next{0};     ///< the next pending trial to take
  std::atomic<bool> storeFailed{false};
  std::string storeError{};
  int finished = 0;
};

/// Conditions registering on the same CT (after resampling, if any) with the same views share a case.
std::string caseKey(const StudyCondition& c, const Volume& ct) {
  return fmt::format("{}|{}|{}|{}", c.ct, StudyXraySource::effectiveSliceSpacing_mm(ct, c.sliceSpacing_mm),
                     c.viewCount, StudyCatalog::scenarioHasForeignObjects(c.scenario));
}

/// Checks the job count and every condition (unique name, known CT, views, trials, initial range) before any work.
Status validate(const StudyDefinition& study, const std::vector<StudyCt>& cts, const StudyRunOptions& options) {
  if (options.jobs < 1 || options.jobs > StudyRunner::kMaxJobs) {
    return fail(fmt::format("parallel jobs must be between 1 and {}, got {}", StudyRunner::kMaxJobs, options.jobs));
  }
  if (study.conditions.empty()) return fail(fmt::format("study '{}' has no condition", study.name));
  std::set<std::string> names;
  for (const StudyCondition& c : study.conditions) {
    if (!names.insert(c.name).second) return fail(fmt::format("study '{}': condition '{}' appears twice", study.name, c.name));
    const bool known = std::any_of(cts.begin(), cts.end(), [&](const StudyCt& ct) { return ct.label == c.ct; });
    if (!known) return fail(fmt::format("study '{}', condition '{}': no CT labelled '{}' was given", study.name, c.name, c.ct));
    if (c.viewCount < 1 || c.viewCount > kMaxViews) {
      return fail(fmt::format("condition '{}': {} views; use 1 to {}", c.name, c.viewCount, kMaxViews));
    }
    if (c.trials < 1) return fail(fmt::format("condition '{}': {} trials; use at least 1", c.name, c.trials));
    if (!(c.initialLow_mm >= 0.0) || !(c.initialHigh_mm >= c.initialLow_mm) || !std::isfinite(c.initialHigh_mm)) {
      return fail(fmt::format("condition '{}': initial sTRE range {}..{} mm is not a finite range from 0 up", c.name,
                              c.initialLow_mm, c.initialHigh_mm));
    }
    if (c.start == StudyStart::Rotation && !(c.rotationLow_deg >= 0.0 && c.rotationHigh_deg >= c.rotationLow_deg &&
                                             c.rotationHigh_deg <= 180.0)) {
      return fail(fmt::format("condition '{}': start rotation range {}..{} deg is not a range within 0..180 deg",
                              c.name, c.rotationLow_deg, c.rotationHigh_deg));
    }
  }
  return Ok{};
}

/// The cameras of a scene's views.
std::vector<Camera> cameras(const std::vector<RegistrationView>& views) {
  std::vector<Camera> out;
  for (const RegistrationView& v : views) out.push_back(v.camera);
  return out;
}

/// The record of a trial that did not register: identification, NaN errors, status Failed and the reason.
TrialRecord failedTrial(const StudyDefinition& study, const StudyCondition& c, int trial, const std::string& reason) {
  TrialRecord r;
  r.study = study.name;
  r.ct = c.ct;
  r.condition = c.name;
  r.scenario = c.scenario;
  r.variant = c.variant;
  r.views = c.viewCount;
  r.trial = trial;
  r.seed = study.setup.seed + static_cast<std::uint32_t>(trial);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.error = PoseError{nan, nan, nan, nan, nan};
  r.status = TrialStatus::Failed;
  r.reason = reason;
  return r;
}

/// The trial's true pose, and with per-trial X-rays its own X-rays swapped into `registrationCase`. Fails naming the
/// simulation or the view whose X-ray the case rejects.
Result<Eigen::Isometry3d> prepareTrialXrays(const StudyDefinition& study, const StudyCondition& c, std::uint32_t seed,
                                            const CtScene& scene, RegistrationCase& registrationCase) {
  if (!study.setup.xraysPerTrial) return scene.T_truth;
  const Eigen::Isometry3d T_truth = StudyRunner::trialTruthPose(scene.metrics->surface(), seed);
  const std::vector<ViewSpec> views(scene.views.begin(), scene.views.begin() + c.viewCount);
  auto xrays = StudyXraySource::simulate(*scene.ct, views, T_truth, StudyRunner::trialXraySeed(seed),
                                         StudyCatalog::scenarioHasForeignObjects(c.scenario));
  if (!xrays) return fail("simulating the trial's X-rays: " + xrays.error());
  for (std::size_t v = 0; v < xrays.value().size(); ++v) {
    if (Status swapped = registrationCase.replaceXray(v, xrays.value()[v].xray); !swapped) return fail(swapped.error());
  }
  return T_truth;
}

/// Runs one trial on `registrationCase` (a worker's own copy).
TrialRecord runTrial(const StudyDefinition& study, const StudyCondition& c, int trial, const CtScene& scene,
                     RegistrationCase& registrationCase, const RegistrationSchedule& schedule,
                     const std::atomic<bool>* cancel) {
  TrialRecord r = failedTrial(study, c, trial, "");
  auto truth = prepareTrialXrays(study, c, r.seed, scene, registrationCase);
  if (!truth) {
    r.reason = truth.error();
    return r;
  }
  const Eigen::Isometry3d& T_truth = truth.value();
  r.truthOffset_mm = scene.metrics->measure(T_truth, scene.T_truth).streMean_mm;

  auto start = StudyRunner::startPose(c, scene.metrics->surface(), T_truth, cameras(scene.xrays), r.seed,
                                      r.initialTarget_mm);
  if (!start) {
    r.reason = "start pose: " + start.error();
    return r;
  }
  r.initialStre_mm = scene.metrics->measure(start.value(), T_truth).streMean_mm;

  RegistrationOptions options;
  options.schedule = schedule;
  options.ablation = c.ablation;
  options.seed = r.seed;
  const auto clockStart = std::chrono::steady_clock::now();
  auto result = Registration::run(registrationCase, start.value(), options, {}, cancel);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clockStart).count();
  if (!result) {
    r.reason = result.error();
    return r;
  }
  r.setupSeconds = result.value().viewRendererSetupSeconds;
  r.seconds -= r.setupSeconds;
  r.status = TrialStatus::Ok;
  r.drrs = result.value().totalDrrs;
  r.error = scene.metrics->measure(result.value().T_world_from_ct, T_truth);
  r.success = PoseErrorMetrics::isSuccess(r.error);
  if (result.value().cancelled) {
    r.status = TrialStatus::Cancelled;
    r.reason = "cancelled before the registration ended";
  }
  return r;
}

/// Passes a preparation step to StudyRunOptions::onMessage, when one is set.
void say(const StudyRunOptions& options, const std::string& text) {
  if (options.onMessage) options.onMessage(text);
}

/// True once the run's cancel flag is set.
bool cancelRequested(const StudyRunOptions& options) { return options.cancel && options.cancel->load(); }

/// The trials of `study` (of `shard`, when given) that `store` does not hold yet, by condition then trial index; adds
/// the others of the shard to `skipped`.
std::vector<PendingTrial> findPendingTrials(const StudyDefinition& study, const StudyShard* shard,
                                            const TrialStore& store, int& skipped) {
  std::vector<PendingTrial> pending;
  for (const StudyCondition& c : study.conditions) {
    for (int t = 0; t < c.trials; ++t) {
      if (shard && !shard->holds(c.name, t)) continue;
      if (store.isDone(study.name, c.name, t)) {
        ++skipped;
      } else {
        pending.push_back(PendingTrial{&c, t});
      }
    }
  }
  return pending;
}

/// The most views any pending trial on the CT labelled `label` needs; 0 when none uses it.
int viewsNeeded(const std::vector<PendingTrial>& pending, const std::string& label) {
  int viewCount = 0;
  for (const PendingTrial& p : pending) {
    if (p.condition->ct == label) viewCount = std::max(viewCount, p.condition->viewCount);
  }
  return viewCount;
}

/// The scene of one CT: its error measures, true pose and `viewCount` standard views simulated at that pose (also with
/// foreign objects when `withObjects`). Fails on a CT without bone, bad view settings or a simulation error.
Result<CtScene> simulateScene(const StudyCt& ct, int viewCount, bool withObjects, const StudySetup& setup,
                              const StudyRunOptions& options) {
  CtScene scene;
  scene.ct = &ct.volume;
  auto metrics = PoseErrorMetrics::create(ct.volume);
  if (!metrics) return fail(fmt::format("CT '{}': {}", ct.label, metrics.error()));
  scene.metrics = std::make_unique<PoseErrorMetrics>(std::move(metrics).value());
  scene.T_truth = StudyRunner::truthPose(scene.metrics->surface());
  StandardViewOptions viewOptions = setup.detector;
  viewOptions.count = viewCount;
  auto views = StandardViews::build(Eigen::Vector3d::Zero(), viewOptions);
  if (!views) return fail(views.error());
  scene.views = views.value();
  say(options, fmt::format("simulating {} X-ray views of CT '{}'", viewCount, ct.label));
  auto xrays = StudyXraySource::simulate(ct.volume, views.value(), scene.T_truth, setup.seed, false);
  if (!xrays) return fail(fmt::format("CT '{}': {}", ct.label, xrays.error()));
  scene.xrays = std::move(xrays).value();
  if (withObjects) {
    say(options, fmt::format("simulating {} X-ray views of CT '{}' with foreign objects", viewCount, ct.label));
    auto withTools = StudyXraySource::simulate(ct.volume, views.value(), scene.T_truth, setup.seed, true);
    if (!withTools) return fail(fmt::format("CT '{}': {}", ct.label, withTools.error()));
    scene.xraysWithObjects = std::move(withTools).value();
  }
  return scene;
}

/// The scenes of the CTs that pending trials use, by CT label, each with as many views as its trials need.
Result<CtScenes> simulateScenes(const StudyDefinition& study, const std::vector<StudyCt>& cts,
                                const std::vector<PendingTrial>& pending, const StudyRunOptions& options) {
  CtScenes scenes;
  for (const StudyCt& ct : cts) {
    const int viewCount = viewsNeeded(pending, ct.label);
    if (viewCount == 0) continue;
    // Per-trial X-rays replace the scene's in every case, so the cases need only the tool-free set.
    const bool withObjects = !study.setup.xraysPerTrial &&
                             std::any_of(pending.begin(), pending.end(), [&](const PendingTrial& p) {
                               return p.condition->ct == ct.label &&
                                      StudyCatalog::scenarioHasForeignObjects(p.condition->scenario);
                             });
    auto scene = simulateScene(ct, viewCount, withObjects, study.setup, options);
    if (!scene) return fail(scene.error());
    scenes.emplace(ct.label, std::move(scene).value());
  }
  return scenes;
}

/// The case options of the study's DRR method: the method, its transgraph step and table cache folder (if any).
RegistrationCaseOptions caseOptionsFor(const StudySetup& setup) {
  RegistrationCaseOptions caseOptions;
  caseOptions.drr.method = setup.method;
  caseOptions.drr.transgraph.spacing_mm = setup.transgraphSpacing_mm;
  caseOptions.drr.transgraphCacheFolder = setup.transgraphCacheDir.empty()
                                              ? std::nullopt
                                              : std::optional<std::filesystem::path>(setup.transgraphCacheDir);
  return caseOptions;
}

/// One prepared registration case per caseKey of the pending trials (registration CT and the first views of its
/// scene), copied by each worker (transgraph method: by each trial, whose tables are then built around its own start
/// pose by Registration::run). Fails, naming the CT and scenario, when the CT cannot be resampled or the case prepared.
Result<CasePrototypes> prepareCases(const StudyDefinition& study, const std::vector<PendingTrial>& pending,
                                    const CtScenes& scenes, const StudyRunOptions& options) {
  const RegistrationCaseOptions caseOptions = caseOptionsFor(study.setup);
  CasePrototypes prototypes;
  for (const PendingTrial& p : pending) {
    const StudyCondition& c = *p.condition;
    const CtScene& scene = scenes.at(c.ct);
    const std::string key = caseKey(c, *scene.ct);
    if (prototypes.count(key)) continue;
    const double sliceSpacing_mm = StudyXraySource::effectiveSliceSpacing_mm(*scene.ct, c.sliceSpacing_mm);
    say(options, fmt::format("preparing registration on CT '{}' ({}) with {} views", c.ct,
                             sliceSpacing_mm > 0 ? fmt::format("{:g} mm slices", sliceSpacing_mm) : "original slices",
                             c.viewCount));
    auto registrationCt = StudyXraySource::registrationCt(*scene.ct, c.sliceSpacing_mm);
    if (!registrationCt) return fail(fmt::format("CT '{}', scenario '{}': {}", c.ct, c.scenario, registrationCt.error()));
    const std::vector<RegistrationView>& xrays =
        scene.xraysWithObjects.empty() || !StudyCatalog::scenarioHasForeignObjects(c.scenario) ? scene.xrays
                                                                                                : scene.xraysWithObjects;
    const std::vector<RegistrationView> views(xrays.begin(), xrays.begin() + c.viewCount);
    auto created = RegistrationCase::create(registrationCt.value(), views, caseOptions);
    if (!created) return fail(fmt::format("CT '{}', scenario '{}': {}", c.ct, c.scenario, created.error()));
    prototypes.emplace(key, std::make_unique<RegistrationCase>(std::move(created).value()));
  }
  return prototypes;
}

/// The schedule of each StudyMeasures, derived from the preset's `base`.
std::map<StudyMeasures, RegistrationSchedule> schedulesFor(const RegistrationSchedule& base) {
  std::map<StudyMeasures, RegistrationSchedule> schedules;
  for (StudyMeasures m : {StudyMeasures::Both, StudyMeasures::NccOnly, StudyMeasures::VlncOnly}) {
    schedules.emplace(m, StudyRunner::scheduleFor(base, m));
  }
  return schedules;
}

/// A worker's case for a trial with this key: a copy of the prototype made on first use and kept for the worker's
/// later trials, except with per-trial tables (transgraph), where every trial starts again from the prototype.
RegistrationCase& caseForTrial(std::map<std::string, RegistrationCase>& ownCases, const std::string& key,
                               const CasePrototypes& prototypes, bool tablePerTrial) {
  auto found = ownCases.find(key);
  if (found == ownCases.end()) {
    found = ownCases.emplace(key, *prototypes.at(key)).first;
  } else if (tablePerTrial) {
    found->second = *prototypes.at(key);  // no tables yet: this trial builds (or loads) them around its start
  }
  return found->second;
}

/// Runs pending trial `i` on `registrationCase`; an exception (e.g. out of memory) makes it a Failed trial.
TrialRecord runTrialSafely(const TrialWork& work, std::size_t i, RegistrationCase& registrationCase) {
  const StudyCondition& c = *work.pending[i].condition;
  try {
    return runTrial(work.study, c, work.pending[i].trial, work.scenes.at(c.ct), registrationCase,
                    work.schedules.at(c.measures), work.options.cancel);
  } catch (const std::exception& e) {  // this trial fails, the study goes on
    return failedTrial(work.study, c, work.pending[i].trial, fmt::format("unexpected error: {}", e.what()));
  }
}

/// Counts a finished trial in the summary, adds it to the store (keeping the first store error) and reports it.
void recordTrial(TrialWork& work, const TrialRecord& record) {
  const std::lock_guard lock(work.mutex);
  ++work.summary.ran;
  if (record.status == TrialStatus::Failed) ++work.summary.failed;
  if (record.status == TrialStatus::Cancelled) work.summary.cancelled = true;
  if (Status saved = work.store.add(record); !saved && !work.storeFailed.exchange(true)) {
    work.storeError = saved.error();
  }
  ++work.finished;
  if (work.options.onTrial) {
    work.options.onTrial(StudyProgress{work.finished, static_cast<int>(work.pending.size()), record});
  }
}

/// One worker: takes the next pending trial until none is left, the store failed or the run is cancelled.
void workOnTrials(TrialWork& work) {
  const bool tablePerTrial = work.study.setup.method == DrrMethod::Transgraph;
  std::map<std::string, RegistrationCase> ownCases;
  for (;;) {
    const std::size_t i = work.next.fetch_add(1);
    if (i >= work.pending.size() || work.storeFailed.load() || cancelRequested(work.options)) return;
    const StudyCondition& c = *work.pending[i].condition;
    const std::string key = caseKey(c, *work.scenes.at(c.ct).ct);
    RegistrationCase& registrationCase = caseForTrial(ownCases, key, work.prototypes, tablePerTrial);
    recordTrial(work, runTrialSafely(work, i, registrationCase));
  }
}

/// Runs the pending trials on min(jobs, trials) workers (the calling thread when one). Fails when the store could
/// not be written.
Status runTrials(TrialWork& work) {
  const int threads = std::min<int>(work.options.jobs, static_cast<int>(work.pending.size()));
  if (threads == 1) {
    workOnTrials(work);
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back([&work] { workOnTrials(work); });
    for (std::thread& thread : pool) thread.join();
  }
  if (work.storeFailed) return fail("cannot save the trials: " + work.storeError);
  return Ok{};
}

}  // namespace

Result<Eigen::Isometry3d> StudyRunner::startPose(const StudyCondition& c, const BoneSurface& bone,
                                                 const Eigen::Isometry3d& T_truth, const std::vector<Camera>& cameras,
                                                 std::uint32_t seed, double& initialTarget_mm) {
  SeededRandom random(seed ^ 0x5BD1E995u);
  switch (c.start) {
    case StudyStart::SurfaceDistance:
      initialTarget_mm = c.initialLow_mm + (c.initialHigh_mm - c.initialLow_mm) * random.uniform01();
      return PoseOffset::randomAtSurfaceDistance(bone, T_truth, initialTarget_mm, seed);
    case StudyStart::Rotation: {
      initialTarget_mm = std::numeric_limits<double>::quiet_NaN();
      const double angle_deg = random.uniform(c.rotationLow_deg, c.rotationHigh_deg);
      // A uniform random axis: the direction of a 3-D standard normal vector.
      Eigen::Vector3d axis(random.normal(), random.normal(), random.normal());
      if (axis.norm() < 1e-12) axis = Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d centre_world_mm = T_truth * bone.centroid_ct_mm();
      Eigen::Isometry3d rotation = Eigen::Isometry3d::Identity();
      rotation.linear() = Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
      rotation.translation() = centre_world_mm - rotation.linear() * centre_world_mm;
      return Eigen::Isometry3d(rotation * T_truth);
    }
    case StudyStart::SupineSetup:
      initialTarget_mm = std::numeric_limits<double>::quiet_NaN();
      return SetupPose::supineAtIsocentre(bone.centroid_ct_mm(), cameras);
  }
  return fail("unknown start kind");
}

Eigen::Isometry3d StudyRunner::trialTruthPose(const BoneSurface& bone, std::uint32_t seed) {
  SeededRandom random(SeededRandom::streamSeed(seed, 0x7455u));
  PoseParameters move;
  for (int a = 0; a < 3; ++a) move.rotation_deg[a] = random.uniform(-kTrialSpread_deg, kTrialSpread_deg);
  for (int a = 0; a < 3; ++a) move.translation_mm[a] = random.uniform(-kTrialSpread_mm, kTrialSpread_mm);
  const Eigen::Isometry3d T_truth = truthPose(bone);
  // The move about the bone centre in the world: M(p) = R (p - c_world) + c_world + t.
  const Eigen::Vector3d centre_world_mm = T_truth * bone.centroid_ct_mm();
  return Eigen::Isometry3d(RigidPose::toTransform(move, centre_world_mm) * T_truth);
}

std::uint32_t StudyRunner::trialXraySeed(std::uint32_t seed) { return SeededRandom::streamSeed(seed, 0x58524159u); }

Eigen::Isometry3d StudyRunner::truthPose(const BoneSurface& bone) {
  const Eigen::Vector3d centre_ct_mm = bone.centroid_ct_mm();
  PoseParameters truth;
  truth.rotation_deg = Eigen::Vector3d(4.0, -3.0, 6.0);
  truth.translation_mm = -centre_ct_mm + Eigen::Vector3d(2.0, -3.0, 1.5);
  return RigidPose::toTransform(truth, centre_ct_mm);
}

void StudyRunner::resolveSliceSpacings(StudyDefinition& study, const std::vector<StudyCt>& cts) {
  for (StudyCondition& c : study.conditions) {
    const auto ct = std::find_if(cts.begin(), cts.end(), [&](const StudyCt& s) { return s.label == c.ct; });
    if (ct == cts.end()) continue;
    const double resampled_mm = StudyXraySource::effectiveSliceSpacing_mm(ct->volume, c.sliceSpacing_mm);
    c.usedSliceSpacing_mm = resampled_mm > 0.0 ? resampled_mm : ct->volume.spacing_mm().z();
  }
}

std::vector<std::string> StudyRunner::notes(const StudyDefinition& study, const std::vector<StudyCt>& cts) {
  std::vector<std::string> out{"X-rays: " + StudyXraySource::description()};
  out.push_back(study.setup.xraysPerTrial
                    ? fmt::format("every trial registers against X-rays of its own, all from its seed: the bone at the "
                                  "study's true pose moved within +-{:g} mm and +-{:g} deg per axis about its centre, "
                                  "its own foreign-object placement and noise (trial t of every condition: the same "
                                  "pose and noise)",
                                  kTrialSpread_mm, kTrialSpread_deg)
                    : "every trial of a CT registers against one X-ray set simulated at the study's true pose "
                      "(--one-xray-set): a condition's mean is one realization's optimum plus the search's spread");
  if (study.setup.method == DrrMethod::Transgraph) {
    out.push_back(fmt::format("DRRs: transgraph method, tables at a {:g} mm step built around each trial's start pose "
                              "(not the truth) and cached in {}; the 'setup s' column is their build or load time, "
                              "not part of the registration time",
                              study.setup.transgraphSpacing_mm,
                              study.setup.transgraphCacheDir.empty() ? std::string("no cache")
                                                                     : study.setup.transgraphCacheDir.string()));
  } else {
    out.push_back(fmt::format("DRRs: {} method", DrrRendererFactory::methodName(study.setup.method)));
  }
  if (auto schedule = RegistrationSchedule::resolve(study.setup.preset)) {
    for (const std::string& note : schedule.value().stageDrrNotes()) {
      out.push_back("the preset's " + note + ", whatever the study's");
    }
  }
  std::set<std::string> said;
  for (const StudyCondition& c : study.conditions) {
    const auto ct = std::find_if(cts.begin(), cts.end(), [&](const StudyCt& s) { return s.label == c.ct; });
    if (ct == cts.end() || c.sliceSpacing_mm <= 0.0 ||
        StudyXraySource::effectiveSliceSpacing_mm(ct->volume, c.sliceSpacing_mm) > 0.0) {
      continue;
    }
    const std::string key = fmt::format("{}|{}", c.ct, c.sliceSpacing_mm);
    if (!said.insert(key).second) continue;
    out.push_back(fmt::format("CT '{}' has {:g} mm slices already, so scenario '{}' ({:g} mm) registers on the original "
                              "CT",
                              c.ct, ct->volume.spacing_mm().z(), c.scenario, c.sliceSpacing_mm));
  }
  return out;
}

RegistrationSchedule StudyRunner::scheduleFor(const RegistrationSchedule& base, StudyMeasures measures) {
  RegistrationSchedule schedule = base;
  if (measures == StudyMeasures::Both) return schedule;
  const SimilarityMetric metric = measures == StudyMeasures::NccOnly ? SimilarityMetric::Ncc : SimilarityMetric::Vlnc;
  for (RegistrationStage& stage : schedule.stages) stage.metric = metric;
  schedule.name += measures == StudyMeasures::NccOnly ? " (ncc only)" : " (vlnc only)";
  return schedule;
}

Result<StudyRunSummary> StudyRunner::run(const StudyDefinition& study, const std::vector<StudyCt>& cts,
                                         TrialStore& store, const StudyRunOptions& options) {
  if (Status valid = validate(study, cts, options); !valid) return fail(valid.error());
  auto baseSchedule = RegistrationSchedule::resolve(study.setup.preset);
  if (!baseSchedule) return fail(baseSchedule.error());

  StudyRunSummary summary;
  const std::vector<PendingTrial> pending = findPendingTrials(study, options.shard, store, summary.skipped);
  if (summary.skipped > 0) {
    say(options, fmt::format("{} trials already in {}; skipping them", summary.skipped, store.path().string()));
  }
  if (pending.empty()) return summary;
  auto scenes = simulateScenes(study, cts, pending, options);
  if (!scenes) return fail(scenes.error());
  auto prototypes = prepareCases(study, pending, scenes.value(), options);
  if (!prototypes) return fail(prototypes.error());
  TrialWork work{study, pending, scenes.value(), prototypes.value(), schedulesFor(baseSchedule.value()), options,
                 store, summary};
  if (Status saved = runTrials(work); !saved) return fail(saved.error());
  summary.cancelled = summary.cancelled || cancelRequested(options);
  return summary;
}

}  // namespace fct
