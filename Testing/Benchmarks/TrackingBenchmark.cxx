// Tracking benchmark: frames per second and per-frame pose error of CineTracker on a simulated sequence (the bone
// moving smoothly, every frame rendered by the physical simulator, TrackingTestSequence.h), once with exact DRRs
// (frame 0 Siddon; the frames --frame-drr, trilinear by default, on the CT coarsened to the tracking level) and once
// with per-view Transgraph tables built around frame 0's start pose (table build time reported apart). Frame 0 is
// registered with the default preset from 3 mm off the truth. The error
// of a frame is the mean bone-surface distance to its true pose; frames/s counts the frames after frame 0 over their
// tracking time (X-ray swap, search, recovery), and the CPU time per frame is printed beside it.
//
// Usage: fluoroct_tracking_benchmark --ct CT [--views 1|2] [--size PIXELS] [--pixel-mm MM] [--frames N]
//                                    [--amplitude-mm MM] [--amplitude-deg DEG] [--period FRAMES] [--level L]
//                                    [--roi-fraction F] [--max-evaluations N] [--refine-evaluations N]
//                                    [--method siddon|transgraph|both] [--frame-drr raycast|siddon]
//                                    [--depth-scale S]
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <ctime>
#include <string>
#include <vector>

#include "IO/Volume/CtLoader.h"
#include "Tracking/CineTracker.h"
#include "TrackingTestSequence.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// Tracks the sequence with `method`; prints one line per frame and a summary. Returns false on an error.
bool runMethod(const fct::Volume& ct, const fct::test::SimulatedSequence& sequence, fct::DrrMethod method,
               const fct::CineTrackerOptions& trackerOptions) {
  Eigen::Isometry3d start = sequence.T_truth[0];
  start.translation() += Eigen::Vector3d(2.0, -1.5, 1.5);
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.drr.method = method;
  caseOptions.drr.transgraphCacheFolder = std::nullopt;
  if (method == fct::DrrMethod::Transgraph) caseOptions.T_expected_world_from_ct = start;
  auto registrationCase = fct::RegistrationCase::create(ct, sequence.views, caseOptions);
  if (!registrationCase) return fmt::print(stderr, "error: {}\n", registrationCase.error()), false;
  auto tracker = fct::CineTracker::create(registrationCase.value(), trackerOptions);
  if (!tracker) return fmt::print(stderr, "error: {}\n", tracker.error()), false;
  // "siddon/raycast": frame 0 with Siddon DRRs, the frames with the tracker's exact frame DRR method.
  std::string name(fct::DrrRendererFactory::methodName(method));
  if (method != fct::DrrMethod::Transgraph) {
    name += "/" + std::string(fct::DrrRendererFactory::methodName(*tracker.value().options().frameDrr));
  }
  fmt::print("== {} (table setup {:.2f} s)\n", name, registrationCase.value().viewRendererSetupSeconds());

  auto first = tracker.value().trackFirst(start);
  if (!first) return fmt::print(stderr, "error: {}\n", first.error()), false;
  const fct::BoneSurface& bone = *registrationCase.value().bone();
  std::vector<fct::TrackedFrame> frames{first.value()};
  for (std::size_t f = 1; f < sequence.frames.size(); ++f) {
    auto frame = tracker.value().trackNext(sequence.frames[f]);
    if (!frame) return fmt::print(stderr, "error: {}\n", frame.error()), false;
    frames.push_back(frame.value());
  }
  std::vector<double> errors, cpu, swap;
  double seconds = 0.0, maxError = 0.0;
  int statusCounts[3] = {0, 0, 0};
  for (const fct::TrackedFrame& f : frames) {
    const double error = bone.meanDistance_mm(f.T_world_from_ct, sequence.T_truth[static_cast<std::size_t>(f.index)]);
    fmt::print("{:<10} frame {:3} {:<9} error {:6.3f} mm  similarity {:.4f}  {:6.3f} s (cpu {:6.3f} s, swap {:5.3f} s) "
               "{:4} DRRs {:8} fallback rays\n",
               name, f.index, fct::CineTracker::statusName(f.status), error, f.similarity, f.seconds, f.cpuSeconds,
               f.swapSeconds, f.drrs, f.fallbackRays);
    ++statusCounts[static_cast<int>(f.status)];
    if (f.index == 0) continue;
    errors.push_back(error);
    maxError = std::max(maxError, error);
    cpu.push_back(f.cpuSeconds);
    swap.push_back(f.swapSeconds);
    seconds += f.seconds;
  }
  fmt::print("{:<10} SUMMARY frames 1..{}: {:.2f} frames/s, median error {:.3f} mm, max {:.3f} mm, median CPU {:.3f} s "
             "per frame, median swap {:.3f} s; {} tracked, {} recovered, {} lost; frame 0 error {:.3f} mm in {:.2f} s\n",
             name, errors.size(), errors.size() / seconds, median(errors), maxError, median(cpu), median(swap),
             statusCounts[0], statusCounts[1], statusCounts[2],
             bone.meanDistance_mm(first.value().T_world_from_ct, sequence.T_truth[0]), first.value().seconds);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"CineTracker frames/s and per-frame error on a simulated sequence"};
  std::string ctPath, method = "both";
  fct::test::SequenceOptions sequenceOptions;
  sequenceOptions.size_px = 512;
  sequenceOptions.pixelSpacing_mm = 0.6;
  sequenceOptions.frames = 21;
  sequenceOptions.amplitude_mm = 10.0;
  sequenceOptions.amplitude_deg = 5.0;
  sequenceOptions.period_frames = 60.0;
  fct::CineTrackerOptions trackerOptions;
  app.add_option("--ct", ctPath, "CT volume or DICOM folder")->required();
  app.add_option("--views", sequenceOptions.viewCount, "1 = single-plane (AP), 2 = biplane (AP, lateral)");
  app.add_option("--size", sequenceOptions.size_px, "Square detector side, pixels")->capture_default_str();
  app.add_option("--pixel-mm", sequenceOptions.pixelSpacing_mm, "Detector pixel size, mm")->capture_default_str();
  app.add_option("--frames", sequenceOptions.frames, "Frames")->capture_default_str();
  app.add_option("--amplitude-mm", sequenceOptions.amplitude_mm, "Translation amplitude")->capture_default_str();
  app.add_option("--amplitude-deg", sequenceOptions.amplitude_deg, "Rotation amplitude")->capture_default_str();
  app.add_option("--period", sequenceOptions.period_frames, "Motion period, frames")->capture_default_str();
  app.add_option("--level", trackerOptions.level, "Tracking pyramid level")->capture_default_str();
  app.add_option("--roi-fraction", trackerOptions.roiFraction, "Tracking ROI fraction")->capture_default_str();
  app.add_option("--max-evaluations", trackerOptions.maxEvaluations, "Tracking evaluation cap")->capture_default_str();
  app.add_option("--refine-evaluations", trackerOptions.refineEvaluations, "Exact refinement cap (0 = none)")
      ->capture_default_str();
  app.add_option("--method", method, "siddon, transgraph or both")->capture_default_str();
  std::string frameDrr = "auto";
  app.add_option("--frame-drr", frameDrr, "Frames' exact DRRs (method siddon): auto, raycast or siddon")
      ->capture_default_str();
  app.add_option("--depth-scale", trackerOptions.depthScale, "Single-plane depth scale of the frame search")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (frameDrr != "auto") {
    auto frameMethod = fct::DrrRendererFactory::parseMethod(frameDrr);
    if (!frameMethod) return fmt::print(stderr, "error: --frame-drr: {}\n", frameMethod.error()), 2;
    trackerOptions.frameDrr = frameMethod.value();
  }

  auto ct = fct::CtLoader::load(ctPath);
  if (!ct) return fmt::print(stderr, "error: {}\n", ct.error()), 2;
  const std::clock_t simulationCpu = std::clock();
  auto sequence = fct::test::simulateSequence(ct.value(), sequenceOptions);
  if (!sequence) return fmt::print(stderr, "error: {}\n", sequence.error()), 2;
  fmt::print("simulated {} frames of {} view(s) at {}^2, {} mm pixels (physical simulator, {:.1f} s CPU)\n",
             sequenceOptions.frames, sequenceOptions.viewCount, sequenceOptions.size_px,
             sequenceOptions.pixelSpacing_mm, static_cast<double>(std::clock() - simulationCpu) / CLOCKS_PER_SEC);
  bool ok = true;
  if (method == "siddon" || method == "both") ok &= runMethod(ct.value(), sequence.value(), fct::DrrMethod::Siddon, trackerOptions);
  if (method == "transgraph" || method == "both") {
    ok &= runMethod(ct.value(), sequence.value(), fct::DrrMethod::Transgraph, trackerOptions);
  }
  return ok ? 0 : 2;
}
