#pragma once
// TrialStore: the trials of a study as a CSV file (one row per trial, header first), kept on disk after every trial
// so that an interrupted study resumes where it stopped: a trial is keyed by (study, condition, trial index), and a
// key already stored with status Ok or Failed is not run again (Cancelled ones are). Every save rewrites the
// file atomically (temporary file, then rename), so it is never half-written.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/PoseErrorMetrics.h"

namespace fct {

/// How a trial ended; the CSV's `status` column spells it "ok", "failed" or "cancelled".
enum class TrialStatus {
  Ok,         ///< the registration ran to its end (its pose may still miss the success threshold)
  Failed,     ///< the registration returned an error (see TrialRecord::reason)
  Cancelled,  ///< stopped before the registration ended; a resumed study runs it again
};

/// The CSV spelling of `status`: "ok", "failed" or "cancelled".
std::string_view trialStatusName(TrialStatus status);
/// Parses the CSV spelling of a status; fails on any other text, naming it and the accepted ones.
Result<TrialStatus> parseTrialStatus(std::string_view text);

/// One registration trial of a study and its outcome.
struct TrialRecord {
  std::string study;
  std::string ct;
  std::string condition;
  std::string scenario;
  std::string variant;
  int views = 0;
  int trial = 0;                  ///< 0-based index within the condition
  std::uint32_t seed = 0;         ///< start pose and search seed (and, with per-trial X-rays, their bone pose and noise)
  double truthOffset_mm = 0.0;    ///< mean bone-surface distance of the trial's true pose from the study's (0: one X-ray set)
  double initialTarget_mm = 0.0;  ///< the initial mean sTRE asked for
  double initialStre_mm = 0.0;    ///< the initial mean sTRE measured
  PoseError error;                ///< of the final pose (NaN for a failed trial)
  bool success = false;           ///< PoseErrorMetrics::isSuccess(error)
  double seconds = 0.0;           ///< registration time
  double setupSeconds = 0.0;      ///< Transgraph tables built or loaded for this trial before registering, seconds
  long drrs = 0;                  ///< DRRs rendered
  TrialStatus status = TrialStatus::Ok;  ///< how the trial ended
  std::string reason;             ///< the error or cancellation message
};

/// A study's trials, mirrored in a CSV file.
class TrialStore {
 public:
  /// The CSV column names, in order.
  static const std::vector<std::string>& columns();

  /// Opens `csvPath`: reads its trials if it exists (resume), else starts empty (nothing is written until save).
  /// Fails naming the file and line on a header other than columns(), a row with the wrong number of fields, a
  /// bad number or an unknown status, or an unreadable file.
  static Result<TrialStore> open(const std::filesystem::path& csvPath);

  /// True if the trial is stored with status Ok or Failed (so a resumed study skips it).
  bool isDone(const std::string& study, const std::string& condition, int trial) const;
  /// Stores `record` (replacing one with the same key) and rewrites the file atomically; fails on an unwritable file
  /// (the record is kept in memory).
  Status add(const TrialRecord& record);
  /// All stored trials, in the order they were first added.
  const std::vector<TrialRecord>& records() const { return m_records; }
  /// The file.
  const std::filesystem::path& path() const { return m_path; }

  /// The CSV text of `records` (header line, then one line per record; fields with commas or quotes are quoted).
  static std::string toCsv(const std::vector<TrialRecord>& records);
  /// `text` as one CSV field: quoted (inner quotes doubled, line breaks as spaces) when it holds a comma, quote or line
  /// break, else as it is.
  static std::string csvField(const std::string& text);
  /// Parses CSV text written by toCsv(); `where` names the source in messages.
  static Result<std::vector<TrialRecord>> fromCsv(const std::string& text, const std::string& where);

 private:
  std::filesystem::path m_path;
  std::vector<TrialRecord> m_records;
};

}  // namespace fct
