// fluoroct track: follows the bone through a fluoroscopy sequence (Tracking/CineTracker): frame 0 is registered with a
// preset from --init or --landmarks, every later frame by a short local search from the constant-velocity
// prediction. Writes DIR/track.json, DIR/track.csv and DIR/track.png (the 6 pose parameters against frame); with
// --igtl sends one OpenIGTLink TRANSFORM per frame. Ctrl-C stops after the current frame and writes what is done.
#include <fmt/core.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "Base/JsonDocument.h"
#include "Base/TextFile.h"
#include "CliSupport.h"
#include "Evaluation/LineChart.h"
#include "Evaluation/TrackPoseChart.h"
#include "Geometry/RigidPose.h"
#include "InitialPoseInput.h"
#include "Interop/IgtlTransformSender.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/CtLoader.h"
#include "Registration/RegistrationViewLoader.h"
#include "Tracking/CineTracker.h"

namespace fct::cli {

namespace {

namespace fs = std::filesystem;

struct Options {
  std::string ct;
  std::string views;
  std::string init;
  std::string landmarks;
  std::string out;
  std::string preset = RegistrationSchedule::kDefaultPreset;
  std::uint32_t seed = 1;
  std::string method = "siddon";
  std::string frameDrr = "auto";
  std::string transgraphCache;  ///< empty = the default cache folder; "none" = no cache
  CineTrackerOptions tracker;
  bool noFieldOfView = false;
  bool noMetalMask = false;
  double cutFaceMargin_mm = RegistrationCaseOptions::kDefaultCutFaceMargin_mm;
  double boneContrast = RegistrationCaseOptions::kDefaultBoneContrast;
  std::string igtl;
  std::string igtlDevice = "FluoroCT";
};

/// The views' specs (each with a sequence) and frame 0 of every view.
struct Inputs {
  std::vector<ViewSpec> specs;
  std::vector<RegistrationView> views;
  int frameCount = 0;
  InitialPose initial;
  Volume ct;
};

/// Reads the view file (every view must have a sequence), frame 0, the initial pose and the CT; warnings to stderr.
Result<Inputs> readInputs(const Options& o) {
  if (Status flags = checkInitialPoseFlags(o.init, o.landmarks); !flags) return fail(flags.error());
  Inputs in;
  auto specs = ViewFile::read(o.views);
  if (!specs) return fail("--views: " + specs.error());
  printWarnings(specs.warnings());
  in.specs = std::move(specs).value();
  for (const ViewSpec& spec : in.specs) {
    if (!spec.sequence) {
      return fail(fmt::format("--views: view '{}' has no \"sequence\"; tracking needs the frames of every view as "
                              "\"sequence\": {{\"path\": \"cine.dcm\", \"frames\": \"all\"}} or a list of image files",
                              spec.name));
    }
    auto view = RegistrationViewLoader::loadFrame(spec, 0);
    if (!view) return fail("--views: " + view.error());
    printWarnings(view.warnings());
    in.views.push_back(std::move(view).value());
  }
  in.frameCount = in.specs.front().sequence->frameCount();
  auto initial = readInitialPose(o.init, o.landmarks, in.views);
  if (!initial) return fail(initial.error());
  in.initial = std::move(initial).value();
  auto ct = CtLoader::load(o.ct);
  if (!ct) return fail("--ct: " + ct.error());
  printWarnings(ct.warnings());
  in.ct = std::move(ct).value();
  return in;
}

/// Frame f of every view, as the tracker takes them.
Result<std::vector<XrayImage>> loadFrame(const Inputs& in, int f) {
  std::vector<XrayImage> images;
  for (const ViewSpec& spec : in.specs) {
    auto view = RegistrationViewLoader::loadFrame(spec, f);
    if (!view) return fail("--views: " + view.error());
    images.push_back(std::move(view).value().xray);
  }
  return images;
}

/// The case options: DRR method (Transgraph tables around the initial pose), field-of-view and metal exclusions, the
/// cut-face margin.
RegistrationCaseOptions caseOptionsFor(const Options& o, DrrMethod method, const Eigen::Isometry3d& T_initial) {
  RegistrationCaseOptions options;
  options.drr.method = method;
  options.drr.transgraphCacheFolder = transgraphCacheFolder(o.transgraphCache);
  if (method == DrrMethod::Transgraph) options.T_expected_world_from_ct = T_initial;
  options.preparation.detectFieldOfView = !o.noFieldOfView;
  options.preparation.excludeMetal = !o.noMetalMask;
  options.cutFaceMargin_mm = o.cutFaceMargin_mm;
  options.boneContrast = o.boneContrast;
  return options;
}

/// What the run did, for the output files and the summary.
struct TrackRun {
  std::vector<TrackedFrame> frames;
  Eigen::Vector3d centre_ct_mm = Eigen::Vector3d::Zero();
  std::string drrMethod;
  bool cancelled = false;
  int frameCount = 0;  ///< frames in the sequence
  CineTrackerOptions tracker;  ///< the settings the tracker ran with (the automatic level resolved)

  /// Frames after frame 0 per second of their tracking time (X-ray swap, search, recovery; not reading the files).
  double framesPerSecond() const {
    double seconds = 0.0;
    for (std::size_t i = 1; i < frames.size(); ++i) seconds += frames[i].seconds;
    return seconds > 0.0 ? static_cast<double>(frames.size() - 1) / seconds : 0.0;
  }
};

/// The pose parameters of a frame (rx, ry, rz deg, tx, ty, tz mm) about the bone centre.
PoseVector parametersOf(const TrackRun& run, const TrackedFrame& frame) {
  auto params = RigidPose::fromTransform(frame.T_world_from_ct, run.centre_ct_mm);
  return params ? params.value().asVector() : PoseVector::Constant(std::numeric_limits<double>::quiet_NaN());
}

nlohmann::ordered_json trackJson(const Options& o, const TrackRun& run) {
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (const TrackedFrame& f : run.frames) {
    nlohmann::ordered_json frame{{"index", f.index},
                                 {"T_world_from_ct", JsonDocument::array(f.T_world_from_ct.matrix())},
                                 {"similarity", f.similarity},
                                 {"seconds", f.seconds},
                                 {"status", CineTracker::statusName(f.status)},
                                 {"cpu_seconds", f.cpuSeconds},
                                 {"drrs", f.drrs}};
    if (!f.note.empty()) frame["note"] = f.note;
    if (f.cancelled) frame["cancelled"] = true;
    frames.push_back(std::move(frame));
  }
  return nlohmann::ordered_json{{"frames", std::move(frames)},
                                {"frames_per_second", run.framesPerSecond()},
                                {"frame_count", run.frameCount},
                                {"cancelled", run.cancelled},
                                {"rotation_centre_ct_mm", JsonDocument::array(run.centre_ct_mm)},
                                {"drr_method", run.drrMethod},
                                {"options",
                                 {{"ct", o.ct},
                                  {"views", o.views},
                                  {"preset", o.preset},
                                  {"cut_face_margin_mm", o.cutFaceMargin_mm},
                                  {"bone_contrast", o.boneContrast},
                                  {"level", run.tracker.level},
                                  {"roi_fraction", run.tracker.roiFraction},
                                  {"max_evaluations", run.tracker.maxEvaluations},
                                  {"refine_evaluations", run.tracker.refineEvaluations},
                                  {"frame_drr", DrrRendererFactory::methodName(*run.tracker.frameDrr)},
                                  {"depth_velocity", run.tracker.depthVelocityFactor},
                                  {"depth_scale", run.tracker.depthScale},
                                  {"dissimilarity_growth", run.tracker.dissimilarityGrowth},
                                  {"max_jump_mm", run.tracker.maxJump_mm},
                                  {"max_jump_deg", run.tracker.maxJump_deg},
                                  {"confirm_mm", run.tracker.confirmTolerance_mm},
                                  {"confirm_deg", run.tracker.confirmTolerance_deg}}}};
}

std::string trackCsv(const TrackRun& run) {
  std::string csv = "index,rx_deg,ry_deg,rz_deg,tx_mm,ty_mm,tz_mm,similarity,seconds,cpu_seconds,drrs,status\n";
  for (const TrackedFrame& f : run.frames) {
    const PoseVector p = parametersOf(run, f);
    csv += fmt::format("{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.6f},{:.4f},{:.4f},{},{}\n", f.index, p[0], p[1],
                       p[2], p[3], p[4], p[5], f.similarity, f.seconds, f.cpuSeconds, f.drrs,
                       CineTracker::statusName(f.status));
  }
  return csv;
}

Status writeChart(const TrackRun& run, const fs::path& path) {
  return LineChart::writePng(TrackPoseChart::spec(run.frames, run.centre_ct_mm), path);
}

/// Writes track.json, track.csv and track.png in --out (each atomically).
Status writeOutputs(const Options& o, const TrackRun& run) {
  const fs::path dir(o.out);
  if (Status written = JsonDocument::write(trackJson(o, run), dir / "track.json"); !written) return written;
  if (Status written = TextFile::writeAtomically(dir / "track.csv", trackCsv(run)); !written) return written;
  return writeChart(run, dir / "track.png");
}

/// --igtl: one TRANSFORM per frame; failures are warnings (the first one printed, the rest counted).
class FrameSender {
 public:
  static Result<FrameSender> fromOptions(const Options& o) {
    FrameSender sender;
    if (o.igtl.empty()) return sender;
    auto endpoint = IgtlTransformSender::parseEndpoint(o.igtl);
    if (!endpoint) return fail("--igtl: " + endpoint.error());
    if (Status name = IgtlTransformSender::checkDeviceName(o.igtlDevice); !name) {
      return fail("--igtl-device: " + name.error());
    }
    sender.m_sender = std::make_shared<IgtlTransformSender>(endpoint.value(), o.igtlDevice);
    return sender;
  }
  void send(const TrackedFrame& frame) {
    if (!m_sender) return;
    if (Status sent = m_sender->send(frame.T_world_from_ct); sent) {
      ++m_sent;
    } else if (m_failed++ == 0) {
      printWarnings({fmt::format("--igtl: frame {} was not sent: {}", frame.index, sent.error())});
    }
  }
  void printSummary() const {
    if (m_sender) fmt::print("sent {} of {} frames to {} (RAS)\n", m_sent, m_sent + m_failed, m_sender->endpoint().text());
  }

 private:
  std::shared_ptr<IgtlTransformSender> m_sender;
  int m_sent = 0;
  int m_failed = 0;
};

void printFrame(const TrackedFrame& f, int frameCount) {
  fmt::print(stderr, "frame {:4}/{} {:<9} similarity {:.4f}  {:6.3f} s (cpu {:6.3f} s, swap {:5.3f} s) {:5} DRRs{}{}\n", f.index,
             frameCount, CineTracker::statusName(f.status), f.similarity, f.seconds, f.cpuSeconds, f.swapSeconds,
             f.drrs, f.cancelled ? " (cancelled)" : "", f.note.empty() ? "" : "  " + f.note);
  std::fflush(stderr);
}

void printSummary(const Options& o, const TrackRun& run) {
  int counts[3] = {0, 0, 0};
  std::vector<double> cpu;
  for (std::size_t i = 0; i < run.frames.size(); ++i) {
    ++counts[static_cast<int>(run.frames[i].status)];
    if (i > 0) cpu.push_back(run.frames[i].cpuSeconds);
  }
  std::sort(cpu.begin(), cpu.end());
  fmt::print("{} {} of {} frames: {} tracked, {} recovered, {} lost; {:.2f} frames/s after frame 0 at pyramid level {} "
             "(frame 0: {:.2f} s)",
             run.cancelled ? "cancelled after" : "tracked", run.frames.size(), run.frameCount, counts[0], counts[1],
             counts[2], run.framesPerSecond(), run.tracker.level, run.frames.empty() ? 0.0 : run.frames.front().seconds);
  if (!cpu.empty()) fmt::print("; per-frame CPU median {:.3f} s, max {:.3f} s", cpu[cpu.size() / 2], cpu.back());
  fmt::print("; wrote {}\n", (fs::path(o.out) / "track.json").string());
}

int runTrack(const Options& o) {
  auto sender = FrameSender::fromOptions(o);
  if (!sender) return reportError(sender.error());
  auto method = DrrRendererFactory::parseMethod(o.method);
  if (!method) return reportError("--method: " + method.error());
  auto frameDrr = DrrRendererFactory::parseMethod(o.frameDrr);
  if (o.frameDrr != "auto" && (!frameDrr || frameDrr.value() == DrrMethod::Transgraph)) {
    return reportError(fmt::format("--frame-drr: '{}' is not a frame DRR method; use auto, raycast or siddon",
                                   o.frameDrr));
  }
  auto schedule = RegistrationSchedule::resolve(o.preset);
  if (!schedule) return reportError("--preset: " + schedule.error());
  auto inputs = readInputs(o);
  if (!inputs) return reportError(inputs.error());
  const Inputs& in = inputs.value();
  const InterruptGuard interrupt;  // Ctrl-C ends the run after the current frame, with the frames so far written
  const std::atomic<bool>* cancel = InterruptGuard::cancelFlag();
  auto registrationCase = RegistrationCase::create(in.ct, in.views,
                                                   caseOptionsFor(o, method.value(), in.initial.T_world_from_ct),
                                                   ProgressMonitor(ProgressMonitor::Callback{}, cancel));
  if (!registrationCase) return reportError(registrationCase.error());
  printWarnings(registrationCase.warnings());
  CineTrackerOptions trackerOptions = o.tracker;
  if (frameDrr) trackerOptions.frameDrr = frameDrr.value();
  trackerOptions.firstFrame.schedule = std::move(schedule).value();
  trackerOptions.firstFrame.seed = o.seed;
  auto tracker = CineTracker::create(registrationCase.value(), trackerOptions);
  if (!tracker) return reportError(tracker.error());
  std::error_code ec;  // made once the inputs and options are known to be good, so a bad run leaves no folder
  fs::create_directories(o.out, ec);
  if (ec) return reportError(fmt::format("--out: cannot create the folder '{}': {}", o.out, ec.message()));

  TrackRun run;
  run.centre_ct_mm = registrationCase.value().rotationCentre_ct_mm();
  run.drrMethod = std::string(DrrRendererFactory::methodName(method.value()));
  run.frameCount = in.frameCount;
  run.tracker = tracker.value().options();
  auto first = tracker.value().trackFirst(in.initial.T_world_from_ct, cancel);
  if (!first) return reportError(first.error());
  run.frames.push_back(first.value());
  printFrame(first.value(), in.frameCount);
  sender.value().send(first.value());
  run.cancelled = first.value().cancelled;
  for (int f = 1; f < in.frameCount && !run.cancelled; ++f) {
    auto images = loadFrame(in, f);
    if (!images) return reportError(images.error());
    auto frame = tracker.value().trackNext(images.value(), cancel);
    if (!frame) return reportError(frame.error());
    run.cancelled = frame.value().cancelled || cancel->load();
    run.frames.push_back(frame.value());
    printFrame(frame.value(), in.frameCount);
    sender.value().send(frame.value());
  }
  if (Status written = writeOutputs(o, run); !written) return reportError(written.error());
  printSummary(o, run);
  sender.value().printSummary();
  return 0;
}

}  // namespace

void registerTrackCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "track", "Follow the bone through a fluoroscopy sequence: register frame 0, then track every later frame from "
               "a constant-velocity prediction; writes DIR/track.json, track.csv and track.png");
  command->add_option("--ct", options->ct, "CT volume (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd) or DICOM series folder")
      ->required();
  command->add_option("--views", options->views,
                      "View file (JSON); every view gives its frames as \"sequence\" (a multi-frame DICOM range or a "
                      "list of image files), all with the same frame count")
      ->required();
  auto* init = command->add_option("--init", options->init,
                                   "Initial pose of frame 0: pose file {\"T_world_from_ct\": 4x4} or ITK transform (.tfm)");
  auto* landmarks = command->add_option("--landmarks", options->landmarks,
                                        "Landmark pair file for frame 0's initial pose (see register --landmarks)");
  init->excludes(landmarks);
  command->add_option("--out", options->out, "Output folder (created): track.json, track.csv, track.png")->required();
  command->add_option("--preset", options->preset, "Schedule of frame 0 (and the global stages of a recovery)")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the random searches")->capture_default_str();
  command->add_option("--method", options->method,
                      "DRR method of frame 0 and, for transgraph, of the per-frame search: siddon (exact) or "
                      "transgraph (one ray table per view built once around frame 0's initial pose)")
      ->capture_default_str();
  command->add_option("--transgraph-cache", options->transgraphCache,
                      "Folder of the transgraph table cache (default: ~/.cache/fluoroct/transgraph); 'none' disables it");
  command->add_option("--level", options->tracker.level,
                      fmt::format("Pyramid level of the per-frame search (0 = full resolution, 1 = 1:4 pixels, 2 = "
                                  "1:16; -1 = automatic: the finest level at most {} px on its shorter side)",
                                  CineTracker::kAutomaticLevelSide_px))
      ->capture_default_str();
  command->add_option("--roi-fraction", options->tracker.roiFraction,
                      "Fraction of the valid pixels in the per-frame dynamic ROIs")
      ->capture_default_str();
  command->add_option("--max-evaluations", options->tracker.maxEvaluations, "Cap on DRR sets of a frame's search")
      ->capture_default_str();
  command->add_option("--refine-evaluations", options->tracker.refineEvaluations,
                      "After the per-frame search, an exact-DRR refinement with this cap on DRR sets (0 = none; for "
                      "--method transgraph)")
      ->capture_default_str();
  command->add_option("--frame-drr", options->frameDrr,
                      "How the per-frame search renders without Transgraph tables, on the CT coarsened to the "
                      "tracking level: auto (raycast with one view, siddon with two or more), raycast (trilinear: a "
                      "smooth similarity, which a single-plane search needs to find the depth) or siddon (exact box "
                      "voxels, faster)")
      ->capture_default_str();
  command->add_option("--depth-scale", options->tracker.depthScale,
                      "Single-plane: the per-frame search's step along the viewing ray, in steps across it (1 to "
                      "100; one view sees depth only through the magnification)")
      ->capture_default_str();
  command->add_option("--depth-velocity", options->tracker.depthVelocityFactor,
                      "Single-plane: fraction of the last frame-to-frame motion along the viewing ray carried into the "
                      "next frame's start (0 keeps the depth, 1 = full constant velocity)")
      ->capture_default_str();
  command->add_option("--dissimilarity-growth", options->tracker.dissimilarityGrowth,
                      "Lost track: 1 - similarity above this times the reference (the smaller of the running level's "
                      "and frame 0's, at least 0.005)")
      ->capture_default_str();
  command->add_option("--max-jump-mm", options->tracker.maxJump_mm,
                      "Lost track: bone centre more than this far from the prediction (mm)")
      ->capture_default_str();
  command->add_option("--max-jump-deg", options->tracker.maxJump_deg,
                      "Lost track: rotation more than this from the prediction (deg)")
      ->capture_default_str();
  command->add_option("--confirm-mm", options->tracker.confirmTolerance_mm,
                      "Lost track: a suspect frame whose similarity fell gradually is kept (recovered, the similarity "
                      "level re-anchored there) when its re-registration lands within this of the tracked pose (bone "
                      "centre, mm)")
      ->capture_default_str();
  command->add_option("--confirm-deg", options->tracker.confirmTolerance_deg,
                      "Lost track: the confirmation's rotation tolerance (deg)")
      ->capture_default_str();
  command->add_flag("--no-fov", options->noFieldOfView, "Skip the field-of-view (collimator) detection");
  command->add_flag("--no-metal-mask", options->noMetalMask, "Compare metal shadows too instead of excluding them");
  addCutFaceMarginOption(*command, options->cutFaceMargin_mm);
  addBoneContrastOption(*command, options->boneContrast);
  auto* igtl = command->add_option("--igtl", options->igtl,
                                   "Send each frame's pose to an OpenIGTLink server HOST:PORT as a TRANSFORM (RAS)");
  command->add_option("--igtl-device", options->igtlDevice, "Device name of the TRANSFORM (1-20 characters)")
      ->capture_default_str()
      ->needs(igtl);
  command->callback([&action, options] { action = [options] { return runTrack(*options); }; });
}

}  // namespace fct::cli
