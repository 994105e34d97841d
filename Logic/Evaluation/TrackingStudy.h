#pragma once
// TrackingStudy: the cine tracking evaluation. For every condition (CT, single-plane or biplane C-arm, detector) and
// sequence, the bone moves from the study's true pose (StudyRunner::truthPose) by a seeded smooth motion within
// +-15 mm and +-10 deg per axis plus a fast jerk (BoneMotion); every frame of every view is simulated by the study
// forward model (StudyXraySource::simulateSequence: continuous patient, scatter, noise, anatomy beyond the CT, each
// frame its own noise). The CineTracker registers frame 0 from a start perturbed from its truth as the studies'
// starts are (a random pose at a fixed mean sTRE, StudyRunner::startPose) and then tracks every later frame; each
// frame's pose is measured against its truth (PoseErrorMetrics: sTRE; single-plane also in-plane and out-of-plane).
// A sequence is stored as soon as it ends (TrackingFrameStore), so a stopped study resumes with the next one.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/StudyRunner.h"
#include "Evaluation/TrackingFrameStore.h"
#include "Simulation/BoneMotion.h"
#include "Tracking/CineTracker.h"

namespace fct {

/// One compared condition of the tracking study.
struct TrackingCondition {
  std::string name;              ///< unique within the study, e.g. "pelvis/single-512" (the resume key)
  std::string ct;                ///< label of the CT (StudyCt::label)
  int viewCount = 1;             ///< 1 = single-plane (AP), 2 = biplane (AP, lateral)
  int detector_px = 512;         ///< square detector side, pixels
  double pixelSpacing_mm = 0.45; ///< detector pixel size
  bool foreignObjects = false;   ///< K-wires and screws held fixed in the world while the bone moves
  int sequences = 1;             ///< sequences (each its own motion, noise and start)
};

/// The whole tracking study.
struct TrackingStudyDefinition {
  std::string name = "tracking";
  std::string title;
  bool quick = false;
  std::string preset = RegistrationSchedule::kDefaultPreset;  ///< frame 0's registration schedule
  double sourceToDetector_mm = 1500.0;  ///< C-arm geometry of the standard views
  double sourceToIsocentre_mm = 1000.0;
  double initialStre_mm = 10.0;         ///< frame 0's start: this mean sTRE from its truth
  BoneMotionOptions motion;             ///< frames, bounds, periods and jerk (seed: per sequence)
  std::uint32_t seed = 1;               ///< sequence s of every condition uses seed + s
  std::vector<TrackingCondition> conditions;
};

/// Reported after every finished sequence.
struct TrackingProgress {
  int finished = 0;                          ///< sequences finished in this run
  int toRun = 0;                             ///< sequences this run has to do
  std::vector<TrackingFrameRecord> frames;   ///< the sequence just finished
};

/// How to run the tracking study.
struct TrackingRunOptions {
  std::function<void(const TrackingProgress&)> onSequence;  ///< after each sequence
  std::function<void(const std::string&)> onMessage;        ///< preparation steps
  const std::atomic<bool>* cancel = nullptr;                ///< set to stop: the running frame ends as cancelled
};

/// What a run did.
struct TrackingRunSummary {
  int ran = 0;        ///< sequences run now
  int skipped = 0;    ///< sequences already in the store
  bool cancelled = false;
};

/// Defines and runs the tracking study.
class TrackingStudy {
 public:
  /// The study over the CTs labelled `ctLabels`: per CT, single-plane 512 x 512 at 0.45 mm and biplane 256 x 256 at
  /// 0.9 mm (the same 230 mm field), 40 frames of smooth motion with a 2-frame jerk of 4 mm and 3 deg at frame 20,
  /// 1 sequence each, frame 0 from 10 mm with the default preset. Quick: 96 x 96 at 2.4 mm and 64 x 64 at 3.6 mm,
  /// 5 frames with the jerk at frame 3, the fast preset. Fails on an empty CT list.
  static Result<TrackingStudyDefinition> define(bool quick, const std::vector<std::string>& ctLabels);
  /// Runs the sequences of `study` that `store` does not hold, adding each one as it ends. Fails before any sequence
  /// on a condition naming an unknown CT, a view count other than 1 or 2, no sequences, a bad detector, an unknown
  /// preset or a bad motion; fails when a CT has no bone, a simulation or case preparation fails, or the store cannot
  /// be written. A tracker error ends the sequence with that frame stored as "failed".
  static Result<TrackingRunSummary> run(const TrackingStudyDefinition& study, const std::vector<StudyCt>& cts,
                                        TrackingFrameStore& store, const TrackingRunOptions& options = {});
  /// Notes for the report: the X-ray forward model, the motion, the start and the tracker settings.
  static std::vector<std::string> notes(const TrackingStudyDefinition& study);
  /// The tracker settings of the study (CineTracker defaults, frame 0 with the study's preset); fails on an unknown
  /// preset.
  static Result<CineTrackerOptions> trackerOptions(const TrackingStudyDefinition& study);
};

}  // namespace fct
