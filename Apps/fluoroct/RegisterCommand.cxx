// fluoroct register: registers a CT to the X-ray views of a view file (Registration, a preset schedule) from an
// initial pose given as a pose file or estimated from landmarks; writes RESULT.json.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Base/JsonDocument.h"
#include "CliSupport.h"
#include "Evaluation/ContourOverlay.h"
#include "InitialPose/LandmarkPoseEstimator.h"
#include "IO/Project/LandmarkPairFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/CtLoader.h"
#include "IO/Xray/ImageFileWriter.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationResultJson.h"
#include "Registration/RegistrationViewLoader.h"

namespace fct::cli {

namespace {

namespace fs = std::filesystem;

struct Options {
  std::string ct;
  std::string views;
  std::string init;
  std::string landmarks;
  std::string preset = "paper";
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
  std::string masks;  ///< optional folder for each view's full-resolution validity mask (PNG)
  RegistrationAblation ablation;
};

std::atomic<bool> g_cancel{false};
extern "C" void onInterrupt(int) { g_cancel.store(true); }

/// Writes a validity mask as an 8-bit-range PNG (white = compared, black = excluded), creating the folder.
Status writeMaskPng(const ValidMask& mask, const fs::path& path) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  if (ec) return fail(fmt::format("cannot create the mask folder '{}': {}", path.parent_path().string(), ec.message()));
  FloatImage image{mask.cols, mask.rows, std::vector<float>(mask.valid.begin(), mask.valid.end())};
  return ImageFileWriter::writePng16(image, path, 0.0f, 1.0f);
}

/// The initial pose from --init or --landmarks, and a JSON description of where it came from.
Result<std::pair<Eigen::Isometry3d, nlohmann::ordered_json>> initialPose(const Options& o,
                                                                         const std::vector<RegistrationView>& views) {
  if (!o.init.empty()) {
    auto pose = PoseFile::read(o.init);
    if (!pose) return fail("--init: " + pose.error());
    return std::make_pair(pose.value(), nlohmann::ordered_json{{"source", "pose file"}, {"path", o.init}});
  }
  auto pairs = LandmarkPairFile::read(o.landmarks);
  if (!pairs) return fail("--landmarks: " + pairs.error());
  for (const std::string& warning : pairs.warnings()) fmt::print(stderr, "warning: {}\n", warning);
  const LandmarkPairSet& set = pairs.value();
  std::map<std::string, Camera> cameras;
  for (const RegistrationView& view : views) cameras.emplace(view.name, view.camera);
  for (const auto& [viewName, clicks] : set.landmarks.imageByView) {
    if (!cameras.count(viewName)) {
      std::vector<std::string> names;
      for (const RegistrationView& view : views) names.push_back(view.name);
      return fail(fmt::format("{}: landmarks are clicked in view '{}', which the view file does not have (views: {}); "
                              "the landmark and view files must name the same views",
                              set.imageFile.string(), viewName, fmt::join(names, ", ")));
    }
  }
  auto estimate = set.method == LandmarkPoseMethod::Triangulation
                      ? LandmarkPoseEstimator::fromTriangulation(set.landmarks, cameras)
                      : LandmarkPoseEstimator::fromReprojection(set.landmarks, cameras);
  if (!estimate) return fail("initial pose from landmarks: " + estimate.error());
  const LandmarkPoseEstimate& e = estimate.value();
  nlohmann::ordered_json residuals = nlohmann::ordered_json::array();
  for (const LandmarkResidual& r : e.residuals) {
    nlohmann::ordered_json perView = nlohmann::ordered_json::object();
    for (const auto& [viewName, px] : r.reprojection_px) perView[viewName] = px;
    nlohmann::ordered_json entry{{"name", r.name}, {"reprojection_px", perView}};
    if (std::isfinite(r.distance_mm)) entry["distance_mm"] = r.distance_mm;
    residuals.push_back(std::move(entry));
  }
  nlohmann::ordered_json source{{"source", "landmarks"},
                                {"path", o.landmarks},
                                {"method", e.method},
                                {"rms_reprojection_px", e.rmsReprojection_px}};
  if (std::isfinite(e.rms3d_mm)) source["rms_3d_mm"] = e.rms3d_mm;
  source["residuals"] = std::move(residuals);
  return std::make_pair(e.T_world_from_ct, std::move(source));
}

/// RESULT.json: the result object (RegistrationResultJson) with where the initial pose came from, the Transgraph
/// tables and the command's options added.
nlohmann::ordered_json resultJson(const RegistrationResult& r, const Options& o, nlohmann::ordered_json initial,
                                  nlohmann::ordered_json transgraph) {
  nlohmann::ordered_json json = RegistrationResultJson::write(r);
  for (const auto& item : json["initial_pose"].items()) initial[item.key()] = item.value();
  json["initial_pose"] = std::move(initial);
  nlohmann::ordered_json options{{"ct", o.ct},
                                 {"views", o.views},
                                 {"preset", o.preset},
                                 {"seed", o.seed},
                                 {"ablation", o.ablation.activeNames()},
                                 {"field_of_view_detection", !o.noFieldOfView},
                                 {"metal_mask", !o.noMetalMask},
                                 {"metal_min_excess", o.metalMinExcess}};
  for (const auto& item : json["options"].items()) options[item.key()] = item.value();
  json["options"] = std::move(options);
  json["transgraph"] = std::move(transgraph);
  return json;
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

int runRegister(const Options& o) {
  if (o.init.empty() == o.landmarks.empty()) {
    return reportError("give the initial pose with exactly one of --init POSE.json or --landmarks LM.json");
  }
  auto method = DrrRendererFactory::parseMethod(o.method);
  if (!method) return reportError(method.error());
  auto schedule = RegistrationSchedule::resolve(o.preset);
  if (!schedule) return reportError(schedule.error());
  auto loadedViews = RegistrationViewLoader::load(o.views);
  if (!loadedViews) return reportError("--views: " + loadedViews.error());
  for (const std::string& warning : loadedViews.warnings()) fmt::print(stderr, "warning: {}\n", warning);
  const std::vector<RegistrationView>& views = loadedViews.value();
  auto initial = initialPose(o, views);
  if (!initial) return reportError(initial.error());
  std::optional<Eigen::Isometry3d> T_truth;
  if (!o.truth.empty()) {
    auto truth = PoseFile::read(o.truth);
    if (!truth) return reportError(truth.error());
    T_truth = truth.value();
  }
  auto ct = CtLoader::load(o.ct);
  if (!ct) return reportError(ct.error());
  for (const std::string& warning : ct.warnings()) fmt::print(stderr, "warning: {}\n", warning);

  RegistrationCaseOptions caseOptions;
  caseOptions.drr.method = method.value();
  caseOptions.drr.transgraph.spacing_mm = o.transgraphSpacing_mm;
  if (o.transgraphCache == "none") {
    caseOptions.drr.transgraphCacheFolder = std::nullopt;
  } else {
    caseOptions.drr.transgraphCacheFolder = fs::path(o.transgraphCache);
  }
  // The tables are built around the initial pose, unless the Transgraph is switched off for this run.
  if (!o.ablation.noTransgraph) caseOptions.T_expected_world_from_ct = initial.value().first;
  caseOptions.preparation.detectFieldOfView = !o.noFieldOfView;
  caseOptions.preparation.excludeMetal = !o.noMetalMask;
  caseOptions.preparation.metal.minExcess = o.metalMinExcess;
  g_cancel = false;
  const auto previousHandler = std::signal(SIGINT, onInterrupt);
  ProgressMonitor::Callback onTableProgress;
  if (o.progress) {
    onTableProgress = [](const ProgressUpdate& u) {
      fmt::print(stderr, "\r{}: {:3.0f}% {:<40}", u.stage, 100.0 * u.fraction, u.message);
    };
  }
  auto registrationCase =
      RegistrationCase::create(ct.value(), views, caseOptions, ProgressMonitor(onTableProgress, &g_cancel));
  if (onTableProgress && caseOptions.drr.method == DrrMethod::Transgraph) fmt::print(stderr, "\n");
  if (!registrationCase) {
    std::signal(SIGINT, previousHandler);
    return reportError(registrationCase.error());
  }
  for (const std::string& warning : registrationCase.warnings()) fmt::print(stderr, "warning: {}\n", warning);
  nlohmann::ordered_json transgraphJson = nullptr;
  if (registrationCase.value().transgraph(0)) {
    transgraphJson = {{"setup_seconds", registrationCase.value().viewRendererSetupSeconds()}, {"views", nlohmann::ordered_json::object()}};
    for (std::size_t v = 0; v < registrationCase.value().viewCount(); ++v) {
      const Transgraph& table = registrationCase.value().transgraph(v)->transgraph();
      transgraphJson["views"][registrationCase.value().viewName(v)] = {
          {"rays", table.rayCount()},
          {"memory_bytes", table.memory_bytes()},
          {"seconds", table.buildInfo().build_s},
          {"loaded_from_cache", table.buildInfo().loadedFromCache},
          {"cache_file", table.buildInfo().cacheFile.string()}};
      fmt::print("transgraph {:<10} {:6.1f} M rays, {:5.0f} MB, {} in {:.2f} s\n", registrationCase.value().viewName(v),
                 table.rayCount() / 1e6, table.memory_bytes() / 1e6,
                 table.buildInfo().loadedFromCache ? "loaded from the cache" : "built", table.buildInfo().build_s);
    }
  }
  nlohmann::ordered_json metalFractions = nlohmann::ordered_json::object();
  for (std::size_t v = 0; v < registrationCase.value().viewCount(); ++v) {
    const PreparedXray& prepared = registrationCase.value().prepared(v);
    metalFractions[registrationCase.value().viewName(v)] = prepared.metalFraction;
    if (!o.noMetalMask) {
      fmt::print("view {}: metal mask excludes {:.2f} % of the field\n", registrationCase.value().viewName(v),
                 100.0 * prepared.metalFraction);
    }
    if (!o.masks.empty()) {
      const Status written = writeMaskPng(prepared.pyramid.level(0).mask,
                                          fs::path(o.masks) / (registrationCase.value().viewName(v) + "_mask.png"));
      if (!written) return reportError(written.error());
    }
  }

  RegistrationOptions options;
  options.schedule = schedule.value();
  options.ablation = o.ablation;
  options.seed = o.seed;
  ProgressBar bar;
  RegistrationProgressCallback onProgress;
  if (o.progress) onProgress = [&bar](const RegistrationProgress& p) { bar.update(p); };
  auto result = Registration::run(registrationCase.value(), initial.value().first, options, onProgress, &g_cancel);
  std::signal(SIGINT, previousHandler);
  bar.finish();
  if (!result) return reportError(result.error());
  const RegistrationResult& r = result.value();

  if (!o.overlays.empty()) {
    auto overlay = ContourOverlay::create(ct.value(), caseOptions.boneThreshold_hu);
    if (!overlay) return reportError("overlays: " + overlay.error());
    std::error_code ec;
    fs::create_directories(o.overlays, ec);
    if (ec) return reportError(fmt::format("cannot create the overlay folder '{}': {}", o.overlays, ec.message()));
    for (const RegistrationView& view : views) {
      const Status written = overlay.value().writeOverlayPng(view.xray, view.camera, r.T_initial, r.T_world_from_ct,
                                                             fs::path(o.overlays) / (view.name + ".png"));
      if (!written) return reportError(fmt::format("overlay of view '{}': {}", view.name, written.error()));
    }
  }
  nlohmann::ordered_json json = resultJson(r, o, initial.value().second, std::move(transgraphJson));
  if (!o.noMetalMask) json["metal_fraction"] = std::move(metalFractions);
  std::string errorLine;
  if (T_truth && registrationCase.value().bone()) {
    // The pose error as the paper measures it: mean (max) distance of the bone surface points, final vs. truth.
    const BoneSurface& bone = *registrationCase.value().bone();
    const double initialMean = bone.meanDistance_mm(r.T_initial, *T_truth);
    const double finalMean = bone.meanDistance_mm(r.T_world_from_ct, *T_truth);
    const double finalMax = bone.maxDistance_mm(r.T_world_from_ct, *T_truth);
    json["error_vs_truth"] = {{"initial_mean_surface_mm", initialMean},
                              {"final_mean_surface_mm", finalMean},
                              {"final_max_surface_mm", finalMax}};
    errorLine = fmt::format("pose error vs truth: mean bone-surface distance {:.3f} mm -> {:.3f} mm (max {:.3f} mm)\n",
                            initialMean, finalMean, finalMax);
  }
  if (!o.out.empty()) {
    const Status written = JsonDocument::write(json, o.out);
    if (!written) return reportError(written.error());
  }
  for (const StageReport& s : r.stages) {
    fmt::print("stage {:<16} {:>4} level {} {:<7} {:7.2f} s {:7} DRRs  similarity {:.4f} -> {:.4f}{}{}\n", s.name,
               RegistrationSchedule::metricName(s.metric), s.level, RegistrationSchedule::searchName(s.search), s.seconds,
               s.drrs, s.startSimilarity, s.similarity,
               s.fallbackRays ? fmt::format("  ({} rays outside the Transgraph, exact)", s.fallbackRays) : "",
               s.cancelled ? " (cancelled)" : "");
  }
  fmt::print("{} in {:.2f} s, {} DRRs ({} method){}\n", r.cancelled ? "cancelled" : "registered", r.totalSeconds,
             r.totalDrrs, r.drrMethod, o.out.empty() ? "" : fmt::format("; wrote {}", o.out));
  fmt::print("{}", errorLine);
  return 0;
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
  auto* init = command->add_option("--init", options->init, "Initial pose file {\"T_world_from_ct\": 4x4}");
  auto* landmarks = command->add_option(
      "--landmarks", options->landmarks,
      "Landmark pair file {\"ct\": \"points.mrk.json\", \"image\": \"clicks.json\", \"method\": "
      "\"reprojection\"|\"triangulation\"} (paths relative to it)");
  init->excludes(landmarks);
  command->add_option("--preset", options->preset, "Schedule: 'paper', 'fast' or a preset JSON file")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the random searches")->capture_default_str();
  command->add_option("--method", options->method,
                      "DRR method: siddon (exact), raycast (trilinear) or transgraph (one precomputed ray table per "
                      "view around the initial pose, cached on disk; rays outside it are exact)")
      ->capture_default_str();
  command->add_option("--transgraph-cache", options->transgraphCache,
                      "Folder of the transgraph table cache (default: $XDG_CACHE_HOME/fluoroct/transgraph or "
                      "~/.cache/fluoroct/transgraph); 'none' disables the cache");
  command->add_option("--transgraph-spacing-mm", options->transgraphSpacing_mm,
                      "Transgraph ray sampling step on the planes, mm (offsets 3x; rays grow as spacing^-4)")
      ->check(positiveNumber())
      ->capture_default_str();
  command->add_option("--out", options->out, "Result JSON file (written atomically)");
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
  command->add_option("--masks", options->masks,
                      "Folder for one PNG per view (<view>_mask.png): white pixels are compared with the DRR, black "
                      "ones excluded (field border, margin, calibration spheres, metal)");
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
  command->callback([&action, options] { action = [options] { return runRegister(*options); }; });
}

}  // namespace fct::cli
