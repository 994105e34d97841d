#pragma once
// TrackingFrameStore: the frames of a tracking study, kept on disk after every finished sequence so that an
// interrupted study resumes where it stopped. A sequence (condition, sequence index) is tracked as a whole (the
// tracker's state runs from frame to frame), so it is the unit of resume: a sequence with all its frames stored and
// none cancelled is not run again. The store is DIR/frames.json, rewritten atomically (temporary file, then rename)
// after each sequence; frames.csv, written beside it, holds the same rows for reading.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"

namespace fct {

/// One tracked frame of a study sequence and its error against the truth.
struct TrackingFrameRecord {
  std::string condition;          ///< e.g. "pelvis/single-512"
  std::string ct;                 ///< CT label
  int views = 0;                  ///< 1 = single-plane, 2 = biplane
  int sequence = 0;               ///< 0-based sequence index within the condition
  int frames = 0;                 ///< frames in the sequence
  int frame = 0;                  ///< 0-based frame index
  std::uint32_t seed = 0;         ///< motion, noise and start seed of the sequence
  std::string status;             ///< "tracked", "recovered", "lost", or "failed" (the tracker returned an error)
  bool cancelled = false;         ///< stopped before the frame ended
  double similarity = 0.0;        ///< tracker's frame similarity
  double seconds = 0.0;           ///< wall time of the frame (frame 0: its full registration)
  double cpuSeconds = 0.0;        ///< process CPU time of the frame, every thread
  long drrs = 0;                  ///< DRRs rendered for the frame
  double motionFromFirst_mm = 0.0;  ///< mean bone-surface distance of the frame's true pose from frame 0's
  double initialStre_mm = 0.0;    ///< mean sTRE of the frame's start pose (frame 0: the perturbed start; later: the
                                  ///< tracker's prediction)
  double streMean_mm = 0.0;       ///< mean sTRE of the tracked pose
  double streMax_mm = 0.0;        ///< max sTRE of the tracked pose
  double inPlane_mm = 0.0;        ///< single-plane: mean in-plane part of the sTRE (PoseErrorMetrics::measureInView)
  double outOfPlane_mm = 0.0;     ///< single-plane: mean out-of-plane part (NaN for biplane)
  double rotation_deg = 0.0;      ///< residual rotation
  double translation_mm = 0.0;    ///< bone-centre error
  std::string reason;             ///< error message of a failed frame
};

/// A tracking study's frames, mirrored in DIR/frames.json and DIR/frames.csv.
class TrackingFrameStore {
 public:
  /// Opens the store in folder `dir`: reads frames.json if it exists (resume), else starts empty. Fails naming the
  /// file on unreadable or malformed JSON or a frame missing a field.
  static Result<TrackingFrameStore> open(const std::filesystem::path& dir);

  /// True if every frame of the sequence is stored and none was cancelled.
  bool isDone(const std::string& condition, int sequence) const;
  /// Replaces the sequence's stored frames by `frames` (all of one sequence, appended) and rewrites frames.json and frames.csv
  /// atomically; fails on an unwritable folder (the frames are kept in memory).
  Status addSequence(const std::vector<TrackingFrameRecord>& frames);
  /// All stored frames, by sequence in the order they were stored, then by frame.
  const std::vector<TrackingFrameRecord>& records() const { return m_records; }
  /// The store's folder.
  const std::filesystem::path& dir() const { return m_dir; }

  /// The CSV text of `records`: a header line, then one line per frame.
  static std::string toCsv(const std::vector<TrackingFrameRecord>& records);

 private:
  std::filesystem::path m_dir;
  std::vector<TrackingFrameRecord> m_records;
};

}  // namespace fct
