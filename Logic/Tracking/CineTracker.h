#pragma once
// CineTracker: follows the bone through a fluoroscopy sequence frame by frame on one RegistrationCase (CT, renderers,
// Transgraph tables and bone surface prepared once, on frame 0's images). Frame 0 is registered with a full schedule
// (the default preset). Every later frame swaps each view's X-ray for the new frame (RegistrationCase::replaceXray),
// starts from the previous pose plus a constant-velocity prediction (pose parameters about the case's rotation centre;
// with one view only a fraction of the motion along the viewing ray, which that view barely observes) and runs one
// short local search (BOBYQA) on VLNC over dynamic ROIs re-selected on the new frame (the "frame stage", run by
// Registration with RegistrationObjective, on exact DRRs of the CT coarsened to the level, trilinear with one view and
// box voxels with two, or on the Transgraph tables; with one view the search's unit along the viewing ray is
// depthScale times longer; optionally followed by an exact-DRR refinement). A frame whose
// dissimilarity (1 - similarity) grows beyond dissimilarityGrowth times the reference (the smaller of the running level's
// and frame 0's, so that a slow fall cannot drag the reference down with it; SimilarityLevel), or whose pose differs
// from the prediction by more than the jump limits, is re-registered from the prediction with the global stage(s) of
// the first-frame schedule followed by the frame stage(s): it is `Recovered` when that restores the level (and the jump
// limits hold), or when it confirms the frame stage's pose (within the confirmation tolerances) of a frame whose
// dissimilarity grew at most dissimilarityGrowth times over the last trusted frame's: the image content, not the track,
// lowered the similarity, and the level is re-anchored at that frame. Otherwise it is `Lost` (the next frame then
// starts from the last trusted pose without velocity).

#include <Eigen/Geometry>

#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Drr/DrrRenderer.h"
#include "Image/XrayImage.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationSchedule.h"
#include "Tracking/SimilarityLevel.h"

namespace fct {

/// How a frame's pose was obtained.
enum class TrackedFrameStatus {
  Tracked,    ///< the frame stage from the prediction met the lost-track rule's bounds
  Recovered,  ///< the frame stage did not; the global re-registration restored the level or confirmed the pose
  Lost,       ///< neither did: the pose is the re-registration's best, not trusted for the next prediction
};

/// One tracked frame.
struct TrackedFrame {
  int index = 0;                                                     ///< frame index, 0 = the first frame
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();  ///< the frame's pose (CT mm -> world mm, LPS)
  Eigen::Isometry3d T_predicted_world_from_ct = Eigen::Isometry3d::Identity();  ///< the search's start pose
  double similarity = 0.0;   ///< frame-stage similarity (VLNC over the frame's ROIs, mean over views) at the pose
  double runningLevel = 0.0; ///< the running similarity level the frame was judged against (after frame 0)
  double seconds = 0.0;      ///< wall time of the frame: X-ray swap, search and any recovery
  double cpuSeconds = 0.0;   ///< process CPU time (every thread) of the same
  double swapSeconds = 0.0;  ///< wall time of the X-ray swap alone (RegistrationCase::replaceXray of every view)
  long drrs = 0;             ///< DRRs rendered for the frame (evaluations x views)
  long fallbackRays = 0;     ///< Transgraph rays outside their tables, integrated exactly
  TrackedFrameStatus status = TrackedFrameStatus::Tracked;
  bool cancelled = false;    ///< the cancel flag stopped the frame; the pose is the best so far
  /// Why a Lost frame could not be searched at all (its X-ray or its ROIs unusable, e.g. a blank frame; the pose is
  /// then the prediction), or that a Recovered frame's re-registration confirmed the tracked pose and re-anchored the
  /// similarity level. Empty otherwise.
  std::string note;
};

/// Settings of the tracker. Scaled units as LocalSearchOptions (about 1 mm of bone-surface motion).
struct CineTrackerOptions {
  /// Frame 0's registration; an empty schedule means the default preset (RegistrationSchedule::kDefaultPreset).
  RegistrationOptions firstFrame;
  /// Pyramid level of the frame stage (0 = full resolution, 1 = 1:4 pixels, 2 = 1:16); kAutomaticLevel: the finest
  /// level whose image is at most CineTracker::kAutomaticLevelSide_px on its shorter side in every view (the coarsest
  /// level when none is), e.g. 2 for 512^2 and 1 for 256^2 detectors.
  int level = kAutomaticLevel;
  static constexpr int kAutomaticLevel = -1;
  int windowSize = 7;             ///< VLNC window, pixels of that level
  double roiFraction = 0.2;       ///< dynamic ROIs: fraction of the valid pixels compared (0 < f <= 1)
  int maxEvaluations = 60;        ///< cap on DRR sets of the frame stage
  double initialStep = 0.5;       ///< BOBYQA's first trust radius, scaled units
  double tolerance = 0.05;        ///< BOBYQA's stopping step, scaled units
  /// Render the frame stage exactly (frameDrr on the CT coarsened to the level) even when the case has Transgraph
  /// tables; false uses the tables (built once around frame 0's initial pose).
  bool exactDrr = false;
  /// How the frame stage renders when it renders exactly (a case without Transgraph tables, exactDrr, or the
  /// refinement), on the CT coarsened to the level: RayCast (trilinear samples, one every kFrameRayCastStep_voxels
  /// coarse voxels) or Siddon (exact box voxels); nullopt: RayCast with one view, Siddon with two or more. Box voxels
  /// make the similarity jump as ray positions cross voxel edges (by up to 0.0034 within 0.05 mm in plane on the pelvis
  /// at 1:16), which stops a single-plane search before it finds the depth; trilinear samples keep it smooth. Two views
  /// see the depth anyway, and Siddon is 2-4x faster there (docs/tracking.md).
  std::optional<DrrMethod> frameDrr;
  /// The trilinear frame DRR's sampling step along each ray, in voxels of the coarsened CT (docs/tracking.md).
  static constexpr double kFrameRayCastStep_voxels = 1.5;
  /// With one view: the frame search's scaled unit along the viewing ray in units across it (RegistrationStage::
  /// depthScale), in [1, 100]. The similarity is several hundred times flatter in depth than across it. Ignored with
  /// two or more views.
  double depthScale = 10.0;
  /// > 0: the frame stage is followed by an exact-DRR BOBYQA refinement at the same level and ROIs with this cap on
  /// DRR sets (for Transgraph tables, whose interpolation is too coarse for the final pose); 0: none.
  int refineEvaluations = 0;
  bool constantVelocity = true;   ///< predict previous pose + last inter-frame motion (false: previous pose)
  /// With one view: the fraction of the last inter-frame motion of the rotation centre along the viewing ray (source
  /// to centre) that the prediction carries on, in [0, 1] (0 keeps the depth, 1 is the full constant velocity). One
  /// view sees that motion only through the magnification, so the search corrects little of it and a full velocity
  /// overshoots where the bone turns (docs/tracking.md). Ignored with two or more views.
  double depthVelocityFactor = 0.5;
  /// Suspect when 1 - similarity > this x the reference dissimilarity: the smaller of 1 - running level and
  /// 1 - frame 0's similarity, at least SimilarityLevel::kMinReferenceDissimilarity; > 1.
  double dissimilarityGrowth = 1.75;
  double levelWeight = 0.2;       ///< weight of a new tracked frame in the running level (exponential mean), 0 < w <= 1
  double maxJump_mm = 8.0;        ///< lost when the rotation centre moves more than this from the prediction, mm
  double maxJump_deg = 6.0;       ///< lost when the rotation differs more than this from the prediction, deg
  /// A frame whose re-registration does not restore the level is still Recovered (and the level re-anchored there)
  /// when its similarity fell gradually (SimilarityLevel::fellGradually) and the re-registration's pose is within these
  /// of the frame stage's, the rotation centre's move in mm and the rotation in deg: two searches, one local and one
  /// global, agree, so the image content lowered the similarity, not the track.
  double confirmTolerance_mm = 1.0;
  double confirmTolerance_deg = 1.0;
};

/// Tracks the bone through a sequence, frame by frame.
class CineTracker {
 public:
  /// A tracker on a case prepared on frame 0's images (RegistrationCase::create); it keeps a reference to the case,
  /// which must outlive it. Fails on a frame-stage level the case's pyramid lacks, a window outside 2..64, a fraction
  /// outside (0, 1], a non-positive cap, step or tolerance, a dissimilarity growth not above 1, a level weight outside
  /// (0, 1], a non-positive jump limit or confirmation tolerance, a depth velocity factor outside [0, 1], a depth scale
  /// outside [1, 100], a frame DRR method other than raycast or siddon, or an unknown first-frame preset.
  static Result<CineTracker> create(RegistrationCase& registrationCase, const CineTrackerOptions& options);

  /// Registers frame 0 (the case's current images) with the first-frame schedule from T_initial and sets the running
  /// similarity level. Fails as Registration::run; a cancelled run is a success with `cancelled` set.
  Result<TrackedFrame> trackFirst(const Eigen::Isometry3d& T_initial, const std::atomic<bool>* cancel = nullptr);
  /// Tracks the next frame: one image per view, in the case's view order and of each view's detector size. Fails
  /// before trackFirst or on a wrong image count or size. A frame whose X-ray the preparation rejects or whose search
  /// cannot run (no ROI, e.g. a blank or garbled frame) is a success: `Lost`, with the reason in `note`. A cancelled
  /// frame is a success with `cancelled` set.
  Result<TrackedFrame> trackNext(const std::vector<XrayImage>& frameImages, const std::atomic<bool>* cancel = nullptr);

  /// The stages run on every frame after the first: the frame stage (VLNC on ROIs at the tracker's level, local
  /// BOBYQA) and, with refineEvaluations > 0, its exact-DRR refinement; frame similarities are the last stage's.
  const RegistrationSchedule& frameSchedule() const { return m_frameSchedule; }
  /// The shorter image side, in pixels, up to which the automatic tracking level goes (128 px of 1.8 mm on the
  /// studies' 230 mm field; docs/tracking.md gives the speed and accuracy measured there).
  static constexpr int kAutomaticLevelSide_px = 160;
  /// The options the tracker runs with (the first-frame schedule and the automatic level resolved).
  const CineTrackerOptions& options() const { return m_options; }
  /// Lowercase name of a status ("tracked", "recovered", "lost").
  static const char* statusName(TrackedFrameStatus status);

 private:
  CineTracker(RegistrationCase& registrationCase, CineTrackerOptions options, RegistrationSchedule frameSchedule);
  /// Runs `schedule` from T_start and folds its result into `frame` (pose, similarity, DRRs, cancelled); fails with
  /// Registration's message.
  Status runSchedule(const RegistrationSchedule& schedule, const Eigen::Isometry3d& T_start,
                     const std::atomic<bool>* cancel, TrackedFrame& frame);
  /// The start of the next frame's search: the last trusted pose moved on by the last inter-frame motion (pose
  /// parameters about the rotation centre; with one view only depthVelocityFactor of its part along the viewing ray),
  /// or the last trusted pose itself without a second pose or with constantVelocity off.
  Eigen::Isometry3d predictedPose() const;
  /// How far apart two poses are: the rotation centre's move and the rotation between them.
  struct PoseDistance {
    double move_mm = 0.0;
    double turn_deg = 0.0;
  };
  /// The distance from pose a to pose b (both CT mm -> world mm).
  PoseDistance distanceBetween(const Eigen::Isometry3d& T_a_world_from_ct,
                               const Eigen::Isometry3d& T_b_world_from_ct) const;
  /// True when `frame`'s pose is within the jump limits of its prediction.
  bool withinJumpLimits(const TrackedFrame& frame) const;
  /// True when `frame` passes the lost-track rule against the similarity level and its prediction.
  bool withinBounds(const TrackedFrame& frame) const;
  /// The status of a re-registered frame (the frame stage had ended at T_searched_world_from_ct): Recovered when within
  /// bounds, or when its similarity fell gradually and it confirms the searched pose within the confirmation
  /// tolerances (then the level is re-anchored and the note says so); Lost otherwise.
  TrackedFrameStatus judgeRecovery(const Eigen::Isometry3d& T_searched_world_from_ct, TrackedFrame& frame);

  RegistrationCase* m_case;
  CineTrackerOptions m_options;
  RegistrationSchedule m_frameSchedule;     ///< the frame stage (and its refinement)
  RegistrationSchedule m_recoverySchedule;  ///< the first-frame schedule's global stages, then the frame schedule
  int m_nextIndex = 0;
  SimilarityLevel m_level;  ///< started at frame 0's similarity at its registered pose
  std::optional<Eigen::Isometry3d> m_T_previous;       ///< last trusted pose
  std::optional<Eigen::Isometry3d> m_T_beforePrevious; ///< the trusted pose before it, for the velocity
};

}  // namespace fct
