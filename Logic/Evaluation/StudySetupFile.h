#pragma once
// StudySetupFile: DIR/setup.txt of an evaluation study's output folder: the options that change its results, one
// "key: value" line each. Written on the first run and compared on every resume, so trials run with other options
// are never mixed into one trials.csv (docs/evaluation.md "Resume"). A shard's folder also records "shard: K/N of T trials"; merging
// shards requires their setups to be equal but for that line.

#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/StudyDefinition.h"
#include "Evaluation/StudyShard.h"

namespace fct {

/// Writes and checks the setup file of a study's output folder.
class StudySetupFile {
 public:
  /// The setup file's name inside the output folder.
  static constexpr const char* kFileName = "setup.txt";
  /// The key of the line that records a shard, the one line in which the setups of merged shards may differ.
  static constexpr const char* kShardKey = "shard";

  /// The setup text of `study`: study, quick, cts (`ctPaths` as given; "default" when empty), preset (a preset file
  /// with its size and FNV-1a hash, so an edited file counts as another preset), detector, pixel_mm, sid_mm, sad_mm,
  /// method, transgraph_spacing_mm, seed, xrays ("per trial" or "one set"); then "shard: K/N of T trials" for a
  /// `shard` of more than one (none for the whole study).
  static std::string text(const StudyDefinition& study, const std::vector<std::string>& ctPaths,
                          const StudyShard* shard = nullptr);

  /// The resume check of output folder `folder`. When it holds trials (`hasTrials`) its setup file must exist and hold
  /// `setupText`, otherwise the check fails naming the folder and every line that differs ("'k: now' now, 'k: was'
  /// stored"), or saying the file is missing; nothing is written then. A folder without trials gets `setupText`
  /// written atomically (fails naming the file if it cannot be written).
  static Status checkOrWrite(const std::filesystem::path& folder, const std::string& setupText, bool hasTrials);
  /// The merge check of shard folder `folder`: its setup file must hold `setupText` (a setup without a shard line)
  /// but for its shard line; fails naming the folder and every line that differs ("'k: v' for the merge, 'k: w' in
  /// the shard"), or saying the file is missing.
  static Status checkShard(const std::filesystem::path& folder, const std::string& setupText);
};

}  // namespace fct
