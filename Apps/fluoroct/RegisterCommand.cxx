// fluoroct register: registers a CT to the X-ray views of a view file (Registration, a preset schedule) from an
// initial pose given as a pose file or estimated from landmarks; writes RESULT.json (and a DICOM REG object). Also a 3D Slicer CLI module
// (--xml, --tfm, --returnparameterfile; SlicerModule.h) and, with --igtl, sends the pose live to Slicer over
// OpenIGTLink (Interop/IgtlTransformSender) once the result is written.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Base/JsonDocument.h"
#include "CliSupport.h"
#include "InitialPoseInput.h"
#include "Evaluation/ContourOverlay.h"
#include "Interop/IgtlTransformSender.h"
#include "IO/Project/ItkTransformFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/CtLoader.h"
#include "IO/Xray/ImageFileWriter.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationDicomExport.h"
#include "Registration/RegistrationResultJson.h"
#include "Registration/RegistrationViewLoader.h"
#include "SlicerModule.h"

namespace fct::cli {

namespace {

namespace fs = std::filesystem;

struct Options {
  std::string ct;
  std::string views;
  std::string init;
  std::string landmarks;
  std::string preset = RegistrationSchedule::kDefaultPreset;
  std::uint32_t seed = 1;
  std::string method = "siddon";
  std::string transgraphCache;  ///< empty = the default cache folder; "none" = no cache
  double transgraphSpacing_mm = TransgraphParameters{}.spacing_mm;
  std::string out;
  std::string overlays;
  std::string truth;  ///< optional known true pose (simulated cases): the pose error is reported
  bool progress = false;
  bool noFieldOfView = false;
  bool noMetalMask = false;
  double metalMinExcess = MetalMaskOptions{}.minExcess;
  double cutFaceMargin_mm = RegistrationCaseOptions{}.cutFaceMargin_mm;
  double boneContrast = RegistrationCaseOptions{}.boneContrast;
  double rayCastStep_mm = DrrRendererOptions{}.rayCastStep_mm;
  bool rayCastStepGiven = false;  ///< --raycast-step-mm was on the command line (it only applies to --method raycast)
  std::string masks;  ///< optional folder for each view's full-resolution validity mask (PNG)
  std::string dicomReg;  ///< optional DICOM Spatial Registration object (REG) of the final pose
  RegistrationAblation ablation;
  std::string tfm;                  ///< optional ITK transform file of the registered pose (Slicer's output transform)
  std::string returnParameterFile;  ///< optional "name = value" file of the scalar results (Slicer CLI modules)
  std::string igtl;                 ///< optional OpenIGTLink server HOST:PORT to send the pose to
  std::string igtlDevice = "FluoroCT";
  bool igtlProgress = false;
};

/// Writes a validity mask as an 8-bit-range PNG (white = compared, black = excluded), creating the folder.
Status writeMaskPng(const ValidMask& mask, const fs::path& path) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  if (ec) return fail(fmt::format("cannot create the mask folder '{}': {}", path.parent_path().string(), ec.message()));
  FloatImage image{mask.cols, mask.rows, std::vector<float>(mask.valid.begin(), mask.valid.end())};
  return ImageFileWriter::writePng16(image, path, 0.0f, 1.0f);
}

/// Everything register reads before it prepares the case.
struct Inputs {
  DrrMethod method = DrrMethod::Siddon;
  RegistrationSchedule schedule;
  std::vector<RegistrationView> views;
  InitialPose initial;
  std::optional<Eigen::Isometry3d> T_truth;
  Volume ct;
};

/// Checks the options and reads the views, the initial pose, the truth and the CT; warnings go to stderr.
Result<Inputs> readInputs(const Options& o) {
  if (Status flags = checkInitialPoseFlags(o.init, o.landmarks); !flags) return fail(flags.error());
  if (!o.tfm.empty()) {
    if (Status writable = checkWritableTransform(o.tfm); !writable) return fail("--tfm: " + writable.error());
  }
  Inputs in;
  auto method = DrrRendererFactory::parseMethod(o.method);
  if (!method) return fail("--method: " + method.error());
  in.method = method.value();
  if (o.rayCastStepGiven && in.method != DrrMethod::RayCast) {
    return fail(fmt::format("--raycast-step-mm sets the sampling step of --method raycast; it has no effect with "
                            "--method {}: drop it, or add --method raycast",
                            o.method));
  }
  auto schedule = RegistrationSchedule::resolve(o.preset);
  if (!schedule) return fail("--preset: " + schedule.error());
  in.schedule = std::move(schedule).value();
  auto views = RegistrationViewLoader::load(o.views);
  if (!views) return fail("--views: " + views.error());
  printWarnings(views.warnings());
  in.views = std::move(views).value();
  auto initial = readInitialPose(o.init, o.landmarks, in.views);
  if (!initial) return fail(initial.error());
  in.initial = std::move(initial).value();
  if (!o.truth.empty()) {
    auto truth = PoseFile::read(o.truth);
    if (!truth) return fail("--truth: " + truth.error());
    in.T_truth = truth.value();
  }
  auto ct = CtLoader::load(o.ct);
  if (!ct) return fail("--ct: " + ct.error());
  printWarnings(ct.warnings());
  in.ct = std::move(ct).value();
  return in;
}

/// Draws a one-line progress bar on stderr, at most every 100 ms.
class ProgressBar {
 public:
  void update(const RegistrationProgress& p) {
    const auto now = std::chrono::steady_clock::now();
    if (now - m_last < std::chrono::milliseconds(100)) return;
    m_last = now;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(p.fraction * kWidth + 0.5);
    fmt::print(stderr, "\r[{}{}] {:3.0f}%  stage {}/{} {:<16} eval {:5}  DRRs {:6}  best {:.4f} ",
               std::string(static_cast<std::size_t>(filled), '#'), std::string(kWidth - filled, '.'), 100.0 * p.fraction,
               p.stageIndex + 1, p.stageCount, p.stage, p.iteration, p.drrs, p.bestSimilarity);
    m_drawn = true;
  }
  void finish() {
    if (m_drawn) fmt::print(stderr, "\n");
  }

 private:
  std::chrono::steady_clock::time_point m_last{};
  bool m_drawn = false;
};

/// The case options of the command: DRR method and Transgraph tables (built around the initial pose unless switched
/// off), field-of-view and metal exclusions.
RegistrationCaseOptions caseOptionsFor(const Options& o, const Inputs& in) {
  RegistrationCaseOptions options;
  options.drr.method = in.method;
  options.drr.rayCastStep_mm = o.rayCastStep_mm;
  options.drr.transgraph.spacing_mm = o.transgraphSpacing_mm;
  options.drr.transgraphCacheFolder = transgraphCacheFolder(o.transgraphCache);
  if (!o.ablation.noTransgraph) options.T_expected_world_from_ct = in.initial.T_world_from_ct;
  options.preparation.detectFieldOfView = !o.noFieldOfView;
  options.preparation.excludeMetal = !o.noMetalMask;
  options.preparation.metal.minExcess = o.metalMinExcess;
  options.cutFaceMargin_mm = o.cutFaceMargin_mm;
  options.boneContrast = o.boneContrast;
  return options;
}

/// Prepares the registration case (X-ray pyramids, masks, Transgraph tables), with table progress on stderr under
/// --progress; warnings go to stderr.
Result<RegistrationCase> prepareCase(const Options& o, const Inputs& in, const RegistrationCaseOptions& options,
                                     const std::atomic<bool>* cancel) {
  ProgressMonitor::Callback onTableProgress;
  if (o.progress) {
    onTableProgress = [](const ProgressUpdate& u) {
      fmt::print(stderr, "\r{}: {:3.0f}% {:<40}", u.stage, 100.0 * u.fraction, u.message);
    };
  }
  auto registrationCase = RegistrationCase::create(in.ct, in.views, options, ProgressMonitor(onTableProgress, cancel));
  if (onTableProgress && options.drr.method == DrrMethod::Transgraph) fmt::print(stderr, "\n");
  printWarnings(registrationCase.warnings());
  return registrationCase;
}

/// The case's Transgraph tables for RESULT.json (null without tables), each also printed as one line.
nlohmann::ordered_json transgraphReport(const RegistrationCase& c) {
  if (!c.transgraph(0)) return nullptr;
  nlohmann::ordered_json report{{"setup_seconds", c.viewRendererSetupSeconds()},
                                {"views", nlohmann::ordered_json::object()}};
  for (std::size_t v = 0; v < c.viewCount(); ++v) {
    const Transgraph& table = c.transgraph(v)->transgraph();
    report["views"][c.viewName(v)] = {{"rays", table.rayCount()},
                                      {"memory_bytes", table.memory_bytes()},
                                      {"seconds", table.buildInfo().build_s},
                                      {"loaded_from_cache", table.buildInfo().loadedFromCache},
                                      {"cache_file", table.buildInfo().cacheFile.string()}};
    fmt::print("transgraph {:<10} {:6.1f} M rays, {:5.0f} MB, {} in {:.2f} s\n", c.viewName(v), table.rayCount() / 1e6,
               table.memory_bytes() / 1e6, table.buildInfo().loadedFromCache ? "loaded from the cache" : "built",
               table.buildInfo().build_s);
  }
  return report;
}

/// The RESULT.json members of the metal mask, printed a line per view ending with `when` (e.g. " after the metal
/// review"): each view's fraction of the field excluded as metal ("metal_fraction") and, with a cut-face margin, of
/// the field whose rays clear the CT's cut faces at `T_world_from_ct` ("metal_fraction_covered": what the mask takes
/// from the comparison). None with --no-metal-mask. Fails on a bad view (not expected: the case's own).
Result<nlohmann::ordered_json> metalReport(const Options& o, const RegistrationCase& c,
                                           const Eigen::Isometry3d& T_world_from_ct, const std::string& when = {}) {
  nlohmann::ordered_json report = nlohmann::ordered_json::object();
  if (o.noMetalMask) return report;
  nlohmann::ordered_json fractions = nlohmann::ordered_json::object();
  nlohmann::ordered_json covered = nlohmann::ordered_json::object();
  const bool cutFaces = o.cutFaceMargin_mm >= 0.0;
  for (std::size_t v = 0; v < c.viewCount(); ++v) {
    fractions[c.viewName(v)] = c.prepared(v).metalFraction;
    std::string coveredText;
    if (cutFaces) {
      auto fraction = c.metalFractionOfCoveredField(v, T_world_from_ct);
      if (!fraction) return fail(fmt::format("view {}: {}", c.viewName(v), fraction.error()));
      covered[c.viewName(v)] = fraction.value();
      coveredText =
          fmt::format(" ({:.2f} % of the field whose rays clear the CT's cut faces)", 100.0 * fraction.value());
    }
    fmt::print("view {}: metal mask excludes {:.2f} % of the field{}{}\n", c.viewName(v),
               100.0 * c.prepared(v).metalFraction, coveredText, when);
  }
  report["metal_fraction"] = std::move(fractions);
  if (cutFaces) report["metal_fraction_covered"] = std::move(covered);
  return report;
}

/// --masks: each view's full-resolution validity mask as <view>_mask.png.
Status writeMasks(const Options& o, const RegistrationCase& c) {
  if (o.masks.empty()) return Ok{};
  for (std::size_t v = 0; v < c.viewCount(); ++v) {
    const Status written =
        writeMaskPng(c.prepared(v).pyramid.level(0).mask, fs::path(o.masks) / (c.viewName(v) + "_mask.png"));
    if (!written) return written;
  }
  return Ok{};
}

/// Runs the schedule from the initial pose, with the progress bar on stderr under --progress; `onStageEnd` gets each
/// stage's report.
Result<RegistrationResult> runRegistration(const Options& o, const Inputs& in, RegistrationCase& registrationCase,
                                           const std::atomic<bool>* cancel,
                                           const RegistrationStageCallback& onStageEnd) {
  RegistrationOptions options;
  options.schedule = in.schedule;
  options.ablation = o.ablation;
  options.seed = o.seed;
  ProgressBar bar;
  RegistrationProgressCallback onProgress;
  if (o.progress) onProgress = [&bar](const RegistrationProgress& p) { bar.update(p); };
  auto result =
      Registration::run(registrationCase, in.initial.T_world_from_ct, options, onProgress, cancel, onStageEnd);
  bar.finish();
  return result;
}

/// --overlays: one PNG per view with the bone outlines at the initial and the registered pose.
Status writeOverlays(const Options& o, const Inputs& in, double boneThreshold_hu, const RegistrationResult& r) {
  if (o.overlays.empty()) return Ok{};
  auto overlay = ContourOverlay::create(in.ct, boneThreshold_hu);
  if (!overlay) return fail("overlays: " + overlay.error());
  std::error_code ec;
  fs::create_directories(o.overlays, ec);
  if (ec) return fail(fmt::format("cannot create the overlay folder '{}': {}", o.overlays, ec.message()));
  for (const RegistrationView& view : in.views) {
    const Status written = overlay.value().writeOverlayPng(view.xray, view.camera, r.T_initial, r.T_world_from_ct,
                                                           fs::path(o.overlays) / (view.name + ".png"));
    if (!written) return fail(fmt::format("overlay of view '{}': {}", view.name, written.error()));
  }
  return Ok{};
}

/// The pose error against the truth as the paper measures it: mean (max) bone-surface distance, initial and final.
struct TruthError {
  double initialMean_mm = 0.0;
  double finalMean_mm = 0.0;
  double finalMax_mm = 0.0;
};

/// The pose error against --truth; nullopt without --truth or when the CT has no bone surface.
std::optional<TruthError> truthError(const Inputs& in, const RegistrationCase& c, const RegistrationResult& r) {
  if (!in.T_truth || !c.bone()) return std::nullopt;
  const BoneSurface& bone = *c.bone();
  return TruthError{bone.meanDistance_mm(r.T_initial, *in.T_truth),
                    bone.meanDistance_mm(r.T_world_from_ct, *in.T_truth),
                    bone.maxDistance_mm(r.T_world_from_ct, *in.T_truth)};
}

/// RESULT.json: the result object (RegistrationResultJson) with where the initial pose came from, the command's
/// options, the Transgraph tables, the metal mask's members (metalReport) and the error against --truth added.
nlohmann::ordered_json resultJson(const Options& o, const RegistrationResult& r, nlohmann::ordered_json initialSource,
                                  nlohmann::ordered_json transgraph, nlohmann::ordered_json metal,
                                  const std::optional<TruthError>& error) {
  nlohmann::ordered_json json = RegistrationResultJson::write(r);
  for (const auto& item : json["initial_pose"].items()) initialSource[item.key()] = item.value();
  json["initial_pose"] = std::move(initialSource);
  nlohmann::ordered_json options{{"ct", o.ct},
                                 {"views", o.views},
                                 {"preset", o.preset},
                                 {"seed", o.seed},
                                 {"ablation", o.ablation.activeNames()},
                                 {"field_of_view_detection", !o.noFieldOfView},
                                 {"metal_mask", !o.noMetalMask},
                                 {"metal_min_excess", o.metalMinExcess},
                                 {"cut_face_margin_mm", o.cutFaceMargin_mm},
                                 {"bone_contrast", o.boneContrast},
                                 {"raycast_step_mm", o.rayCastStep_mm}};
  for (const auto& item : json["options"].items()) options[item.key()] = item.value();
  json["options"] = std::move(options);
  json["transgraph"] = std::move(transgraph);
  for (auto& item : metal.items()) json[item.key()] = std::move(item.value());
  if (error) {
    json["error_vs_truth"] = {{"initial_mean_surface_mm", error->initialMean_mm},
                              {"final_mean_surface_mm", error->finalMean_mm},
                              {"final_max_surface_mm", error->finalMax_mm}};
  }
  return json;
}

/// Prints one line per stage, the summary line and the error against the truth.
void printResult(const Options& o, const RegistrationResult& r, const std::optional<TruthError>& error) {
  for (const StageReport& s : r.stages) {
    const std::string startNote = stageStartNote(s);
    fmt::print("stage {:<16} {:>4} level {} {:<7} {:7.2f} s (cpu {:6.2f} s) {:7} DRRs  similarity {:.4f} -> {:.4f}{}{}{}\n",
               s.name, RegistrationSchedule::metricName(s.metric), s.level, RegistrationSchedule::searchName(s.search),
               s.seconds, s.cpuSeconds, s.drrs, s.startSimilarity, s.similarity,
               startNote.empty() ? "" : fmt::format("  ({})", startNote),
               s.fallbackRays ? fmt::format("  ({} rays outside the Transgraph, exact)", s.fallbackRays) : "",
               s.cancelled ? " (cancelled)" : "");
  }
  fmt::print("{} in {:.2f} s, {} DRRs ({} method){}\n", r.cancelled ? "cancelled" : "registered", r.totalSeconds,
             r.totalDrrs, r.drrMethod, o.out.empty() ? "" : fmt::format("; wrote {}", o.out));
  if (error) {
    fmt::print("pose error vs truth: mean bone-surface distance {:.3f} mm -> {:.3f} mm (max {:.3f} mm)\n",
               error->initialMean_mm, error->finalMean_mm, error->finalMax_mm);
  }
}

/// --igtl: the live link to an OpenIGTLink server (3D Slicer); does nothing without --igtl. Failures before the
/// final pose are warnings: the registration and its result files never depend on the link.
class SlicerLink {
 public:
  /// Checks --igtl and --igtl-device; fails naming the flag.
  static Result<SlicerLink> fromOptions(const Options& o) {
    SlicerLink link;
    if (o.igtl.empty()) return link;
    auto endpoint = IgtlTransformSender::parseEndpoint(o.igtl);
    if (!endpoint) return fail("--igtl: " + endpoint.error());
    if (Status name = IgtlTransformSender::checkDeviceName(o.igtlDevice); !name) {
      return fail("--igtl-device: " + name.error());
    }
    link.m_sender = std::make_shared<IgtlTransformSender>(endpoint.value(), o.igtlDevice);
    return link;
  }

  /// Connects now, so that a missing server is reported before the registration starts (a warning).
  void connectEarly() {
    if (!m_sender) return;
    if (Status connected = m_sender->connect(); !connected) {
      printWarnings({"--igtl: " + connected.error() + "; registering anyway, the pose is sent when it is ready"});
    }
  }

  /// --igtl-progress: sends a stage's final pose; a failure is a warning.
  void sendStage(const StageReport& stage) {
    if (!m_sender) return;
    if (Status sent = m_sender->send(stage.T_world_from_ct); !sent) {
      printWarnings({fmt::format("--igtl-progress: the pose after stage '{}' was not sent: {}", stage.name,
                                 sent.error())});
    }
  }

  /// Sends the registered pose; returns 0, or kExitSendFailed with an error naming --igtl and the kept result.
  int sendFinal(const Eigen::Isometry3d& T_world_from_ct, const Options& o) {
    if (!m_sender) return 0;
    if (Status sent = m_sender->send(T_world_from_ct); !sent) {
      std::vector<std::string> kept;
      for (const std::string& file : {o.out, o.tfm}) {
        if (!file.empty()) kept.push_back(file);
      }
      reportError(fmt::format("--igtl: the registered pose was not sent: {}; {}", sent.error(),
                              kept.empty() ? std::string("the result is printed above")
                                           : fmt::format("the result is kept in {}", fmt::join(kept, " and "))));
      return kExitSendFailed;
    }
    fmt::print("sent the pose to the OpenIGTLink server at {} as TRANSFORM '{}' (RAS)\n", m_sender->endpoint().text(),
               o.igtlDevice);
    return 0;
  }

 private:
  std::shared_ptr<IgtlTransformSender> m_sender;
};

/// Writes the result files: RESULT.json (--out), the ITK transform (--tfm) and the scalar results
/// (--returnparameterfile).
Status writeResults(const Options& o, const RegistrationResult& r, const nlohmann::ordered_json& json) {
  if (!o.out.empty()) {
    if (Status written = JsonDocument::write(json, o.out); !written) return written;
  }
  if (!o.tfm.empty()) {
    if (Status written = ItkTransformFile::write(r.T_world_from_ct, o.tfm); !written) return fail("--tfm: " + written.error());
  }
  if (!o.returnParameterFile.empty()) {
    const double finalSimilarity = r.stages.empty() ? 0.0 : r.stages.back().similarity;
    return writeReturnParameters(o.returnParameterFile, {{"finalSimilarity", fmt::format("{:.6f}", finalSimilarity)},
                                                         {"registrationSeconds", fmt::format("{:.3f}", r.totalSeconds)},
                                                         {"drrCount", std::to_string(r.totalDrrs)}});
  }
  return Ok{};
}

int runRegister(const Options& o) {
  auto link = SlicerLink::fromOptions(o);
  if (!link) return reportError(link.error());
  auto inputs = readInputs(o);
  if (!inputs) return reportError(inputs.error());
  const Inputs& in = inputs.value();
  const RegistrationCaseOptions caseOptions = caseOptionsFor(o, in);
  const InterruptGuard interrupt;  // Ctrl-C cancels the table builds and the registration
  auto registrationCase = prepareCase(o, in, caseOptions, InterruptGuard::cancelFlag());
  if (!registrationCase) return reportError(registrationCase.error());
  nlohmann::ordered_json transgraph = transgraphReport(registrationCase.value());
  auto metal = metalReport(o, registrationCase.value(), in.initial.T_world_from_ct);
  if (!metal) return reportError(metal.error());
  if (Status written = writeMasks(o, registrationCase.value()); !written) return reportError(written.error());

  link.value().connectEarly();
  RegistrationStageCallback onStageEnd;
  if (o.igtlProgress) onStageEnd = [&link](const StageReport& stage) { link.value().sendStage(stage); };
  auto result = runRegistration(o, in, registrationCase.value(), InterruptGuard::cancelFlag(), onStageEnd);
  if (!result) return reportError(result.error());
  const RegistrationResult& r = result.value();
  const bool reviewed =
      std::any_of(r.stages.begin(), r.stages.end(), [](const StageReport& s) { return s.metalPiecesGivenBack > 0; });
  if (reviewed || metal.value().contains("metal_fraction_covered")) {  // the mask, or the rays the CT covers, moved
    metal = metalReport(o, registrationCase.value(), r.T_world_from_ct,
                        reviewed ? " after the metal review" : " at the final pose");
    if (!metal) return reportError(metal.error());
  }
  if (reviewed) {
    if (Status written = writeMasks(o, registrationCase.value()); !written) return reportError(written.error());
  }
  if (Status written = writeOverlays(o, in, caseOptions.boneThreshold_hu, r); !written) {
    return reportError(written.error());
  }
  const std::optional<TruthError> error = truthError(in, registrationCase.value(), r);
  const Status written =
      writeResults(o, r, resultJson(o, r, in.initial.source, std::move(transgraph), std::move(metal).value(), error));
  if (!written) return reportError(written.error());
  if (!o.dicomReg.empty()) {
    auto registration = RegistrationDicomExport::write(in.ct, in.views, r, o.dicomReg);
    if (!registration) return reportError("--dicom-reg: " + registration.error());
    printWarnings(registration.warnings());
  }
  printResult(o, r, error);
  if (!o.dicomReg.empty()) fmt::print("wrote DICOM registration {}\n", o.dicomReg);
  return link.value().sendFinal(r.T_world_from_ct, o);
}

}  // namespace

void registerRegisterCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "register", "Register a CT to the X-ray views of a view file (Knaan & Joskowicz 2003 pipeline) from an initial "
                  "pose or landmarks; writes the pose, per-stage timings and similarities to RESULT.json");
  command->add_option("--ct", options->ct, "CT volume (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd) or DICOM series folder")
      ->required();
  command->add_option("--views", options->views, "View file (JSON) with each view's image, detector and camera")
      ->required();
  auto* init = command->add_option(
      "--init", options->init, "Initial pose file {\"T_world_from_ct\": 4x4} or ITK transform (.tfm, as 3D Slicer saves it)");
  auto* landmarks = command->add_option(
      "--landmarks", options->landmarks,
      "Landmark pair file {\"ct\": \"points.mrk.json\", \"image\": \"clicks.json\", \"method\": "
      "\"reprojection\"|\"triangulation\"} (paths relative to it)");
  init->excludes(landmarks);
  command->add_option("--preset", options->preset, "Schedule: 'clinical', 'accurate' (every valid pixel in the last stage), 'paper' (the paper's), 'fast' or a preset JSON file")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the random searches")->capture_default_str();
  command->add_option("--method", options->method,
                      "DRR method: siddon (exact), raycast (trilinear) or transgraph (one precomputed ray table per "
                      "view around the initial pose, cached on disk; rays outside it are exact)")
      ->capture_default_str();
  auto* rayCastStep = command->add_option("--raycast-step-mm", options->rayCastStep_mm,
                      "raycast method: sampling step along each ray in mm; 0 = half the smallest voxel spacing")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_option("--transgraph-cache", options->transgraphCache,
                      "Folder of the transgraph table cache (default: $XDG_CACHE_HOME/fluoroct/transgraph or "
                      "~/.cache/fluoroct/transgraph); 'none' disables the cache");
  command->add_option("--transgraph-spacing-mm", options->transgraphSpacing_mm,
                      "Transgraph ray sampling step on the planes, mm (offsets 3x; rays grow as spacing^-4)")
      ->check(positiveNumber())
      ->capture_default_str();
  command->add_option("--out", options->out, "Result JSON file (written atomically)");
  command->add_option("--tfm", options->tfm,
                      "Also write the registered pose as an ITK transform (.tfm) that 3D Slicer opens (the "
                      "transform to put the CT under)");
  command->add_option("--returnparameterfile", options->returnParameterFile,
                      "Write the scalar results (finalSimilarity, registrationSeconds, drrCount) as 'name = value' "
                      "lines, as 3D Slicer's CLI modules do");
  auto* igtl = command->add_option("--igtl", options->igtl,
                      "Send the registered pose to an OpenIGTLink server HOST:PORT (3D Slicer's OpenIGTLinkIF, port "
                      "18944) as a TRANSFORM in RAS, after the result files are written; connect and send time out "
                      "after 3 s; exit status 3 if it was not sent");
  command->add_option("--igtl-device", options->igtlDevice, "Device name of the TRANSFORM (1-20 characters)")
      ->capture_default_str()
      ->needs(igtl);
  command->add_flag("--igtl-progress", options->igtlProgress, "With --igtl: also send the pose after each stage")
      ->needs(igtl);
  command->add_option("--dicom-reg", options->dicomReg,
                      "Also write the final pose as a DICOM Spatial Registration object (REG, .dcm) referring to the "
                      "CT series and the DICOM X-rays (written atomically)");
  command->add_option("--truth", options->truth,
                      "Known true pose file (simulated cases): report the mean/max bone-surface distance to it");
  command->add_option("--overlays", options->overlays,
                      "Folder for one PNG per view (<view>.png) with the bone outlines at the initial (red) and final "
                      "(green) pose over the X-ray");
  command->add_flag("--progress", options->progress, "Show a live progress bar on stderr");
  command->add_flag("--no-fov", options->noFieldOfView,
                    "Skip the field-of-view (collimator) detection (use every pixel but the margin band)");
  command->add_flag("--no-metal-mask", options->noMetalMask,
                    "Compare metal shadows (K-wires, screws, plates) too instead of excluding them");
  command->add_option("--metal-min-excess", options->metalMinExcess,
                      "Line integral a narrow shadow must add over its surroundings to count as metal (-ln of the "
                      "fraction of signal it passes; physical, log-linear detector images)")
      ->capture_default_str();
  addCutFaceMarginOption(*command, options->cutFaceMargin_mm);
  addBoneContrastOption(*command, options->boneContrast);
  command->add_option("--masks", options->masks,
                      "Folder for one PNG per view (<view>_mask.png): white pixels are compared with the DRR, black "
                      "ones excluded (field border, margin, calibration spheres, metal; rewritten after a metal review)");
  command->add_flag("--no-rois", options->ablation.noDynamicRois, "Ablation: every valid pixel instead of dynamic ROIs");
  command->add_flag("--no-pyramid", options->ablation.noPyramid, "Ablation: full resolution in every stage");
  command->add_flag("--ncc-only", options->ablation.nccOnly, "Ablation: NCC in every stage (no VLNC)");
  command->add_flag("--local-only", options->ablation.localOnly, "Ablation: local simplex instead of global search");
  command->add_flag("--cmaes", options->ablation.cmaesForGenetic, "CMA-ES instead of the genetic search");
  command->add_flag("--no-transgraph", options->ablation.noTransgraph,
                    "Ablation: exact (Siddon) DRRs instead of the Transgraph tables (no table is built)");
  command->add_flag("--no-ct-pyramid", options->ablation.noCtPyramid,
                    "Exact DRRs of coarse pyramid levels integrate the full CT instead of one box-averaged to the "
                    "level's pixel size at the bone");
  addModuleXmlFlag(command, registerModuleXml());
  command->callback([&action, options, rayCastStep] {
    options->rayCastStepGiven = rayCastStep->count() > 0;
    action = [options] { return runRegister(*options); };
  });
}

}  // namespace fct::cli
