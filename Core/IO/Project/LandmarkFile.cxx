#include "IO/Project/LandmarkFile.h"

#include <fmt/core.h>

#include <set>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"

namespace fct {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

constexpr const char* kMarkupsSchema =
    "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/"
    "markups-schema-v1.0.3.json#";

/// Millimetres per unit of a markup's "coordinateUnits" ("mm" by default; "um"), or an error.
Result<double> mmPerUnit(const JsonReader& markup) {
  const json* units = markup.find("coordinateUnits");
  if (!units) return 1.0;
  // Either "mm" or a DICOM code triple such as ["mm", "UCUM", "millimeter"].
  const json& code = units->is_array() && !units->empty() ? (*units)[0] : *units;
  if (code == "mm") return 1.0;
  if (code == "um") return 0.001;
  return fail(fmt::format("{}: key 'coordinateUnits' must be \"mm\" or \"um\", got {}", markup.where(),
                          JsonReader::describe(*units)));
}

bool isFinite(const CtLandmark& landmark) { return landmark.p_ct_mm.allFinite(); }
bool isFinite(const ImageLandmark& landmark) { return landmark.uv_px.allFinite(); }

/// Checks that names are non-empty and unique and points finite before writing; `what` starts each message.
template <typename Landmark>
Status checkBeforeWrite(const std::vector<Landmark>& landmarks, const std::string& what) {
  std::set<std::string> names;
  for (const Landmark& landmark : landmarks) {
    if (landmark.name.empty()) return fail(fmt::format("{}: a landmark has no name", what));
    if (!names.insert(landmark.name).second) {
      return fail(fmt::format("{}: landmark name '{}' is used twice", what, landmark.name));
    }
    if (!isFinite(landmark)) return fail(fmt::format("{}: landmark '{}' has NaN or infinity", what, landmark.name));
  }
  return Ok{};
}

}  // namespace

Result<std::vector<CtLandmark>> LandmarkFile::readCt(const std::filesystem::path& path) {
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  const std::string file = path.string();
  JsonReader top(document.value(), file);
  const json* markups = top.find("markups");
  if (top.ok() && (!markups || !markups->is_array())) {
    top.reject("not a 3D Slicer markups file: it has no \"markups\" array");
  }
  if (!top.ok()) return fail(top.error());

  std::vector<CtLandmark> landmarks;
  std::vector<std::string> warnings;
  std::set<std::string> names;
  for (std::size_t m = 0; m < markups->size(); ++m) {
    JsonReader markup((*markups)[m], fmt::format("{}: markups[{}]", file, m));
    const std::string type = markup.string("type");
    if (!markup.ok()) return fail(markup.error());
    if (type != "Fiducial") {
      warnings.push_back(fmt::format("{}: markup of type '{}' ignored; only point lists (Fiducial) are read",
                                     markup.where(), type));
      continue;
    }
    const std::string system = markup.has("coordinateSystem") ? markup.string("coordinateSystem") : "LPS";
    if (markup.ok() && system != "LPS" && system != "RAS") {
      markup.rejectKey("coordinateSystem", fmt::format("must be \"LPS\" or \"RAS\", got \"{}\"", system));
    }
    if (!markup.ok()) return fail(markup.error());
    const auto scale = mmPerUnit(markup);
    if (!scale) return fail(scale.error());
    const json* points = markup.find("controlPoints");
    if (!points) continue;
    if (!points->is_array()) {
      return fail(fmt::format("{}: key 'controlPoints' must be an array, got {}", markup.where(),
                              JsonReader::describe(*points)));
    }
    for (std::size_t i = 0; i < points->size(); ++i) {
      const json& pointJson = (*points)[i];
      JsonReader unnamed(pointJson, fmt::format("{}: control point {}", markup.where(), i));
      CtLandmark landmark;
      landmark.name = unnamed.string("label");
      if (!unnamed.ok()) {
        return fail(unnamed.error() + "; every CT landmark needs a label to be paired with its X-ray points");
      }
      JsonReader point(pointJson, fmt::format("{}: landmark '{}'", file, landmark.name));
      if (point.has("positionStatus") && point.string("positionStatus") == "undefined") {
        warnings.push_back(fmt::format("{}: position not placed yet (positionStatus \"undefined\"); skipped",
                                       point.where()));
        continue;
      }
      if (!names.insert(landmark.name).second) {
        return fail(fmt::format("{}: landmark label '{}' is used twice; labels must be unique", file, landmark.name));
      }
      landmark.p_ct_mm = point.vector("position", 3) * scale.value();
      if (!point.ok()) return fail(point.error());
      if (system == "RAS") landmark.p_ct_mm.head<2>() *= -1.0;
      landmarks.push_back(std::move(landmark));
    }
  }
  if (landmarks.empty()) warnings.push_back(fmt::format("{}: no landmarks found", file));
  Result<std::vector<CtLandmark>> result(std::move(landmarks));
  for (std::string& warning : warnings) result.addWarning(std::move(warning));
  return result;
}

Status LandmarkFile::writeCt(const std::vector<CtLandmark>& landmarks, const std::filesystem::path& path) {
  if (auto ok = checkBeforeWrite(landmarks, fmt::format("cannot write '{}'", path.string())); !ok) return ok;
  ordered_json points = ordered_json::array();
  int id = 0;
  for (const CtLandmark& landmark : landmarks) {
    points.push_back({{"id", std::to_string(++id)},
                      {"label", landmark.name},
                      {"description", ""},
                      {"associatedNodeID", ""},
                      {"position", JsonDocument::array(landmark.p_ct_mm)},
                      // Slicer's identity orientation (RAS) as written in an LPS file.
                      {"orientation", {-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0}},
                      {"selected", true},
                      {"locked", false},
                      {"visibility", true},
                      {"positionStatus", "defined"}});
  }
  ordered_json markup{{"type", "Fiducial"},
                      {"coordinateSystem", "LPS"},
                      {"coordinateUnits", "mm"},
                      {"locked", false},
                      {"fixedNumberOfControlPoints", false},
                      {"labelFormat", "%N-%d"},
                      {"lastUsedControlPointNumber", id},
                      {"controlPoints", std::move(points)},
                      {"measurements", ordered_json::array()}};
  ordered_json document{{"@schema", kMarkupsSchema}, {"markups", ordered_json::array({std::move(markup)})}};
  return JsonDocument::write(document, path);
}

Result<std::map<std::string, std::vector<ImageLandmark>>> LandmarkFile::readImage(const std::filesystem::path& path) {
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  const std::string file = path.string();
  JsonReader top(document.value(), file);
  const json* views = top.find("views");
  if (top.ok() && (!views || !views->is_object())) {
    top.rejectKey("views", fmt::format("must be an object {{\"AP\": [{{\"name\": ..., \"uv_px\": [u, v]}}], ...}}, "
                                       "got {}",
                                       views ? JsonReader::describe(*views) : "nothing"));
  }
  if (!top.ok()) return fail(top.error());
  std::vector<std::string> warnings = top.unknownKeys({"views"});

  std::map<std::string, std::vector<ImageLandmark>> byView;
  for (auto it = views->begin(); it != views->end(); ++it) {
    const std::string where = fmt::format("{}: view '{}'", file, it.key());
    if (!it.value().is_array()) {
      return fail(fmt::format("{}: must be an array of {{\"name\": ..., \"uv_px\": [u, v]}}, got {}", where,
                              JsonReader::describe(it.value())));
    }
    std::vector<ImageLandmark>& landmarks = byView[it.key()];
    std::set<std::string> names;
    for (std::size_t i = 0; i < it.value().size(); ++i) {
      const json& pointJson = it.value()[i];
      JsonReader unnamed(pointJson, fmt::format("{}: landmark {}", where, i));
      ImageLandmark landmark;
      landmark.name = unnamed.string("name");
      if (!unnamed.ok()) return fail(unnamed.error());
      if (!names.insert(landmark.name).second) {
        return fail(fmt::format("{}: landmark name '{}' is used twice in this view", where, landmark.name));
      }
      JsonReader point(pointJson, fmt::format("{}: landmark '{}'", where, landmark.name));
      landmark.uv_px = point.vector("uv_px", 2);
      if (!point.ok()) return fail(point.error());
      auto unknown = point.unknownKeys({"name", "uv_px"});
      warnings.insert(warnings.end(), unknown.begin(), unknown.end());
      landmarks.push_back(std::move(landmark));
    }
  }
  Result<std::map<std::string, std::vector<ImageLandmark>>> result(std::move(byView));
  for (std::string& warning : warnings) result.addWarning(std::move(warning));
  return result;
}

Status LandmarkFile::writeImage(const std::map<std::string, std::vector<ImageLandmark>>& landmarksByView,
                                const std::filesystem::path& path) {
  ordered_json views = ordered_json::object();
  for (const auto& [view, landmarks] : landmarksByView) {
    if (view.empty()) return fail(fmt::format("cannot write '{}': a view has no name", path.string()));
    const auto ok = checkBeforeWrite(landmarks, fmt::format("cannot write '{}': view '{}'", path.string(), view));
    if (!ok) return ok;
    ordered_json points = ordered_json::array();
    for (const ImageLandmark& landmark : landmarks) {
      points.push_back({{"name", landmark.name}, {"uv_px", JsonDocument::array(landmark.uv_px)}});
    }
    views[view] = std::move(points);
  }
  return JsonDocument::write(ordered_json{{"views", std::move(views)}}, path);
}

}  // namespace fct
