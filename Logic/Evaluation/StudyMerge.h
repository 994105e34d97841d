#pragma once
// StudyMerge: gathers the trials of a study run as shards (StudyShard, one output folder each) into the trials of one
// run. A merge never covers less than it says: it refuses shard folders whose setups differ but for their shard
// line, a trial finished in two folders, a trial of a condition the study does not have, and any trial of the study
// that no folder holds finished (Ok or Failed; a Cancelled trial counts as missing), listing each. The merged
// trials are in study order (condition by condition, trial by trial), the order of an unsharded run on one job.

#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/StudyDefinition.h"
#include "Evaluation/TrialStore.h"

namespace fct {

/// Merges the output folders of a study's shards.
class StudyMerge {
 public:
  /// The finished trials of `study` (its conditions with the trial counts to merge) read from the shard output folders
  /// `folders`, whose setup files must hold `setupText` but for their shard line (StudySetupFile::checkShard), in
  /// study order; trials beyond a condition's count are kept, as a resumed run keeps them. Fails, naming the folder or
  /// listing the trials, on no folder, a folder given twice or missing, an unreadable trials.csv, another setup, a
  /// trial finished in two folders, a condition the study does not have, and missing trials.
  static Result<std::vector<TrialRecord>> collect(const StudyDefinition& study, const std::string& setupText,
                                                  const std::vector<std::filesystem::path>& folders);
  /// Writes merged `records` into output folder `folder` (existing) as one run writes them: setup.txt (`setupText`)
  /// and trials.csv, each atomically. Fails, writing nothing, when the folder holds trials run with other options or
  /// finished trials that `records` does not hold as they are (they would be lost; listed), or a file cannot be
  /// written. So a merge may be repeated into its own folder, after more shard trials have finished.
  static Status write(const std::filesystem::path& folder, const std::string& setupText,
                      const std::vector<TrialRecord>& records);
};

}  // namespace fct
