#pragma once
// StudyReport: turns the trials of a study into report.md (Markdown tables per condition: trials, success rate,
// sTRE mean and max, mTRE, rotation and translation error, median time, DRRs; table2 beside the paper's values,
// capture with cumulative failure and the capture range) and PNG charts (LineChart) in the output folder.
// Statistics: sTRE mean is the mean over successful trials of each trial's mean sTRE; sTRE max the largest
// per-trial maximum among successful trials; "all" columns use every finished trial; failed trials count as failures.

#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/StudyDefinition.h"
#include "Evaluation/TrialStore.h"

namespace fct {

/// Summary of the finished trials of one condition.
struct ConditionStats {
  int trials = 0;              ///< finished trials (status Ok or Failed)
  int successes = 0;
  double successRate = 0.0;    ///< successes / trials (0 without trials)
  double streMean_mm = 0.0;    ///< mean of the trials' mean sTRE, successful trials (NaN if none)
  double streMax_mm = 0.0;     ///< largest max sTRE, successful trials (NaN if none)
  double streMeanAll_mm = 0.0; ///< mean of the trials' mean sTRE, all registered trials (NaN if none)
  double streMaxAll_mm = 0.0;  ///< mean of the trials' max sTRE, all registered trials (NaN if none)
  double mtre_mm = 0.0;        ///< mean mTRE, successful trials
  double rotation_deg = 0.0;   ///< mean rotation error, successful trials
  double translation_mm = 0.0; ///< mean translation error, successful trials
  double medianSeconds = 0.0;  ///< median registration time, all registered trials
  double meanDrrs = 0.0;       ///< mean DRRs, all registered trials
  double meanSetupSeconds = 0.0; ///< mean Transgraph table build/load time, all registered trials (NaN if none)
};

/// Writes study reports.
class StudyReport {
 public:
  /// Statistics of `records` (trials of one condition; cancelled ones are ignored).
  static ConditionStats statistics(const std::vector<TrialRecord>& records);
  /// The Markdown report of `study` from `records` (trials of other studies or conditions are ignored); `notes` are
  /// listed in its header (e.g. the X-ray forward model, StudyRunner::notes). Lists each failed trial's reason.
  static std::string markdown(const StudyDefinition& study, const std::vector<TrialRecord>& records,
                              const std::vector<std::string>& notes);
  /// Writes report.md and the study's charts into `outDir` (existing folder); returns the files written. Fails on an
  /// unwritable folder.
  static Result<std::vector<std::filesystem::path>> write(const StudyDefinition& study,
                                                          const std::vector<TrialRecord>& records,
                                                          const std::vector<std::string>& notes,
                                                          const std::filesystem::path& outDir);
};

}  // namespace fct
