#include "Tracking/CineTracker.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <algorithm>
#include <ctime>
#include <utility>

#include "Drr/DrrRendererFactory.h"
#include "Geometry/RigidPose.h"
#include "Registration/RegistrationObjective.h"

namespace fct {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double cpuSecondsSince(std::clock_t start) { return static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC; }

/// Fails naming the option unless every tracker option is in range (the level is checked against the case).
Status checkOptions(const CineTrackerOptions& o, int levelCount) {
  if (o.level < 0 || o.level >= levelCount) {
    return fail(fmt::format("tracking level {} does not exist; the case's pyramid has levels 0 to {} (or -1: "
                            "automatic)", o.level, levelCount - 1));
  }
  if (o.windowSize < 2 || o.windowSize > 64) return fail(fmt::format("tracking window must be 2..64 pixels, got {}", o.windowSize));
  if (!(o.roiFraction > 0.0 && o.roiFraction <= 1.0)) {
    return fail(fmt::format("tracking ROI fraction must be in (0, 1], got {}", o.roiFraction));
  }
  if (o.refineEvaluations < 0) {
    return fail(fmt::format("tracking refinement cap must be >= 0 (0 = none), got {}", o.refineEvaluations));
  }
  if (o.maxEvaluations <= 0) return fail(fmt::format("tracking evaluation cap must be > 0, got {}", o.maxEvaluations));
  if (!(o.initialStep > 0.0) || !(o.tolerance > 0.0) || !(o.tolerance < o.initialStep)) {
    return fail(fmt::format("tracking step {} and tolerance {} must be positive with the tolerance below the step",
                            o.initialStep, o.tolerance));
  }
  if (!(o.dissimilarityGrowth > 1.0 && std::isfinite(o.dissimilarityGrowth))) {
    return fail(fmt::format("lost-track dissimilarity growth must be above 1, got {}", o.dissimilarityGrowth));
  }
  if (!(o.depthVelocityFactor >= 0.0 && o.depthVelocityFactor <= 1.0)) {
    return fail(fmt::format("single-plane depth velocity factor must be in [0, 1], got {}", o.depthVelocityFactor));
  }
  if (!(o.depthScale >= 1.0 && o.depthScale <= 100.0)) {
    return fail(fmt::format("single-plane depth scale must be in [1, 100], got {}", o.depthScale));
  }
  if (o.frameDrr != DrrMethod::RayCast && o.frameDrr != DrrMethod::Siddon) {
    return fail(fmt::format("the frame stage renders exactly with raycast or siddon, not {}",
                            DrrRendererFactory::methodName(*o.frameDrr)));
  }
  if (!(o.levelWeight > 0.0 && o.levelWeight <= 1.0)) {
    return fail(fmt::format("running-level weight must be in (0, 1], got {}", o.levelWeight));
  }
  if (!(o.maxJump_mm > 0.0) || !(o.maxJump_deg > 0.0)) {
    return fail(fmt::format("lost-track jump limits must be positive, got {} mm and {} deg", o.maxJump_mm, o.maxJump_deg));
  }
  if (!(o.confirmTolerance_mm > 0.0) || !(o.confirmTolerance_deg > 0.0)) {
    return fail(fmt::format("lost-track confirmation tolerances must be positive, got {} mm and {} deg",
                            o.confirmTolerance_mm, o.confirmTolerance_deg));
  }
  return Ok{};
}

/// The automatic tracking level of the case: the finest whose image is at most kAutomaticLevelSide_px on its shorter
/// side in every view, else the coarsest.
int automaticLevel(const RegistrationCase& registrationCase) {
  const int levels = registrationCase.levelCount();
  for (int level = 0; level < levels; ++level) {
    bool small = true;
    for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) {
      const FloatImage& image = registrationCase.prepared(v).pyramid.level(level).image;
      small = small && std::min(image.cols, image.rows) <= CineTracker::kAutomaticLevelSide_px;
    }
    if (small) return level;
  }
  return levels - 1;
}

/// Makes `stage` render exactly with the options' (resolved) frame DRR method.
void renderExactly(const CineTrackerOptions& o, RegistrationStage& stage) {
  stage.exactDrr = true;
  stage.drrMethod = o.frameDrr;
  stage.drrStep_voxels = o.frameDrr == DrrMethod::RayCast ? CineTrackerOptions::kFrameRayCastStep_voxels : 0.0;
}

/// The frame schedule of the options on a case rendered with `caseMethod`: VLNC on dynamic ROIs at the tracking level
/// with one local BOBYQA search (on the Transgraph tables, or exactly with frameDrr), then with refineEvaluations > 0
/// the same rendered exactly, with a smaller step and that cap.
RegistrationSchedule frameScheduleOf(const CineTrackerOptions& o, DrrMethod caseMethod) {
  RegistrationStage stage;
  stage.name = fmt::format("track-vlnc-rois-level{}", o.level);
  stage.metric = SimilarityMetric::Vlnc;
  stage.level = o.level;
  if (o.exactDrr || caseMethod != DrrMethod::Transgraph) renderExactly(o, stage);
  stage.depthScale = o.depthScale;
  stage.pixels.kind = PixelSetKind::Rois;
  stage.pixels.windowSize = o.windowSize;
  stage.pixels.targetFraction = o.roiFraction;
  stage.search = SearchStrategy::Local;
  stage.maxEvaluations = o.maxEvaluations;
  stage.simplex.method = LocalSearchMethod::Bobyqa;
  stage.simplex.initialStep = o.initialStep;
  stage.simplex.tolerance = o.tolerance;
  stage.simplex.maxEvaluations = o.maxEvaluations;
  stage.simplex.restarts = 0;
  RegistrationSchedule schedule;
  schedule.name = "tracking";
  schedule.stages = {stage};
  if (o.refineEvaluations > 0) {
    stage.name += "-exact";
    renderExactly(o, stage);
    stage.maxEvaluations = stage.simplex.maxEvaluations = o.refineEvaluations;
    stage.simplex.initialStep = std::max(2.0 * o.tolerance, 0.5 * o.initialStep);
    schedule.stages.push_back(stage);
  }
  return schedule;
}

}  // namespace

const char* CineTracker::statusName(TrackedFrameStatus status) {
  switch (status) {
    case TrackedFrameStatus::Tracked: return "tracked";
    case TrackedFrameStatus::Recovered: return "recovered";
    case TrackedFrameStatus::Lost: break;
  }
  return "lost";
}

CineTracker::CineTracker(RegistrationCase& registrationCase, CineTrackerOptions options,
                         RegistrationSchedule frameSchedule)
    : m_case(&registrationCase), m_options(std::move(options)), m_frameSchedule(std::move(frameSchedule)) {
  m_recoverySchedule.name = m_options.firstFrame.schedule.name + "-recovery";
  for (const RegistrationStage& stage : m_options.firstFrame.schedule.stages) {
    if (stage.search != SearchStrategy::Local) m_recoverySchedule.stages.push_back(stage);
  }
  m_recoverySchedule.stages.insert(m_recoverySchedule.stages.end(), m_frameSchedule.stages.begin(),
                                   m_frameSchedule.stages.end());
}

Result<CineTracker> CineTracker::create(RegistrationCase& registrationCase, const CineTrackerOptions& options) {
  CineTrackerOptions resolved = options;
  if (resolved.level == CineTrackerOptions::kAutomaticLevel) resolved.level = automaticLevel(registrationCase);
  if (!resolved.frameDrr) {
    resolved.frameDrr = registrationCase.viewCount() == 1 ? DrrMethod::RayCast : DrrMethod::Siddon;
  }
  if (Status valid = checkOptions(resolved, registrationCase.levelCount()); !valid) return fail(valid.error());
  if (resolved.firstFrame.schedule.stages.empty()) {
    auto schedule = RegistrationSchedule::builtin(RegistrationSchedule::kDefaultPreset);
    if (!schedule) return fail(schedule.error());
    resolved.firstFrame.schedule = std::move(schedule).value();
  }
  RegistrationSchedule frameSchedule = frameScheduleOf(resolved, registrationCase.drrMethod());
  return CineTracker(registrationCase, std::move(resolved), std::move(frameSchedule));
}

Status CineTracker::runSchedule(const RegistrationSchedule& schedule, const Eigen::Isometry3d& T_start,
                                const std::atomic<bool>* cancel, TrackedFrame& frame) {
  RegistrationOptions options = m_options.firstFrame;
  options.schedule = schedule;
  options.checkOverlap = false;  // the start is a tracked pose; the check would cost a whole-level DRR per frame
  auto result = Registration::run(*m_case, T_start, options, {}, cancel);
  if (!result) return fail(result.error());
  const RegistrationResult& r = result.value();
  frame.T_world_from_ct = r.T_world_from_ct;
  frame.drrs += r.totalDrrs;
  for (const StageReport& stage : r.stages) frame.fallbackRays += stage.fallbackRays;
  if (!r.stages.empty()) frame.similarity = r.stages.back().similarity;
  frame.cancelled = frame.cancelled || r.cancelled;
  return Ok{};
}

Eigen::Isometry3d CineTracker::predictedPose() const {
  if (!m_options.constantVelocity || !m_T_beforePrevious) return *m_T_previous;
  const Eigen::Vector3d& centre_ct_mm = m_case->rotationCentre_ct_mm();
  auto p1 = RigidPose::fromTransform(*m_T_previous, centre_ct_mm);
  auto p0 = RigidPose::fromTransform(*m_T_beforePrevious, centre_ct_mm);
  if (!p1 || !p0) return *m_T_previous;
  const PoseVector next = 2.0 * p1.value().asVector() - p0.value().asVector();
  Eigen::Isometry3d T_predicted = RigidPose::toTransform(PoseParameters::fromVector(next), centre_ct_mm);
  if (m_case->viewCount() == 1) {
    const Eigen::Vector3d centre_world_mm = *m_T_previous * centre_ct_mm;
    const Eigen::Vector3d ray_world = (centre_world_mm - m_case->camera(0).sourcePosition_world_mm()).normalized();
    const double alongRay_mm = (T_predicted * centre_ct_mm - centre_world_mm).dot(ray_world);
    T_predicted.pretranslate(-(1.0 - m_options.depthVelocityFactor) * alongRay_mm * ray_world);
  }
  return T_predicted;
}

CineTracker::PoseDistance CineTracker::distanceBetween(const Eigen::Isometry3d& T_a_world_from_ct,
                                                       const Eigen::Isometry3d& T_b_world_from_ct) const {
  const Eigen::Vector3d& c = m_case->rotationCentre_ct_mm();
  const Eigen::Isometry3d T_b_from_a = T_b_world_from_ct * T_a_world_from_ct.inverse();
  return {(T_b_world_from_ct * c - T_a_world_from_ct * c).norm(),
          Eigen::AngleAxisd(T_b_from_a.rotation()).angle() * 180.0 / M_PI};
}

bool CineTracker::withinJumpLimits(const TrackedFrame& frame) const {
  const PoseDistance jump = distanceBetween(frame.T_predicted_world_from_ct, frame.T_world_from_ct);
  return jump.move_mm <= m_options.maxJump_mm && jump.turn_deg <= m_options.maxJump_deg;
}

bool CineTracker::withinBounds(const TrackedFrame& frame) const {
  return m_level.holds(frame.similarity) && withinJumpLimits(frame);
}

TrackedFrameStatus CineTracker::judgeRecovery(const Eigen::Isometry3d& T_searched_world_from_ct, TrackedFrame& frame) {
  const bool withinJumps = withinJumpLimits(frame);
  if (withinJumps && m_level.holds(frame.similarity)) return TrackedFrameStatus::Recovered;
  if (frame.cancelled || !withinJumps || !m_level.fellGradually(frame.similarity)) return TrackedFrameStatus::Lost;
  const PoseDistance apart = distanceBetween(T_searched_world_from_ct, frame.T_world_from_ct);
  if (apart.move_mm > m_options.confirmTolerance_mm || apart.turn_deg > m_options.confirmTolerance_deg) {
    return TrackedFrameStatus::Lost;
  }
  frame.note = fmt::format("similarity {:.4f} fell gradually (last frame {:.4f}) below the level; the re-registration "
                           "confirmed the tracked pose ({:.2f} mm, {:.2f} deg apart): level re-anchored here",
                           frame.similarity, m_level.last(), apart.move_mm, apart.turn_deg);
  m_level.reanchor(frame.similarity);
  return TrackedFrameStatus::Recovered;
}

Result<TrackedFrame> CineTracker::trackFirst(const Eigen::Isometry3d& T_initial, const std::atomic<bool>* cancel) {
  const auto start = Clock::now();
  const std::clock_t cpuStart = std::clock();
  TrackedFrame frame;
  frame.index = 0;
  frame.T_predicted_world_from_ct = T_initial;
  auto result = Registration::run(*m_case, T_initial, m_options.firstFrame, {}, cancel);
  if (!result) return fail("frame 0: " + result.error());
  frame.T_world_from_ct = result.value().T_world_from_ct;
  frame.drrs = result.value().totalDrrs;
  frame.cancelled = result.value().cancelled;
  // The running level starts at the last frame stage's similarity at the registered pose (the stage's own metric).
  const RegistrationStage& judged = m_frameSchedule.stages.back();
  auto objective = RegistrationObjective::create(*m_case, judged, !judged.exactDrr,
                                                 frame.T_world_from_ct, frame.T_world_from_ct);
  if (!objective) return fail("frame 0: " + objective.error());
  auto similarity = objective.value().similarity(frame.T_world_from_ct);
  if (!similarity) return fail("frame 0: " + similarity.error());
  frame.drrs += objective.value().drrCount();
  frame.similarity = similarity.value();
  m_level = SimilarityLevel(frame.similarity, m_options.dissimilarityGrowth, m_options.levelWeight);
  frame.runningLevel = frame.similarity;
  m_T_previous = frame.T_world_from_ct;
  m_T_beforePrevious.reset();
  m_nextIndex = 1;
  frame.seconds = secondsSince(start);
  frame.cpuSeconds = cpuSecondsSince(cpuStart);
  return frame;
}

Result<TrackedFrame> CineTracker::trackNext(const std::vector<XrayImage>& frameImages, const std::atomic<bool>* cancel) {
  if (!m_T_previous) return fail("tracking: register the first frame (trackFirst) before the next ones");
  if (frameImages.size() != m_case->viewCount()) {
    return fail(fmt::format("frame {}: {} images given for {} views; give one image per view", m_nextIndex,
                            frameImages.size(), m_case->viewCount()));
  }
  for (std::size_t v = 0; v < frameImages.size(); ++v) {
    const CameraIntrinsics& in = m_case->camera(v).intrinsics();
    if (frameImages[v].cols != in.cols || frameImages[v].rows != in.rows) {
      return fail(fmt::format("frame {}, view '{}': the image is {}x{} pixels but the view's detector is {}x{}",
                              m_nextIndex, m_case->viewName(v), frameImages[v].cols, frameImages[v].rows, in.cols,
                              in.rows));
    }
  }
  const auto start = Clock::now();
  const std::clock_t cpuStart = std::clock();
  TrackedFrame frame;
  frame.index = m_nextIndex;
  frame.runningLevel = m_level.running();
  frame.T_predicted_world_from_ct = frame.T_world_from_ct = predictedPose();
  Status usable = Ok{};
  for (std::size_t v = 0; v < frameImages.size() && usable; ++v) usable = m_case->replaceXray(v, frameImages[v]);
  frame.swapSeconds = secondsSince(start);

  if (usable) usable = runSchedule(m_frameSchedule, frame.T_predicted_world_from_ct, cancel, frame);
  if (usable && !frame.cancelled && !withinBounds(frame)) {
    const Eigen::Isometry3d T_searched_world_from_ct = frame.T_world_from_ct;
    usable = runSchedule(m_recoverySchedule, frame.T_predicted_world_from_ct, cancel, frame);
    if (usable) frame.status = judgeRecovery(T_searched_world_from_ct, frame);
  }
  if (!usable) {
    frame.status = TrackedFrameStatus::Lost;
    frame.note = fmt::format("frame {}: {}", frame.index, usable.error());
    frame.T_world_from_ct = frame.T_predicted_world_from_ct;
    frame.similarity = 0.0;
  }
  if (!frame.cancelled) {
    if (frame.status == TrackedFrameStatus::Lost) {
      m_T_beforePrevious.reset();  // keep the last trusted pose, drop the velocity
    } else {
      m_T_beforePrevious = m_T_previous;
      m_T_previous = frame.T_world_from_ct;
      m_level.follow(frame.similarity);
    }
  }
  ++m_nextIndex;
  frame.seconds = secondsSince(start);
  frame.cpuSeconds = cpuSecondsSince(cpuStart);
  return frame;
}

}  // namespace fct
