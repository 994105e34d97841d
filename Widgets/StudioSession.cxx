#include "StudioSession.h"

#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"
#include "IO/Project/PoseFile.h"
#include "Registration/RegistrationResultJson.h"

namespace fct {

namespace {

namespace fs = std::filesystem;
using ordered_json = nlohmann::ordered_json;

constexpr const char* kFormat = "fluoroct-studio-session";
/// Version 2 embeds the result as a RegistrationResultJson object; version 1 (its own result keys) is read too.
constexpr int kVersion = 2;

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

std::string verdictName(ResultVerdict verdict) {
  switch (verdict) {
    case ResultVerdict::Accepted:
      return "accepted";
    case ResultVerdict::Rejected:
      return "rejected";
    case ResultVerdict::Undecided:
      break;
  }
  return "undecided";
}

ordered_json pose(const Eigen::Isometry3d& T) { return JsonDocument::array(T.matrix()); }

/// The result object shared with RESULT.json, with the user's verdict added.
ordered_json resultJson(const RegistrationResult& r, ResultVerdict verdict) {
  ordered_json json = RegistrationResultJson::write(r);
  json["verdict"] = verdictName(verdict);
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
                 {"sphere_margin_px", roi.sphereMargin_px}};
  const StudioRegistrationOptions& options = d.registrationOptions();
  json["registration"] = {{"preset", options.preset}, {"seed", options.seed}, {"drr_method", options.drrMethod}};
  if (d.result()) json["result"] = resultJson(*d.result(), d.resultVerdict());
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
  std::optional<RegistrationResult> result;
  ResultVerdict verdict = ResultVerdict::Undecided;
  std::optional<Eigen::Isometry3d> truthPose;
  fs::path autosaveOf;
  bool isAutosave = false;
};

/// The result object (RegistrationResultJson) and the verdict beside it.
Result<RegistrationResult> readResult(const nlohmann::json& json, const std::string& where, ResultVerdict& verdict) {
  JsonReader reader(json, where);
  const std::string verdictText = reader.string("verdict");
  if (reader.ok()) {
    if (verdictText == "accepted") {
      verdict = ResultVerdict::Accepted;
    } else if (verdictText == "rejected") {
      verdict = ResultVerdict::Rejected;
    } else if (verdictText == "undecided") {
      verdict = ResultVerdict::Undecided;
    } else {
      reader.rejectKey("verdict", fmt::format("is '{}'; use accepted, rejected or undecided", verdictText));
    }
  }
  if (!reader.ok()) return fail(reader.error());
  return RegistrationResultJson::read(json, where);
}

Result<SessionContent> readSession(const fs::path& path) {
  auto parsed = JsonDocument::parse(path);
  if (!parsed) return fail(parsed.error());
  const nlohmann::json& json = parsed.value();
  const std::string where = path.string();
  const fs::path folder = path.parent_path();
  JsonReader reader(json, where);
  const std::string format = reader.string("format");
  if (reader.ok() && format != kFormat) {
    reader.rejectKey("format", fmt::format("is '{}', not '{}': this is not a FluoroCT Studio session file", format,
                                           kFormat));
  }
  const int version = reader.integer("version", 1);
  if (reader.ok() && version > kVersion) {
    reader.rejectKey("version", fmt::format("is {}; this program reads version {} (update FluoroCT)", version, kVersion));
  }
  if (!reader.ok()) return fail(reader.error());

  SessionContent content;
  if (reader.has("autosave_of")) {
    content.isAutosave = true;
    if (const nlohmann::json* owner = reader.find("autosave_of"); owner->is_string()) {
      content.autosaveOf = owner->get<std::string>();
    }
  }
  if (reader.has("ct")) {
    JsonReader ct(*reader.find("ct"), where + ": ct");
    const std::string ctPath = ct.string("path");
    DicomSeriesReadOptions options;
    if (ct.has("series_uid")) options.seriesInstanceUid = ct.string("series_uid");
    if (!ct.ok()) return fail(ct.error());
    auto loaded = StudioDocument::readCt(resolvedPath(ctPath, folder), options);
    if (!loaded) return fail(fmt::format("{}: the session's CT cannot be loaded ({}); put the CT back or edit ct.path in the "
                                          "session file",
                                          where, loaded.error()));
    content.ct = std::move(loaded).value();
  }
  if (reader.has("views")) {
    JsonReader views(*reader.find("views"), where + ": views");
    if (views.has("view_file")) {
      const std::string viewFile = views.string("view_file");
      if (!views.ok()) return fail(views.error());
      auto loaded = StudioDocument::readViews(resolvedPath(viewFile, folder));
      if (!loaded) return fail(fmt::format("{}: the session's views cannot be loaded ({}); put the files back or edit "
                                            "views.view_file in the session file",
                                            where, loaded.error()));
      content.views = std::move(loaded).value();
    } else if (const nlohmann::json* files = views.find("xray_files"); files && files->is_array()) {
      LoadedViews loaded;
      for (std::size_t i = 0; i < files->size(); ++i) {
        JsonReader file((*files)[i], fmt::format("{}: views.xray_files[{}]", where, i));
        const std::string name = file.string("name");
        const std::string xrayPath = file.string("path");
        if (!file.ok()) return fail(file.error());
        auto view = StudioDocument::readXrayFile(resolvedPath(xrayPath, folder));
        if (!view) return fail(fmt::format("{}: view '{}': {}", where, name, view.error()));
        view.value().name = name;
        loaded.views.push_back(std::move(view).value());
      }
      content.views = std::move(loaded);
    } else {
      return fail(where + ": views needs \"view_file\" or \"xray_files\"");
    }
  }
  if (reader.has("landmarks")) {
    JsonReader landmarks(*reader.find("landmarks"), where + ": landmarks");
    if (const nlohmann::json* ct = landmarks.find("ct"); ct && ct->is_array()) {
      for (std::size_t i = 0; i < ct->size(); ++i) {
        JsonReader l((*ct)[i], fmt::format("{}: landmarks.ct[{}]", where, i));
        CtLandmark landmark{l.string("name"), l.vector("p_ct_mm", 3)};
        if (!l.ok()) return fail(l.error());
        content.landmarks.ct.push_back(std::move(landmark));
      }
    }
    if (const nlohmann::json* image = landmarks.find("image"); image && image->is_object()) {
      for (const auto& [viewName, points] : image->items()) {
        if (!points.is_array()) return fail(fmt::format("{}: landmarks.image.{} must be an array", where, viewName));
        std::vector<ImageLandmark>& list = content.landmarks.imageByView[viewName];
        for (std::size_t i = 0; i < points.size(); ++i) {
          JsonReader l(points[i], fmt::format("{}: landmarks.image.{}[{}]", where, viewName, i));
          ImageLandmark landmark{l.string("name"), l.vector("uv_px", 2)};
          if (!l.ok()) return fail(l.error());
          list.push_back(std::move(landmark));
        }
      }
    }
  }
  if (reader.has("initial_pose")) {
    JsonReader initial(*reader.find("initial_pose"), where + ": initial_pose");
    content.initialPose = PoseFile::readKey(initial, "T_world_from_ct");
    if (initial.has("source")) {
      if (const nlohmann::json* source = initial.find("source"); source->is_string()) {
        content.initialPoseSource = QString::fromStdString(source->get<std::string>());
      }
    }
    if (!initial.ok()) return fail(initial.error());
  }
  if (reader.has("roi")) {
    JsonReader roi(*reader.find("roi"), where + ": roi");
    RoiParameters& r = content.roi;
    r.windowSize = roi.integer("window_size", 2);
    r.useThreshold = roi.boolean("use_threshold");
    r.targetFraction = roi.positiveNumber("target_fraction");
    r.varianceThreshold = roi.number("variance_threshold");
    r.margin_px = roi.integer("margin_px", 0);
    r.detectFieldOfView = roi.boolean("detect_field_of_view");
    r.detectSpheres = roi.boolean("detect_spheres");
    r.sphereMargin_px = roi.number("sphere_margin_px");
    if (roi.ok() && r.targetFraction > 1.0) roi.rejectKey("target_fraction", "must be in (0, 1]");
    if (!roi.ok()) return fail(roi.error());
  }
  if (reader.has("registration")) {
    JsonReader registration(*reader.find("registration"), where + ": registration");
    content.options.preset = registration.string("preset");
    content.options.seed = static_cast<std::uint32_t>(registration.integer("seed", 0));
    content.options.drrMethod = registration.string("drr_method");
    if (!registration.ok()) return fail(registration.error());
  }
  if (reader.has("result")) {
    auto result = readResult(*reader.find("result"), where + ": result", content.verdict);
    if (!result) return fail(result.error());
    content.result = std::move(result).value();
  }
  if (reader.has("truth_pose")) {
    JsonReader truth(*reader.find("truth_pose"), where + ": truth_pose");
    content.truthPose = PoseFile::readKey(truth, "T_world_from_ct");
    if (!truth.ok()) return fail(truth.error());
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
  if (content.result) {
    document.setResult(std::move(content.result));
    document.setResultVerdict(content.verdict);
  }
  document.setTruthPose(content.truthPose);
  document.setSessionPath(content.isAutosave ? content.autosaveOf : path);
  document.setModified(content.isAutosave);
  return Ok{};
}

}  // namespace fct
