#include "Evaluation/TrackingReport.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "Base/TextFile.h"

namespace fct {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
/// The targets: median sTRE (biplane) and in-plane sTRE (single-plane), mm; frames per second.
constexpr double kTargetMedian_mm = 0.5;
constexpr double kTargetSinglePlaneFps = 10.0;
constexpr double kTargetBiplaneFps = 5.0;

double median(std::vector<double> values) {
  if (values.empty()) return kNan;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double maximum(const std::vector<double>& values) {
  return values.empty() ? kNan : *std::max_element(values.begin(), values.end());
}

std::string mm(double value) { return std::isnan(value) ? "-" : fmt::format("{:.3f}", value); }

/// "met" / "NOT met" for a figure against its target (lower is better unless `higherIsBetter`).
std::string verdict(double value, double target, bool higherIsBetter) {
  if (std::isnan(value)) return "not measured";
  return (higherIsBetter ? value >= target : value <= target) ? "met" : "NOT met";
}

}  // namespace

TrackingConditionStats TrackingReport::statistics(const TrackingCondition& c,
                                                  const std::vector<TrackingFrameRecord>& records) {
  TrackingConditionStats s;
  s.condition = c.name;
  s.views = c.viewCount;
  s.detector_px = c.detector_px;
  std::vector<double> stre, inPlane, outOfPlane, firstSeconds;
  double laterSeconds = 0.0, laterCpu = 0.0;
  int laterFrames = 0, lastSequence = -1;
  for (const TrackingFrameRecord& r : records) {
    if (r.condition != c.name || r.cancelled) continue;
    if (r.sequence != lastSequence) {
      ++s.sequences;
      lastSequence = r.sequence;
    }
    ++s.frames;
    const bool failed = r.status == "failed";
    if (r.status == "lost" || failed) ++s.lost;
    if (r.status == "recovered") ++s.recoveries;
    if (failed || r.status == "lost" || !(r.streMean_mm <= kFailure_mm)) ++s.failures;
    if (failed) continue;
    stre.push_back(r.streMean_mm);
    if (c.viewCount == 1) {
      inPlane.push_back(r.inPlane_mm);
      outOfPlane.push_back(r.outOfPlane_mm);
    }
    if (r.frame == 0) {
      firstSeconds.push_back(r.seconds);
    } else {
      laterSeconds += r.seconds;
      laterCpu += r.cpuSeconds;
      ++laterFrames;
    }
  }
  s.medianStre_mm = median(stre);
  s.maxStre_mm = maximum(stre);
  s.medianInPlane_mm = median(inPlane);
  s.maxInPlane_mm = maximum(inPlane);
  s.medianOutOfPlane_mm = median(outOfPlane);
  s.framesPerSecond = laterFrames > 0 && laterSeconds > 0.0 ? laterFrames / laterSeconds : kNan;
  s.cpuPerFrame_s = laterFrames > 0 ? laterCpu / laterFrames : kNan;
  s.firstFrameSeconds = median(firstSeconds);
  return s;
}

std::string TrackingReport::markdown(const TrackingStudyDefinition& study,
                                     const std::vector<TrackingFrameRecord>& records,
                                     const std::vector<std::string>& notes) {
  std::string out = fmt::format("# Tracking study{}\n\n{}\n\n", study.quick ? " (quick)" : "", study.title);
  for (const std::string& note : notes) out += fmt::format("- {}\n", note);
  out += fmt::format(
      "\nsTRE: mean bone-surface distance of a frame's pose from its truth; single-plane also split along the viewing "
      "ray through the bone centre (out-of-plane) and across it (in-plane). A failure is a frame above {:g} mm, lost, "
      "or not tracked. Frames/s: the frames after the first over their wall time (frame 0 is a full registration, "
      "its time apart).\n\n",
      kFailure_mm);
  out += "| condition | views | detector | sequences | frames | median sTRE mm | max sTRE mm | median in-plane mm | "
         "max in-plane mm | median out-of-plane mm | failures | lost | recoveries | frames/s | CPU s/frame | frame 0 s "
         "| accuracy target | speed target |\n";
  out += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const TrackingCondition& c : study.conditions) {
    const TrackingConditionStats s = statistics(c, records);
    const bool single = c.viewCount == 1;
    const double accuracy = single ? s.medianInPlane_mm : s.medianStre_mm;
    const std::string accuracyVerdict =
        s.frames == 0 ? "not measured"
                      : fmt::format("{} (median {} <= {:g}, no frame > {:g}: {})",
                                    verdict(accuracy, kTargetMedian_mm, false) == "met" && s.failures == 0 ? "met"
                                                                                                           : "NOT met",
                                    single ? "in-plane" : "sTRE", kTargetMedian_mm, kFailure_mm,
                                    s.failures == 0 ? "yes" : "no");
    const double fpsTarget = single ? kTargetSinglePlaneFps : kTargetBiplaneFps;
    out += fmt::format("| {} | {} | {}x{} at {:g} mm | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | "
                       "{} | {} (>= {:g}/s) |\n",
                       c.name, single ? "single-plane" : "biplane", c.detector_px, c.detector_px, c.pixelSpacing_mm,
                       s.sequences, s.frames, mm(s.medianStre_mm), mm(s.maxStre_mm), mm(s.medianInPlane_mm),
                       mm(s.maxInPlane_mm), mm(s.medianOutOfPlane_mm), s.failures, s.lost, s.recoveries,
                       std::isnan(s.framesPerSecond) ? "-" : fmt::format("{:.1f}", s.framesPerSecond),
                       std::isnan(s.cpuPerFrame_s) ? "-" : fmt::format("{:.2f}", s.cpuPerFrame_s),
                       std::isnan(s.firstFrameSeconds) ? "-" : fmt::format("{:.1f}", s.firstFrameSeconds),
                       accuracyVerdict, verdict(s.framesPerSecond, fpsTarget, true), fpsTarget);
  }
  std::string failures;
  for (const TrackingFrameRecord& r : records) {
    if (r.status == "failed") {
      failures += fmt::format("- {} sequence {} frame {}: {}\n", r.condition, r.sequence, r.frame, r.reason);
    }
  }
  if (!failures.empty()) out += "\n## Frames the tracker could not track\n\n" + failures;
  return out;
}

std::string TrackingReport::summaryCsv(const TrackingStudyDefinition& study,
                                       const std::vector<TrackingFrameRecord>& records) {
  std::string out =
      "condition,views,detector_px,sequences,frames,median_stre_mm,max_stre_mm,median_in_plane_mm,max_in_plane_mm,"
      "median_out_of_plane_mm,failures,lost,recoveries,frames_per_second,cpu_seconds_per_frame,first_frame_seconds\n";
  const auto number = [](double v) { return std::isnan(v) ? std::string("nan") : fmt::format("{:.6g}", v); };
  for (const TrackingCondition& c : study.conditions) {
    const TrackingConditionStats s = statistics(c, records);
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", s.condition, s.views, s.detector_px,
                       s.sequences, s.frames, number(s.medianStre_mm), number(s.maxStre_mm),
                       number(s.medianInPlane_mm), number(s.maxInPlane_mm), number(s.medianOutOfPlane_mm), s.failures,
                       s.lost, s.recoveries, number(s.framesPerSecond), number(s.cpuPerFrame_s),
                       number(s.firstFrameSeconds));
  }
  return out;
}

Result<std::vector<std::filesystem::path>> TrackingReport::write(const TrackingStudyDefinition& study,
                                                                 const std::vector<TrackingFrameRecord>& records,
                                                                 const std::vector<std::string>& notes,
                                                                 const std::filesystem::path& outDir) {
  const std::filesystem::path report = outDir / "report.md";
  const std::filesystem::path summary = outDir / "summary.csv";
  if (Status saved = TextFile::writeAtomically(report, markdown(study, records, notes)); !saved) return fail(saved.error());
  if (Status saved = TextFile::writeAtomically(summary, summaryCsv(study, records)); !saved) return fail(saved.error());
  return std::vector<std::filesystem::path>{report, summary};
}

}  // namespace fct
