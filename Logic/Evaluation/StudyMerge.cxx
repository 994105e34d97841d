#include "Evaluation/StudyMerge.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <map>
#include <set>
#include <system_error>
#include <utility>

#include "Base/TextFile.h"
#include "Evaluation/StudySetupFile.h"

namespace fct {

namespace fs = std::filesystem;

namespace {

/// A trial's key: condition name and trial index.
using TrialKey = std::pair<std::string, int>;

/// True when a trial is finished (a resumed run would not run it again).
bool isFinished(const TrialRecord& r) { return r.status == TrialStatus::Ok || r.status == TrialStatus::Failed; }

/// Trial keys listed by condition in `study` order, e.g. "phantom/bad trials 0, 1; phantom/ideal trial 1", each
/// key followed by `detail` of it when given (e.g. the folders that hold it).
std::string listTrials(const StudyDefinition& study, const std::map<TrialKey, std::string>& keys) {
  std::vector<std::string> parts;
  for (const StudyCondition& c : study.conditions) {
    std::vector<std::string> trials;
    for (const auto& [key, detail] : keys) {
      if (key.first == c.name) trials.push_back(detail.empty() ? std::to_string(key.second)
                                                               : fmt::format("{} ({})", key.second, detail));
    }
    if (!trials.empty()) {
      parts.push_back(fmt::format("{} trial{} {}", c.name, trials.size() > 1 ? "s" : "", fmt::join(trials, ", ")));
    }
  }
  return fmt::format("{}", fmt::join(parts, "; "));
}

/// The trials of one shard folder, after checking that it exists and was run with `setupText`.
Result<std::vector<TrialRecord>> readShard(const fs::path& folder, const std::string& setupText) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    return fail(fmt::format("shard folder {} does not exist or is not a folder", folder.string()));
  }
  if (Status same = StudySetupFile::checkShard(folder, setupText); !same) return fail(same.error());
  auto store = TrialStore::open(folder / "trials.csv");  // a shard without trials of its own has no trials.csv
  if (!store) return fail(store.error());
  return store.value().records();
}

}  // namespace

Result<std::vector<TrialRecord>> StudyMerge::collect(const StudyDefinition& study, const std::string& setupText,
                                                     const std::vector<fs::path>& folders) {
  if (folders.empty()) return fail("no shard folder to merge");
  std::map<std::string, std::size_t> conditionIndex;
  for (std::size_t i = 0; i < study.conditions.size(); ++i) conditionIndex.emplace(study.conditions[i].name, i);

  std::set<fs::path> seen;
  std::map<TrialKey, TrialRecord> finished;
  std::map<TrialKey, std::vector<std::string>> holders;  // the folders that hold each finished trial
  std::map<TrialKey, std::string> cancelled;             // trials stopped before they ended, and where
  for (const fs::path& folder : folders) {
    if (!seen.insert(fs::weakly_canonical(folder)).second) {
      return fail(fmt::format("shard folder {} is given twice; give each shard's folder once", folder.string()));
    }
    auto records = readShard(folder, setupText);
    if (!records) return fail(records.error());
    for (const TrialRecord& r : records.value()) {
      if (r.study != study.name || !conditionIndex.count(r.condition)) {
        return fail(fmt::format("shard folder {} holds trial {} of condition '{}' of study '{}', which study '{}' with "
                                "these options does not have; merge only the shards of one study run",
                                folder.string(), r.trial, r.condition, r.study, study.name));
      }
      const TrialKey key{r.condition, r.trial};
      if (!isFinished(r)) {
        cancelled.emplace(key, "cancelled in " + folder.string());
        continue;
      }
      holders[key].push_back(folder.string());
      finished.emplace(key, r);
    }
  }

  std::map<TrialKey, std::string> duplicates;
  for (const auto& [key, where] : holders) {
    if (where.size() > 1) duplicates.emplace(key, fmt::format("{}", fmt::join(where, ", ")));
  }
  if (!duplicates.empty()) {
    return fail(fmt::format("{} trial(s) are finished in more than one shard folder: {}; each trial belongs to one "
                            "shard: merge the folders of one run of N shards",
                            duplicates.size(), listTrials(study, duplicates)));
  }
  std::map<TrialKey, std::string> missing;
  for (const StudyCondition& c : study.conditions) {
    for (int t = 0; t < c.trials; ++t) {
      const TrialKey key{c.name, t};
      if (finished.count(key)) continue;
      const auto stopped = cancelled.find(key);
      missing.emplace(key, stopped == cancelled.end() ? "" : stopped->second);
    }
  }
  if (!missing.empty()) {
    return fail(fmt::format("{} trial(s) of the study are in no shard folder: {}; run (or resume) the shards that "
                            "hold them, and give every shard's folder",
                            missing.size(), listTrials(study, missing)));
  }

  std::vector<TrialRecord> merged;
  for (auto& [key, record] : finished) merged.push_back(std::move(record));
  std::stable_sort(merged.begin(), merged.end(), [&](const TrialRecord& a, const TrialRecord& b) {
    return std::pair(conditionIndex.at(a.condition), a.trial) < std::pair(conditionIndex.at(b.condition), b.trial);
  });
  return merged;
}

Status StudyMerge::write(const fs::path& folder, const std::string& setupText, const std::vector<TrialRecord>& records) {
  const fs::path csv = folder / "trials.csv";
  auto existing = TrialStore::open(csv);
  if (!existing) return fail(existing.error());
  const bool hasTrials = !existing.value().records().empty();
  if (hasTrials) {
    if (Status same = StudySetupFile::checkOrWrite(folder, setupText, true); !same) return fail(same.error());
    std::set<std::string> merged;  // each merged trial as its CSV text
    for (const TrialRecord& r : records) merged.insert(TrialStore::toCsv({r}));
    std::vector<std::string> lost;
    for (const TrialRecord& r : existing.value().records()) {
      if (isFinished(r) && !merged.count(TrialStore::toCsv({r}))) {
        lost.push_back(fmt::format("{} trial {}", r.condition, r.trial));
      }
    }
    if (!lost.empty()) {
      return fail(fmt::format("{} holds {} finished trial(s) that the shards do not hold as they are ({}); the merge "
                              "would replace them: merge into another folder",
                              folder.string(), lost.size(), fmt::join(lost, ", ")));
    }
  } else if (Status written = StudySetupFile::checkOrWrite(folder, setupText, false); !written) {
    return fail(written.error());
  }
  return TextFile::writeAtomically(csv, TrialStore::toCsv(records));
}

}  // namespace fct
