#pragma once
// TrackingReport: the tracking study's figures per condition (frames, median and max sTRE, single-plane in-plane and
// out-of-plane parts, failures, recoveries, frames per second) beside the targets, as DIR/summary.csv and
// DIR/report.md.

#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/TrackingFrameStore.h"
#include "Evaluation/TrackingStudy.h"

namespace fct {

/// The figures of one condition over its stored frames (cancelled frames are left out).
struct TrackingConditionStats {
  std::string condition;
  int views = 0;
  int detector_px = 0;
  int sequences = 0;
  int frames = 0;              ///< frames measured (every sequence, frame 0 included)
  double medianStre_mm = 0.0;  ///< median over frames of the mean sTRE (NaN without frames)
  double maxStre_mm = 0.0;     ///< largest mean sTRE of a frame
  double medianInPlane_mm = 0.0;     ///< single-plane: median in-plane part (NaN for biplane)
  double maxInPlane_mm = 0.0;        ///< single-plane: largest in-plane part
  double medianOutOfPlane_mm = 0.0;  ///< single-plane: median out-of-plane part
  int failures = 0;            ///< frames above kFailure_mm mean sTRE, lost or failed
  int lost = 0;                ///< frames the tracker called lost (or whose tracking failed)
  int recoveries = 0;          ///< frames the tracker recovered
  double framesPerSecond = 0.0;   ///< frames after the first / their wall time (NaN when none)
  double cpuPerFrame_s = 0.0;     ///< mean process CPU time of a frame after the first
  double firstFrameSeconds = 0.0; ///< median wall time of frame 0's registration
};

/// Writes tracking study reports.
class TrackingReport {
 public:
  /// A frame whose mean sTRE is above this is a failure, mm.
  static constexpr double kFailure_mm = 1.5;

  /// The figures of condition `c` from `records` (frames of other conditions are ignored).
  static TrackingConditionStats statistics(const TrackingCondition& c, const std::vector<TrackingFrameRecord>& records);
  /// The Markdown report: title, notes, the per-condition table beside the targets, and every failed frame's reason.
  static std::string markdown(const TrackingStudyDefinition& study, const std::vector<TrackingFrameRecord>& records,
                              const std::vector<std::string>& notes);
  /// The per-condition figures as CSV (header line, one row per condition).
  static std::string summaryCsv(const TrackingStudyDefinition& study, const std::vector<TrackingFrameRecord>& records);
  /// Writes report.md and summary.csv into `outDir` (existing folder); returns the files written. Fails on an
  /// unwritable folder.
  static Result<std::vector<std::filesystem::path>> write(const TrackingStudyDefinition& study,
                                                          const std::vector<TrackingFrameRecord>& records,
                                                          const std::vector<std::string>& notes,
                                                          const std::filesystem::path& outDir);
};

}  // namespace fct
