#pragma once
// StudyDefinition: an evaluation study as data: the conditions to compare (CT, scenario, views, technique switches,
// similarity measures, initial-error range) and the trials per condition, plus the setup they share (preset,
// detector, simulated dose, seed). StudyCatalog makes the built-in ones; StudyRunner runs them.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "Drr/DrrRendererFactory.h"
#include "Registration/RegistrationSchedule.h"
#include "Simulation/StandardViews.h"

namespace fct {

/// Which similarity measures a study registration uses.
enum class StudyMeasures {
  Both,      ///< the schedule as it is (NCC, then VLNC)
  NccOnly,   ///< NCC in every stage (RegistrationAblation::nccOnly)
  VlncOnly,  ///< VLNC in every stage (the first stage's whole images become every complete window)
};

/// How a trial's start pose is made.
enum class StudyStart {
  SurfaceDistance,  ///< a random pose at a mean bone-surface distance in [initialLow_mm, initialHigh_mm] from the truth
  Rotation,         ///< the truth rotated about the bone centre by an angle in [rotationLow_deg, rotationHigh_deg]
                    ///< about a random axis (no translation)
  SupineSetup,      ///< the clinical setup alone, no landmarks: supine at the C-arm isocentre (SetupPose)
};

/// One compared condition of a study; its trials differ by the random start pose and search seed and, with
/// StudySetup::xraysPerTrial, by their own simulated X-rays.
struct StudyCondition {
  std::string name;               ///< unique within the study, e.g. "pelvis/realistic" (the resume key with the trial)
  std::string ct;                 ///< label of the CT (StudyCt::label)
  std::string scenario = "ideal"; ///< "ideal" (registration on the original CT), "realistic", "bad"
  double sliceSpacing_mm = 0.0;   ///< registration CT resampled to this slice spacing (0: the original CT)
  /// Slice spacing of the registration CT actually used, mm (StudyRunner::resolveSliceSpacings; 0: not resolved yet).
  /// Equals sliceSpacing_mm, or the CT's own spacing when that is already as coarse (or sliceSpacing_mm is 0).
  double usedSliceSpacing_mm = 0.0;
  int viewCount = 3;              ///< the first viewCount standard views (StandardViews)
  std::string variant = "full";   ///< technique variant for reports ("full", "no-rois", "ncc-only", ...)
  RegistrationAblation ablation;  ///< techniques switched off
  StudyMeasures measures = StudyMeasures::Both;
  double initialLow_mm = 10.0;    ///< initial mean sTRE drawn uniformly in [low, high] per trial (equal: fixed)
  double initialHigh_mm = 10.0;
  StudyStart start = StudyStart::SurfaceDistance;
  double rotationLow_deg = 0.0;   ///< StudyStart::Rotation: angle drawn uniformly in [low, high] per trial
  double rotationHigh_deg = 0.0;
  int trials = 10;
};

/// The setup shared by all conditions of a study.
struct StudySetup {
  std::string preset = RegistrationSchedule::kDefaultPreset;  ///< registration schedule (RegistrationSchedule::resolve)
  StandardViewOptions detector;   ///< C-arm geometry and detector (its count is ignored: conditions choose)
  std::uint32_t seed = 1;         ///< base seed: trial t of every condition starts from seed + t
  /// True: every trial registers against X-rays of its own (StudyRunner::trialTruthPose: the bone placed around the
  /// study's true pose; its own foreign-object placement and noise), all from its seed, so a condition's mean is over
  /// X-ray realizations and not one image set's optimum. False: every trial of a CT uses one X-ray set at the true pose.
  bool xraysPerTrial = true;
  DrrMethod method = DrrMethod::Siddon;  ///< DRR method of the registrations (a condition's ablation may switch the
                                         ///< Transgraph off)
  double transgraphSpacing_mm = 3.0;     ///< Transgraph table step (TransgraphParameters::spacing_mm)
  /// Transgraph table cache folder shared by the trials (empty: no cache, every trial builds its tables).
  std::filesystem::path transgraphCacheDir;
};

/// A whole study.
struct StudyDefinition {
  std::string name;               ///< "table2", "capture", "ablation", "views"
  std::string title;              ///< one line for the report
  bool quick = false;             ///< the small CI version
  StudySetup setup;
  std::vector<StudyCondition> conditions;
  std::vector<std::string> gaps;  ///< parts of the study this build cannot measure, said in the report
};

}  // namespace fct
