#include "Widgets/StudioSession.h"

#include <fmt/core.h>

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <string_view>
#include <utility>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"
#include "Base/NameTable.h"
#include "IO/Project/PoseFile.h"
#include "Registration/RegistrationResultJson.h"

namespace fct {

namespace {

namespace fs = std::filesystem;
using ordered_json = nlohmann::ordered_json;

constexpr const char* kFormat = "fluoroct-studio-session";
/// Version 3 keeps the result history ("results", "current_result") and the X-ray windows ("display"); versions 2 (one
/// "result", a RegistrationResultJson object) and 1 (one "result" in its own keys) are read too.
constexpr int kVersion = 3;

/// A path as written into a file in `folder`: relative when inside it, else absolute. Empty folder: absolute.
std::string storedPath(const fs::path& path, const fs::path& folder) {
  if (path.empty()) return {};
  const fs::path absolute = fs::absolute(path).lexically_normal();
  if (folder.empty()) return absolute.string();
  const fs::path relative = absolute.lexically_relative(fs::absolute(folder).lexically_normal());
  if (relative.empty() || *relative.begin() == "..") return absolute.string();
  return relative.string();
}

/// A stored path read back: relative paths are taken relative to the session's folder.
fs::path resolvedPath(const std::string& stored, const fs::path& folder) {
  const fs::path path(stored);
  return path.is_absolute() ? path : (folder / path).lexically_normal();
}

/// The session file's names of the user's verdicts.
constexpr NameTable<ResultVerdict, 3> kVerdicts{{{"accepted", ResultVerdict::Accepted},
                                                 {"rejected", ResultVerdict::Rejected},
                                                 {"undecided", ResultVerdict::Undecided}}};

ordered_json pose(const Eigen::Isometry3d& T) { return JsonDocument::array(T.matrix()); }

/// The result object shared with RESULT.json, with the user's verdict added.
ordered_json resultJson(const RegistrationResult& r, ResultVerdict verdict) {
  ordered_json json = RegistrationResultJson::write(r);
  json["verdict"] = nameOf(verdict, kVerdicts);
  return json;
}

/// The session document; paths relative to `folder` (absolute if empty).
ordered_json sessionJson(const StudioDocument& d, const fs::path& folder) {
  ordered_json json{{"format", kFormat}, {"version", kVersion}};
  if (d.ct()) {
    ordered_json ct{{"path", storedPath(d.ctPath(), folder)}};
    if (!d.ctSeriesUid().empty()) ct["series_uid"] = d.ctSeriesUid();
    json["ct"] = std::move(ct);
  }
  if (!d.viewFilePath().empty()) {
    json["views"] = {{"view_file", storedPath(d.viewFilePath(), folder)}};
  } else if (!d.views().empty()) {
    ordered_json files = ordered_json::array();
    for (const RegistrationView& view : d.views()) {
      files.push_back({{"name", view.name}, {"path", storedPath(view.xray.sourcePath, folder)}});
    }
    json["views"] = {{"xray_files", std::move(files)}};
  }
  ordered_json ctLandmarks = ordered_json::array();
  for (const CtLandmark& l : d.landmarks().ct) {
    ctLandmarks.push_back({{"name", l.name}, {"p_ct_mm", JsonDocument::array(l.p_ct_mm)}});
  }
  ordered_json imageLandmarks = ordered_json::object();
  for (const auto& [viewName, points] : d.landmarks().imageByView) {
    ordered_json list = ordered_json::array();
    for (const ImageLandmark& l : points) list.push_back({{"name", l.name}, {"uv_px", JsonDocument::array(l.uv_px)}});
    imageLandmarks[viewName] = std::move(list);
  }
  json["landmarks"] = {{"ct", std::move(ctLandmarks)}, {"image", std::move(imageLandmarks)}};
  if (d.initialPose()) {
    json["initial_pose"] = {{"T_world_from_ct", pose(*d.initialPose())},
                            {"source", d.initialPoseSource().toStdString()}};
  }
  const RoiParameters& roi = d.roiParameters();
  json["roi"] = {{"window_size", roi.windowSize},
                 {"use_threshold", roi.useThreshold},
                 {"target_fraction", roi.targetFraction},
                 {"variance_threshold", roi.varianceThreshold},
                 {"margin_px", roi.margin_px},
                 {"detect_field_of_view", roi.detectFieldOfView},
                 {"detect_spheres", roi.detectSpheres},
                 {"sphere_margin_px", roi.sphereMargin_px},
                 {"cut_face_margin_mm", roi.cutFaceMargin_mm}};
  const StudioRegistrationOptions& options = d.registrationOptions();
  json["registration"] = {{"preset", options.preset},
                          {"seed", options.seed},
                          {"drr_method", options.drrMethod},
                          {"bone_contrast", options.boneContrast}};
  if (!d.results().empty()) {
    ordered_json results = ordered_json::array();
    for (const StudioResult& entry : d.results()) results.push_back(resultJson(entry.result, entry.verdict));
    json["results"] = std::move(results);
    json["current_result"] = d.currentResultIndex();
  }
  if (!d.xrayWindows().empty()) {
    ordered_json windows = ordered_json::object();
    for (const auto& [view, w] : d.xrayWindows()) windows[view] = {{"window", w.window}, {"level", w.level}};
    json["display"] = {{"xray_windows", std::move(windows)}};
  }
  if (d.truthPose()) json["truth_pose"] = {{"T_world_from_ct", pose(*d.truthPose())}};
  return json;
}

/// Everything a session file holds, with the CT and X-rays loaded.
struct SessionContent {
  std::optional<LoadedCt> ct;
  std::optional<LoadedViews> views;
  Landmarks landmarks;
  std::optional<Eigen::Isometry3d> initialPose;
  QString initialPoseSource;
  RoiParameters roi;
  StudioRegistrationOptions options;
  std::vector<StudioResult> results;
  int currentResult = -1;
  std::map<std::string, DisplayWindow> xrayWindows;
  std::optional<Eigen::Isometry3d> truthPose;
  fs::path autosaveOf;
  bool isAutosave = false;
};

/// The session file being read: its name for messages, and the folder its relative paths start from.
struct SessionFile {
  std::string where;
  fs::path folder;
};

/// Checks "format" and "version" (1 up to the version this program writes). Fails naming the file and key for another
/// format or a newer version.
Status checkHeader(JsonReader& reader) {
  reader.formatVersion(kFormat, "Studio session file", kVersion);
  if (!reader.ok()) return fail(reader.error());
  return Ok{};
}

/// Marks an autosave file (it has "autosave_of") and records the session file it belongs to (a non-string: none).
void readAutosaveOwner(const JsonReader& reader, SessionContent& content) {
  if (!reader.has("autosave_of")) return;
  content.isAutosave = true;
  if (const nlohmann::json* owner = reader.find("autosave_of"); owner->is_string()) {
    content.autosaveOf = owner->get<std::string>();
  }
}

/// The message for an input of the session that cannot be loaded: which one, why, and how to bring it back.
std::string unloadableInput(const SessionFile& file, const char* what, const char* restore, const char* key,
                            const std::string& why) {
  return fmt::format("{}: the session's {} cannot be loaded ({}); put {} back or edit {} in the session file",
                     file.where, what, why, restore, key);
}

/// "ct": loads the CT at its path (and series). Fails naming the key, or telling how to bring the CT back.
Status readCtSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader ct(section, file.where + ": ct");
  const std::string ctPath = ct.string("path");
  DicomSeriesReadOptions options;
  if (ct.has("series_uid")) options.seriesInstanceUid = ct.string("series_uid");
  if (!ct.ok()) return fail(ct.error());
  auto loaded = StudioDocument::readCt(resolvedPath(ctPath, file.folder), options);
  if (!loaded) return fail(unloadableInput(file, "CT", "the CT", "ct.path", loaded.error()));
  content.ct = std::move(loaded).value();
  return Ok{};
}

/// "views.xray_files": loads each listed X-ray under its stored name. Fails naming the entry or the view.
Result<LoadedViews> readXrayFiles(const nlohmann::json& files, const SessionFile& file) {
  LoadedViews loaded;
  for (std::size_t i = 0; i < files.size(); ++i) {
    JsonReader entry(files[i], fmt::format("{}: views.xray_files[{}]", file.where, i));
    const std::string name = entry.string("name");
    const std::string xrayPath = entry.string("path");
    if (!entry.ok()) return fail(entry.error());
    auto view = StudioDocument::readXrayFile(resolvedPath(xrayPath, file.folder));
    if (!view) return fail(fmt::format("{}: view '{}': {}", file.where, name, view.error()));
    view.value().name = name;
    loaded.views.push_back(std::move(view).value());
  }
  return loaded;
}

/// "views": loads the view file, or else the listed X-ray files. Fails naming the key or the file to bring back.
Status readViewsSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader views(section, file.where + ": views");
  if (views.has("view_file")) {
    const std::string viewFile = views.string("view_file");
    if (!views.ok()) return fail(views.error());
    auto loaded = StudioDocument::readViews(resolvedPath(viewFile, file.folder));
    if (!loaded) return fail(unloadableInput(file, "views", "the files", "views.view_file", loaded.error()));
    content.views = std::move(loaded).value();
    return Ok{};
  }
  if (const nlohmann::json* files = views.find("xray_files"); files && files->is_array()) {
    auto loaded = readXrayFiles(*files, file);
    if (!loaded) return fail(loaded.error());
    content.views = std::move(loaded).value();
    return Ok{};
  }
  return fail(file.where + ": views needs \"view_file\" or \"xray_files\"");
}

/// "landmarks.ct": the CT landmarks (p_ct_mm, LPS mm), appended to `landmarks`. Fails naming the entry.
Status readCtLandmarks(const nlohmann::json& list, const SessionFile& file, Landmarks& landmarks) {
  for (std::size_t i = 0; i < list.size(); ++i) {
    JsonReader l(list[i], fmt::format("{}: landmarks.ct[{}]", file.where, i));
    CtLandmark landmark{l.string("name"), l.vector("p_ct_mm", 3)};
    if (!l.ok()) return fail(l.error());
    landmarks.ct.push_back(std::move(landmark));
  }
  return Ok{};
}

/// "landmarks.image": each view's image landmarks (uv_px), added to `landmarks`. Fails naming the view or entry.
Status readImageLandmarks(const nlohmann::json& byView, const SessionFile& file, Landmarks& landmarks) {
  for (const auto& [viewName, points] : byView.items()) {
    if (!points.is_array()) return fail(fmt::format("{}: landmarks.image.{} must be an array", file.where, viewName));
    std::vector<ImageLandmark>& list = landmarks.imageByView[viewName];
    for (std::size_t i = 0; i < points.size(); ++i) {
      JsonReader l(points[i], fmt::format("{}: landmarks.image.{}[{}]", file.where, viewName, i));
      ImageLandmark landmark{l.string("name"), l.vector("uv_px", 2)};
      if (!l.ok()) return fail(l.error());
      list.push_back(std::move(landmark));
    }
  }
  return Ok{};
}

/// "landmarks": the CT and image landmarks (a missing or non-list part: none). Fails naming the bad entry.
Status readLandmarksSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader landmarks(section, file.where + ": landmarks");
  if (const nlohmann::json* ct = landmarks.find("ct"); ct && ct->is_array()) {
    if (const Status read = readCtLandmarks(*ct, file, content.landmarks); !read) return read;
  }
  if (const nlohmann::json* image = landmarks.find("image"); image && image->is_object()) {
    if (const Status read = readImageLandmarks(*image, file, content.landmarks); !read) return read;
  }
  return Ok{};
}

/// "initial_pose": T_world_from_ct (LPS mm) and where it came from (a non-string source: none). Fails naming the key.
Status readInitialPoseSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader initial(section, file.where + ": initial_pose");
  content.initialPose = PoseFile::readKey(initial, "T_world_from_ct");
  if (initial.has("source")) {
    if (const nlohmann::json* source = initial.find("source"); source->is_string()) {
      content.initialPoseSource = QString::fromStdString(source->get<std::string>());
    }
  }
  if (!initial.ok()) return fail(initial.error());
  return Ok{};
}

/// "roi": the dynamic-ROI and exclusion parameters. Fails naming the key with a bad value.
Status readRoiSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader roi(section, file.where + ": roi");
  RoiParameters& r = content.roi;
  r.windowSize = roi.integer("window_size", 2);
  r.useThreshold = roi.boolean("use_threshold");
  r.targetFraction = roi.positiveNumber("target_fraction");
  r.varianceThreshold = roi.number("variance_threshold");
  r.margin_px = roi.integer("margin_px", 0);
  r.detectFieldOfView = roi.boolean("detect_field_of_view");
  r.detectSpheres = roi.boolean("detect_spheres");
  r.sphereMargin_px = roi.number("sphere_margin_px");
  // A session written before the key existed keeps the default.
  if (roi.has("cut_face_margin_mm")) r.cutFaceMargin_mm = roi.number("cut_face_margin_mm");
  if (roi.ok() && r.targetFraction > 1.0) roi.rejectKey("target_fraction", "must be in (0, 1]");
  if (roi.ok() && r.cutFaceMargin_mm > RegistrationCaseOptions::kMaxCutFaceMargin_mm) {
    roi.rejectKey("cut_face_margin_mm", fmt::format("must be at most {} mm (negative: off)",
                                                    RegistrationCaseOptions::kMaxCutFaceMargin_mm));
  }
  if (!roi.ok()) return fail(roi.error());
  return Ok{};
}

/// "registration": the preset, seed, DRR method and bone contrast. Fails naming the key with a bad value.
Status readRegistrationSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader registration(section, file.where + ": registration");
  StudioRegistrationOptions& r = content.options;
  r.preset = registration.string("preset");
  r.seed = static_cast<std::uint32_t>(registration.integer("seed", 0));
  r.drrMethod = registration.string("drr_method");
  // A session written before the key existed keeps the default.
  if (registration.has("bone_contrast")) r.boneContrast = registration.number("bone_contrast");
  if (registration.ok() && !DrrValueOptions::acceptsBoneContrast(r.boneContrast)) {
    registration.rejectKey("bone_contrast",
                           fmt::format("must be above 0 and at most {:g}", DrrValueOptions::kMaxBoneContrast));
  }
  if (!registration.ok()) return fail(registration.error());
  return Ok{};
}

/// One result (the RegistrationResultJson object, version 1 or 2) with the user's verdict beside it, read at `where`.
/// Fails naming the key with a bad value.
Result<StudioResult> readResult(const nlohmann::json& section, const std::string& where) {
  JsonReader reader(section, where);
  const ResultVerdict verdict =
      readNamed(reader, "verdict", kVerdicts, "accepted, rejected or undecided").value_or(ResultVerdict::Undecided);
  if (!reader.ok()) return fail(reader.error());
  auto result = RegistrationResultJson::read(section, where);
  if (!result) return fail(result.error());
  return StudioResult{std::move(result).value(), verdict};
}

/// "result" (session versions 1 and 2): the one result, which becomes a history of one. Fails as readResult.
Status readResultSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  auto read = readResult(section, file.where + ": result");
  if (!read) return fail(read.error());
  content.results = {std::move(read).value()};
  content.currentResult = 0;
  return Ok{};
}

/// "results" (version 3): the result history, oldest first. Fails naming the entry.
Status readResultsSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  if (!section.is_array()) return fail(file.where + ": results must be an array of results");
  content.results.clear();
  for (std::size_t i = 0; i < section.size(); ++i) {
    auto read = readResult(section[i], fmt::format("{}: results[{}]", file.where, i));
    if (!read) return fail(read.error());
    content.results.push_back(std::move(read).value());
  }
  content.currentResult = static_cast<int>(content.results.size()) - 1;
  return Ok{};
}

/// "current_result": the index into "results" of the result shown. Fails naming the key when out of range.
Status readCurrentResultSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  const int count = static_cast<int>(content.results.size());
  if (!section.is_number_integer() || section.get<int>() < 0 || section.get<int>() >= count) {
    return fail(fmt::format("{}: current_result must be an index into results (0 to {})", file.where, count - 1));
  }
  content.currentResult = section.get<int>();
  return Ok{};
}

/// "display": the X-ray windows {<view>: {window, level}}. Fails naming the view with a bad value.
Status readDisplaySection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader display(section, file.where + ": display");
  const nlohmann::json* windows = display.find("xray_windows");
  if (!windows || !windows->is_object()) return Ok{};
  for (const auto& [view, value] : windows->items()) {
    JsonReader w(value, fmt::format("{}: display.xray_windows.{}", file.where, view));
    const DisplayWindow window{w.positiveNumber("window"), w.number("level")};
    if (!w.ok()) return fail(w.error());
    content.xrayWindows[view] = window;
  }
  return Ok{};
}

/// "truth_pose": the known true T_world_from_ct (LPS mm) of a simulated case. Fails naming the key.
Status readTruthPoseSection(const nlohmann::json& section, const SessionFile& file, SessionContent& content) {
  JsonReader truth(section, file.where + ": truth_pose");
  content.truthPose = PoseFile::readKey(truth, "T_world_from_ct");
  if (!truth.ok()) return fail(truth.error());
  return Ok{};
}

/// Reads one optional section of a session file into the content.
using SectionReader = Status (*)(const nlohmann::json& section, const SessionFile& file, SessionContent& content);

/// The optional sections in the order they are read: the first one that fails ends the read.
constexpr std::array<std::pair<std::string_view, SectionReader>, 11> kSections{{
    {"ct", readCtSection},
    {"views", readViewsSection},
    {"landmarks", readLandmarksSection},
    {"initial_pose", readInitialPoseSection},
    {"roi", readRoiSection},
    {"registration", readRegistrationSection},
    {"result", readResultSection},
    {"results", readResultsSection},
    {"current_result", readCurrentResultSection},
    {"display", readDisplaySection},
    {"truth_pose", readTruthPoseSection},
}};

/// Reads a session (or autosave) file with its CT and X-rays loaded. Fails naming the file and key.
Result<SessionContent> readSession(const fs::path& path) {
  auto parsed = JsonDocument::parse(path);
  if (!parsed) return fail(parsed.error());
  const SessionFile file{path.string(), path.parent_path()};
  JsonReader reader(parsed.value(), file.where);
  if (const Status header = checkHeader(reader); !header) return fail(header.error());

  SessionContent content;
  readAutosaveOwner(reader, content);
  for (const auto& [key, read] : kSections) {
    if (!reader.has(key)) continue;
    if (const Status section = read(*reader.find(key), file, content); !section) return fail(section.error());
  }
  return content;
}

}  // namespace

Status StudioSession::save(StudioDocument& document, const fs::path& path) {
  const Status written = JsonDocument::write(sessionJson(document, path.parent_path()), path);
  if (!written) return written;
  document.setSessionPath(path);
  document.setModified(false);
  return Ok{};
}

Status StudioSession::writeAutosave(const StudioDocument& document, const fs::path& path) {
  ordered_json json = sessionJson(document, {});
  json["autosave_of"] = document.sessionPath().empty() ? std::string() : fs::absolute(document.sessionPath()).string();
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  return JsonDocument::write(json, path);
}

fs::path StudioSession::autosaveOwner(const fs::path& autosavePath) {
  auto parsed = JsonDocument::parse(autosavePath);
  if (!parsed) return {};
  const auto it = parsed.value().find("autosave_of");
  return it != parsed.value().end() && it->is_string() ? fs::path(it->get<std::string>()) : fs::path();
}

Status StudioSession::open(StudioDocument& document, const fs::path& path) {
  auto read = readSession(path);
  if (!read) return fail(read.error());
  SessionContent content = std::move(read).value();
  document.clear();
  if (content.ct) document.setCt(std::move(*content.ct));
  if (content.views) document.setViews(std::move(*content.views));
  document.setLandmarks(std::move(content.landmarks));
  if (content.initialPose) document.setInitialPose(content.initialPose, content.initialPoseSource);
  document.setRoiParameters(content.roi);
  document.setRegistrationOptions(content.options);
  document.setResults(std::move(content.results), content.currentResult);
  for (const auto& [view, window] : content.xrayWindows) document.setXrayWindow(view, window);
  document.setTruthPose(content.truthPose);
  document.setSessionPath(content.isAutosave ? content.autosaveOf : path);
  document.setModified(content.isAutosave);
  return Ok{};
}

}  // namespace fct
