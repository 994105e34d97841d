#pragma once
// StudyTrialCase: writes one trial of a study as a case folder that `fluoroct register` reads, so that an engineer can
// re-run, inspect and vary a single trial: the trial's X-rays (simulated exactly as the study does, from the trial's
// seed: bone pose, foreign objects and noise; saved as 16-bit PNG), its views, its true pose, its start pose and, when
// the condition registers on coarser slices, the registration CT. Trials of a study that shares one X-ray set
// (setup.xraysPerTrial false) are written with that set's true pose and seed.

#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/StudyDefinition.h"
#include "Evaluation/StudyRunner.h"

namespace fct {

/// The files of a written trial case.
struct StudyTrialCaseFiles {
  std::filesystem::path viewFile;         ///< DIR/views.json (cameras and the X-ray PNGs)
  std::filesystem::path truthFile;        ///< DIR/truth_pose.json: the trial's true T_world_from_ct
  std::filesystem::path startFile;        ///< DIR/start_pose.json: the trial's start T_world_from_ct
  std::filesystem::path registrationCt;   ///< the CT the trial registers on: the study's CT file, or DIR/ct_registration.nrrd
  bool ctWritten = false;                 ///< true when registrationCt was written here
  double cutFaceMargin_mm = 0.0;          ///< the cut-face margin the study registers with
  double initialStre_mm = 0.0;            ///< mean sTRE of the start pose from the truth
};

/// Writes single trials of a study as case folders.
class StudyTrialCase {
 public:
  /// Writes trial `trial` (0-based) of the condition named `conditionName` of `study` into `folder` (created). `ctPath`
  /// is the file or folder the condition's CT was loaded from, empty for a CT built in memory (the phantom). The
  /// registration CT is written into the folder when the condition registers on coarser slices or `ctPath` is empty.
  /// Fails before writing on an unknown condition (the message lists the known ones), a trial outside the condition's
  /// count, a CT label not in `cts` or a CT without bone; fails on a simulation or write error.
  static Result<StudyTrialCaseFiles> write(const StudyDefinition& study, const std::vector<StudyCt>& cts,
                                           const std::string& conditionName, int trial,
                                           const std::filesystem::path& ctPath, const std::filesystem::path& folder);
};

}  // namespace fct
