#include "Evaluation/TrackingStudy.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>

#include "Evaluation/PoseErrorMetrics.h"
#include "Evaluation/StudyXraySource.h"
#include "Registration/RegistrationCase.h"
#include "Simulation/StandardViews.h"

namespace fct {

namespace {

/// The study's CT-side preparation shared by its sequences: error measures and the true pose of the motion's base.
struct TrackingScene {
  const Volume* ct = nullptr;
  std::unique_ptr<PoseErrorMetrics> metrics;
  Eigen::Isometry3d T_base = Eigen::Isometry3d::Identity();
};

TrackingCondition condition(const std::string& ct, int views, int detector_px, double pixel_mm) {
  TrackingCondition c;
  c.ct = ct;
  c.viewCount = views;
  c.detector_px = detector_px;
  c.pixelSpacing_mm = pixel_mm;
  c.name = fmt::format("{}/{}-{}", ct, views == 1 ? "single" : "biplane", detector_px);
  return c;
}

/// Checks every condition and the shared settings before any work.
Status validate(const TrackingStudyDefinition& study, const std::vector<StudyCt>& cts) {
  if (study.conditions.empty()) return fail("the tracking study has no condition");
  if (auto motion = BoneMotion::create(study.motion); !motion) return fail("bone motion: " + motion.error());
  if (!(study.initialStre_mm >= 0.0) || !std::isfinite(study.initialStre_mm)) {
    return fail(fmt::format("frame 0's initial sTRE must be finite and >= 0 mm, got {}", study.initialStre_mm));
  }
  std::set<std::string> names;
  for (const TrackingCondition& c : study.conditions) {
    if (!names.insert(c.name).second) return fail(fmt::format("tracking condition '{}' appears twice", c.name));
    if (std::none_of(cts.begin(), cts.end(), [&](const StudyCt& ct) { return ct.label == c.ct; })) {
      return fail(fmt::format("tracking condition '{}': no CT labelled '{}' was given", c.name, c.ct));
    }
    if (c.viewCount < 1 || c.viewCount > 2) {
      return fail(fmt::format("tracking condition '{}': {} views; use 1 (single-plane) or 2 (biplane)", c.name,
                              c.viewCount));
    }
    if (c.sequences < 1) return fail(fmt::format("tracking condition '{}': {} sequences; use at least 1", c.name, c.sequences));
    if (c.detector_px < 8 || !(c.pixelSpacing_mm > 0.0) || !std::isfinite(c.pixelSpacing_mm)) {
      return fail(fmt::format("tracking condition '{}': detector {} px at {} mm; use >= 8 px and a positive pixel size",
                              c.name, c.detector_px, c.pixelSpacing_mm));
    }
  }
  return Ok{};
}

/// The condition's standard views (AP; AP and lateral) about the isocentre at the world origin.
Result<std::vector<ViewSpec>> viewsFor(const TrackingStudyDefinition& study, const TrackingCondition& c) {
  StandardViewOptions o;
  o.count = c.viewCount;
  o.cols = o.rows = c.detector_px;
  o.pixelSpacing_mm = c.pixelSpacing_mm;
  o.sourceToDetector_mm = study.sourceToDetector_mm;
  o.sourceToIsocentre_mm = study.sourceToIsocentre_mm;
  return StandardViews::build(Eigen::Vector3d::Zero(), o);
}

/// Which frame of which sequence a record is.
struct FrameKey {
  const TrackingCondition& condition;
  int sequence = 0;
  std::uint32_t seed = 0;
  int frames = 0;
  int frame = 0;
};

/// A record holding only the frame's identification.
TrackingFrameRecord identifiedFrame(const FrameKey& key) {
  TrackingFrameRecord r;
  r.condition = key.condition.name;
  r.ct = key.condition.ct;
  r.views = key.condition.viewCount;
  r.sequence = key.sequence;
  r.frames = key.frames;
  r.frame = key.frame;
  r.seed = key.seed;
  return r;
}

/// The frame's record without the tracker's part: identification and the errors of `T_estimate`.
TrackingFrameRecord measuredFrame(const FrameKey& key, const TrackingScene& scene, const std::vector<ViewSpec>& views,
                                  const Eigen::Isometry3d& T_truth, const Eigen::Isometry3d& T_firstTruth,
                                  const Eigen::Isometry3d& T_start, const Eigen::Isometry3d& T_estimate) {
  TrackingFrameRecord r = identifiedFrame(key);
  r.motionFromFirst_mm = scene.metrics->measure(T_truth, T_firstTruth).streMean_mm;
  r.initialStre_mm = scene.metrics->measure(T_start, T_truth).streMean_mm;
  const PoseError error = scene.metrics->measure(T_estimate, T_truth);
  r.streMean_mm = error.streMean_mm;
  r.streMax_mm = error.streMax_mm;
  r.rotation_deg = error.rotation_deg;
  r.translation_mm = error.translation_mm;
  if (key.condition.viewCount == 1) {
    const ViewPlaneError inView =
        scene.metrics->measureInView(T_estimate, T_truth, views.front().camera.T_world_from_camera().translation());
    r.inPlane_mm = inView.inPlaneMean_mm;
    r.outOfPlane_mm = inView.outOfPlaneMean_mm;
  } else {
    r.inPlane_mm = r.outOfPlane_mm = std::numeric_limits<double>::quiet_NaN();
  }
  return r;
}

/// Folds the tracker's frame into `r`.
void addTrackerPart(const TrackedFrame& f, TrackingFrameRecord& r) {
  r.status = CineTracker::statusName(f.status);
  r.cancelled = f.cancelled;
  r.similarity = f.similarity;
  r.seconds = f.seconds;
  r.cpuSeconds = f.cpuSeconds;
  r.drrs = f.drrs;
}

/// The record of a frame the tracker returned an error for (NaN errors, status "failed").
TrackingFrameRecord failedFrame(const FrameKey& key, const std::string& reason) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  TrackingFrameRecord r = identifiedFrame(key);
  r.status = "failed";
  r.similarity = r.seconds = r.cpuSeconds = nan;
  r.motionFromFirst_mm = r.initialStre_mm = r.streMean_mm = r.streMax_mm = nan;
  r.inPlane_mm = r.outOfPlane_mm = r.rotation_deg = r.translation_mm = nan;
  r.reason = reason;
  return r;
}

/// Simulates and tracks one sequence. Fails on a simulation or case preparation error; a tracker error ends the
/// sequence with a "failed" frame.
Result<std::vector<TrackingFrameRecord>> runSequence(const TrackingStudyDefinition& study, const TrackingCondition& c,
                                                     int sequence, const TrackingScene& scene,
                                                     const CineTrackerOptions& trackerOptions,
                                                     const TrackingRunOptions& options) {
  const std::uint32_t seed = study.seed + static_cast<std::uint32_t>(sequence);
  auto views = viewsFor(study, c);
  if (!views) return fail(views.error());
  BoneMotionOptions motionOptions = study.motion;
  motionOptions.seed = seed;
  auto motion = BoneMotion::create(motionOptions);
  if (!motion) return fail(motion.error());
  const std::vector<Eigen::Isometry3d> truth =
      motion.value().poses(scene.T_base, scene.metrics->surface().centroid_ct_mm());
  const int frames = motion.value().frameCount();

  if (options.onMessage) options.onMessage(fmt::format("{} sequence {}: simulating {} frames", c.name, sequence, frames));
  std::vector<std::vector<XrayImage>> images;
  const Status simulated = StudyXraySource::simulateSequence(*scene.ct, views.value(), truth, seed, c.foreignObjects,
                                                             [&](int, std::vector<XrayImage> xrays) -> Status {
                                                               images.push_back(std::move(xrays));
                                                               return Ok{};
                                                             });
  if (!simulated) return fail(fmt::format("condition '{}': {}", c.name, simulated.error()));

  std::vector<RegistrationView> firstViews;
  for (std::size_t v = 0; v < views.value().size(); ++v) {
    firstViews.push_back(RegistrationView{views.value()[v].name, images[0][v], views.value()[v].camera, {}});
  }
  auto registrationCase = RegistrationCase::create(*scene.ct, firstViews);  // the default cut-face margin
  if (!registrationCase) return fail(fmt::format("condition '{}': {}", c.name, registrationCase.error()));
  auto tracker = CineTracker::create(registrationCase.value(), trackerOptions);
  if (!tracker) return fail(fmt::format("condition '{}': {}", c.name, tracker.error()));

  StudyCondition start;  // the studies' start: a random pose at a fixed mean sTRE from frame 0's truth
  start.initialLow_mm = start.initialHigh_mm = study.initialStre_mm;
  std::vector<Camera> cameras;
  for (const ViewSpec& spec : views.value()) cameras.push_back(spec.camera);
  double target_mm = 0.0;
  auto T_start = StudyRunner::startPose(start, scene.metrics->surface(), truth[0], cameras, seed, target_mm);
  if (!T_start) return fail(T_start.error());

  std::vector<TrackingFrameRecord> out;
  for (int k = 0; k < frames; ++k) {
    if (options.onMessage) options.onMessage(fmt::format("{} sequence {}: tracking frame {}", c.name, sequence, k));
    auto tracked = k == 0 ? tracker.value().trackFirst(T_start.value(), options.cancel)
                          : tracker.value().trackNext(images[k], options.cancel);
    const FrameKey key{c, sequence, seed, frames, k};
    if (!tracked) {
      out.push_back(failedFrame(key, tracked.error()));
      break;
    }
    const TrackedFrame& f = tracked.value();
    TrackingFrameRecord r = measuredFrame(key, scene, views.value(), truth[k], truth[0], f.T_predicted_world_from_ct,
                                          f.T_world_from_ct);
    addTrackerPart(f, r);
    out.push_back(r);
    if (f.cancelled) break;
  }
  return out;
}

}  // namespace

Result<TrackingStudyDefinition> TrackingStudy::define(bool quick, const std::vector<std::string>& ctLabels) {
  if (ctLabels.empty()) return fail("the tracking study needs at least one CT");
  TrackingStudyDefinition d;
  d.quick = quick;
  d.title = "Cine tracking: a moving bone (smooth motion within +-15 mm and +-10 deg per axis, and a jerk), "
            "single-plane and biplane";
  d.motion.maxTranslation_mm = 15.0;
  d.motion.maxRotation_deg = 10.0;
  d.motion.jerkFrames = 2;
  d.motion.jerkTranslation_mm = 4.0;
  d.motion.jerkRotation_deg = 3.0;
  if (quick) {
    d.preset = "fast";
    d.sourceToDetector_mm = 1000.0;
    d.sourceToIsocentre_mm = 700.0;
    d.motion.frames = 5;
    d.motion.jerkFrame = 3;
  } else {
    d.motion.frames = 40;
    d.motion.jerkFrame = 20;
  }
  for (const std::string& ct : ctLabels) {
    d.conditions.push_back(quick ? condition(ct, 1, 96, 2.4) : condition(ct, 1, 512, 0.45));
    d.conditions.push_back(quick ? condition(ct, 2, 64, 3.6) : condition(ct, 2, 256, 0.9));
  }
  return d;
}

Result<CineTrackerOptions> TrackingStudy::trackerOptions(const TrackingStudyDefinition& study) {
  auto schedule = RegistrationSchedule::resolve(study.preset);
  if (!schedule) return fail(schedule.error());
  CineTrackerOptions o;
  o.firstFrame.schedule = schedule.value();
  return o;
}

std::vector<std::string> TrackingStudy::notes(const TrackingStudyDefinition& study) {
  const BoneMotionOptions& m = study.motion;
  std::vector<std::string> out{"X-rays: " + StudyXraySource::description()};
  out.push_back(fmt::format(
      "motion: {} frames per sequence about the bone centre, each parameter a sum of {} sinusoids (periods {:g}-{:g} "
      "frames) within +-{:g} mm and +-{:g} deg, plus a jerk of {:g} mm and {:g} deg ramped in over {} frame(s) from "
      "frame {}; each frame and view its own noise; C-arm SID {:g} mm, SAD {:g} mm (AP; AP and lateral)",
      m.frames, m.sinusoids, m.minPeriod_frames, m.maxPeriod_frames, m.maxTranslation_mm, m.maxRotation_deg,
      m.jerkTranslation_mm, m.jerkRotation_deg, m.jerkFrames, m.jerkFrame, study.sourceToDetector_mm,
      study.sourceToIsocentre_mm));
  const CineTrackerOptions trackerDefaults;
  out.push_back(fmt::format("frame 0: registered with the '{}' preset from a random pose at {:g} mm mean sTRE from its "
                            "truth, Siddon DRRs; later frames: CineTracker defaults (constant-velocity prediction, "
                            "single-plane with {:g} of the motion along the viewing ray; local search on VLNC ROIs of "
                            "{:g} % of the valid pixels at the finest pyramid level at most {} px across, single-plane "
                            "on trilinear DRRs (a sample every {:g} coarse voxels) with a {:g}x step along the ray, "
                            "biplane on Siddon DRRs; recovery when lost); registration on the original CT",
                            study.preset, study.initialStre_mm, trackerDefaults.depthVelocityFactor,
                            100.0 * trackerDefaults.roiFraction, CineTracker::kAutomaticLevelSide_px,
                            CineTrackerOptions::kFrameRayCastStep_voxels, trackerDefaults.depthScale));
  if (auto schedule = RegistrationSchedule::resolve(study.preset)) {
    for (const std::string& note : schedule.value().stageDrrNotes()) out.push_back("frame 0: the preset's " + note);
  }
  return out;
}

Result<TrackingRunSummary> TrackingStudy::run(const TrackingStudyDefinition& study, const std::vector<StudyCt>& cts,
                                              TrackingFrameStore& store, const TrackingRunOptions& options) {
  if (Status valid = validate(study, cts); !valid) return fail(valid.error());
  auto trackerSettings = trackerOptions(study);
  if (!trackerSettings) return fail(trackerSettings.error());

  TrackingRunSummary summary;
  std::vector<std::pair<const TrackingCondition*, int>> pending;
  for (const TrackingCondition& c : study.conditions) {
    for (int s = 0; s < c.sequences; ++s) {
      if (store.isDone(c.name, s)) {
        ++summary.skipped;
      } else {
        pending.emplace_back(&c, s);
      }
    }
  }
  std::map<std::string, TrackingScene> scenes;
  for (const auto& [c, s] : pending) {
    if (scenes.count(c->ct)) continue;
    const StudyCt& ct = *std::find_if(cts.begin(), cts.end(), [&label = c->ct](const StudyCt& x) { return x.label == label; });
    auto metrics = PoseErrorMetrics::create(ct.volume);
    if (!metrics) return fail(fmt::format("CT '{}': {}", ct.label, metrics.error()));
    TrackingScene scene;
    scene.ct = &ct.volume;
    scene.metrics = std::make_unique<PoseErrorMetrics>(std::move(metrics).value());
    scene.T_base = StudyRunner::truthPose(scene.metrics->surface());
    scenes.emplace(ct.label, std::move(scene));
  }
  for (const auto& [c, s] : pending) {
    if (options.cancel && options.cancel->load()) break;
    auto frames = runSequence(study, *c, s, scenes.at(c->ct), trackerSettings.value(), options);
    if (!frames) return fail(frames.error());
    if (Status saved = store.addSequence(frames.value()); !saved) return fail("cannot save the frames: " + saved.error());
    ++summary.ran;
    if (options.onSequence) options.onSequence(TrackingProgress{summary.ran, static_cast<int>(pending.size()), frames.value()});
  }
  summary.cancelled = options.cancel && options.cancel->load();
  return summary;
}

}  // namespace fct
