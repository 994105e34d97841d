#pragma once
// StudyShard: shard K of N of a study's trials, for running one study as N independent processes (cluster array
// tasks, GNU parallel jobs) that are merged afterwards (StudyMerge). The assignment is a round robin over the trial
// keys of the study as run (its conditions with the trial counts of the run, after any --trials limit) in
// definition order, condition by condition and trial by trial: trial t of the condition whose trials start at
// position p of that order goes to shard (p + t) mod N + 1. So every condition's trials are spread evenly over the
// shards and the shards differ by at most one trial in all. The assignment depends on the trial counts, so a shard's
// setup records their total ("shard: K/N of T trials") and a shard resumed with other counts is refused.

#include <map>
#include <string>
#include <string_view>

#include "Base/Result.h"
#include "Evaluation/StudyDefinition.h"

namespace fct {

/// One shard of a study's trials.
class StudyShard {
 public:
  /// The most shards a study may be split into.
  static constexpr int kMaxCount = 10000;

  /// Shard `index` of `count` of `study` (its conditions with the trial counts of the run fix the assignment).
  /// Fails unless 1 <= index <= count <= kMaxCount.
  static Result<StudyShard> create(const StudyDefinition& study, int index, int count);
  /// Shard "K/N" of `study` (as create); fails on any other text, naming it and the accepted form.
  static Result<StudyShard> parse(const StudyDefinition& study, std::string_view text);

  /// K, from 1.
  int index() const { return m_index; }
  /// N.
  int count() const { return m_count; }
  /// "K/N".
  std::string text() const;
  /// The number of trials of the study that the shards share out.
  long totalTrials() const { return m_totalTrials; }
  /// The shard (1..count()) that runs trial `trial` (0-based) of the condition named `condition`; 0 for a condition
  /// the study does not have.
  int shardOf(const std::string& condition, int trial) const;
  /// True when this shard runs trial `trial` of the condition named `condition`.
  bool holds(const std::string& condition, int trial) const { return shardOf(condition, trial) == m_index; }

 private:
  int m_index = 1;
  int m_count = 1;
  long m_totalTrials = 0;
  std::map<std::string, long> m_firstPosition;  ///< per condition: position of its trial 0 in the study's key order
};

}  // namespace fct
