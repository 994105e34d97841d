#include "Registration/RegistrationResultJson.h"

#include <fmt/core.h>

#include <cmath>
#include <string_view>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"
#include "IO/Project/PoseFile.h"

namespace fct {

namespace {

using ordered_json = nlohmann::ordered_json;

/// Where the keys that differ between the spellings are.
struct Keys {
  const char* initialPose;
  const char* method;
  const char* schedule;
};
constexpr Keys kKeys{"initial_pose.T_world_from_ct", "options.method", "options.schedule"};
constexpr Keys kSessionVersion1Keys{"T_initial", "drr_method", "schedule"};

/// A required whole number >= 0 that may exceed an int (DRR and ray counts); 0 after an error.
long count(JsonReader& reader, std::string_view key) {
  const double value = reader.number(key);
  if (reader.ok() && (value < 0.0 || value != std::floor(value) || value > 9.0e15)) {
    reader.rejectKey(key, fmt::format("must be a whole number >= 0, got {}", value));
  }
  return reader.ok() ? static_cast<long>(value) : 0;
}

/// A required string that may be empty (the DRR method of a run cancelled before its first stage).
std::string text(JsonReader& reader, std::string_view key) {
  const nlohmann::json* value = reader.find(key);
  if (reader.ok() && (!value || !value->is_string())) {
    reader.rejectKey(key, value ? "must be a string, got " + JsonReader::describe(*value) : "is missing");
  }
  return reader.ok() ? value->get<std::string>() : std::string();
}

/// The view names: the `view_names` array, or (version 1 without it) the first stage's kept_fraction keys.
std::vector<std::string> readViewNames(JsonReader& reader, const nlohmann::json& object, int version) {
  std::vector<std::string> names;
  if (!reader.has("view_names") && version == 1) {
    const auto stages = object.find("stages");
    if (stages != object.end() && stages->is_array() && !stages->empty() && stages->front().is_object()) {
      const auto kept = stages->front().find("kept_fraction");
      if (kept != stages->front().end() && kept->is_object()) {
        for (const auto& item : kept->items()) names.push_back(item.key());
      }
    }
    return names;
  }
  const nlohmann::json* list = reader.array("view_names", "an array of view names");
  if (!list) return names;
  for (const nlohmann::json& name : *list) {
    if (!name.is_string()) {
      reader.rejectKey("view_names", "must hold only strings, got " + JsonReader::describe(name));
      return {};
    }
    names.push_back(name.get<std::string>());
  }
  return names;
}

StageReport readStage(const nlohmann::json& object, const std::string& where, const std::vector<std::string>& views,
                      JsonReader& parent) {
  JsonReader reader(object, where);
  StageReport stage;
  stage.name = reader.string("name");
  if (const std::string metric = reader.string("metric"); reader.ok()) {
    if (auto parsed = RegistrationSchedule::parseMetric(metric)) {
      stage.metric = parsed.value();
    } else {
      reader.reject("key 'metric': " + parsed.error());
    }
  }
  stage.level = reader.integer("level", 0);
  if (const std::string search = reader.string("search"); reader.ok()) {
    if (auto parsed = RegistrationSchedule::parseSearch(search)) {
      stage.search = parsed.value();
    } else {
      reader.reject("key 'search': " + parsed.error());
    }
  }
  stage.seconds = reader.number("seconds");
  stage.drrs = count(reader, "drrs");
  stage.fallbackRays = count(reader, "fallback_rays");
  stage.evaluations = reader.integer("evaluations", 0);
  stage.startSimilarity = reader.number("start_similarity");
  stage.similarity = reader.number("similarity");
  const nlohmann::json* kept = reader.object("kept_fraction", "an object {<view name>: fraction}");
  for (std::size_t v = 0; reader.ok() && v < views.size(); ++v) {
    const auto value = kept->find(views[v]);
    if (value == kept->end()) break;  // the writer leaves out nothing but fractions without a view name
    if (!value->is_number() || !std::isfinite(value->get<double>())) {
      reader.rejectKey("kept_fraction", fmt::format("of view '{}' must be a finite number, got {}", views[v],
                                                    JsonReader::describe(*value)));
      break;
    }
    stage.keptFraction.push_back(value->get<double>());
  }
  if (reader.has("prealign_shift_mm")) stage.prealignShift_world_mm = reader.vector("prealign_shift_mm", 3);
  if (reader.has("rotation_sweep_seeds")) stage.rotationSweepSeeds = reader.integer("rotation_sweep_seeds", 0);
  if (reader.has("metal_pieces_given_back")) {
    stage.metalPiecesGivenBack = reader.integer("metal_pieces_given_back", 0);
  }
  if (reader.has("haze_views_corrected")) {
    stage.hazeViewsCorrected = reader.integer("haze_views_corrected", 0);
    stage.hazeFraction = reader.number("haze_fraction");
    if (reader.has("haze_hardening")) stage.hazeHardening = reader.number("haze_hardening");
  }
  if (const nlohmann::json* kept = reader.has("haze_views_kept")
                                       ? reader.array("haze_views_kept", "a list of texts (one per view)")
                                       : nullptr) {
    for (const nlohmann::json& text : *kept) {
      if (!text.is_string()) {
        reader.rejectKey("haze_views_kept", fmt::format("holds {}; use texts", JsonReader::describe(text)));
        break;
      }
      stage.hazeViewsKept.push_back(text.get<std::string>());
    }
  }
  stage.cancelled = reader.boolean("cancelled");
  parent.adoptError(reader);
  return stage;
}

}  // namespace

ordered_json RegistrationResultJson::write(const RegistrationResult& result) {
  ordered_json stages = ordered_json::array();
  for (const StageReport& s : result.stages) {
    ordered_json kept = ordered_json::object();
    for (std::size_t v = 0; v < s.keptFraction.size() && v < result.viewNames.size(); ++v) {
      kept[result.viewNames[v]] = s.keptFraction[v];
    }
    stages.push_back({{"name", s.name},
                      {"metric", RegistrationSchedule::metricName(s.metric)},
                      {"level", s.level},
                      {"search", RegistrationSchedule::searchName(s.search)},
                      {"seconds", s.seconds},
                      {"drrs", s.drrs},
                      {"fallback_rays", s.fallbackRays},
                      {"evaluations", s.evaluations},
                      {"start_similarity", s.startSimilarity},
                      {"similarity", s.similarity},
                      {"kept_fraction", std::move(kept)},
                      {"cancelled", s.cancelled}});
    if (!s.prealignShift_world_mm.isZero()) {
      stages.back()["prealign_shift_mm"] = JsonDocument::array(s.prealignShift_world_mm);
    }
    if (s.rotationSweepSeeds > 0) stages.back()["rotation_sweep_seeds"] = s.rotationSweepSeeds;
    if (s.metalPiecesGivenBack > 0) stages.back()["metal_pieces_given_back"] = s.metalPiecesGivenBack;
    if (s.hazeViewsCorrected > 0) {
      stages.back()["haze_views_corrected"] = s.hazeViewsCorrected;
      stages.back()["haze_fraction"] = s.hazeFraction;
      stages.back()["haze_hardening"] = s.hazeHardening;
    }
    if (!s.hazeViewsKept.empty()) stages.back()["haze_views_kept"] = s.hazeViewsKept;
  }
  ordered_json initialPose = ordered_json::object();
  initialPose["T_world_from_ct"] = JsonDocument::array(result.T_initial.matrix());
  ordered_json options = ordered_json::object();
  options["method"] = result.drrMethod;
  options["schedule"] = result.schedule.toJson();
  return ordered_json{{"format", kFormat},
                      {"version", kVersion},
                      {"T_world_from_ct", JsonDocument::array(result.T_world_from_ct.matrix())},
                      {"cancelled", result.cancelled},
                      {"initial_pose", std::move(initialPose)},
                      {"rotation_centre_ct_mm", JsonDocument::array(result.rotationCentre_ct_mm)},
                      {"view_names", result.viewNames},
                      {"stages", std::move(stages)},
                      {"total_seconds", result.totalSeconds},
                      {"total_drrs", result.totalDrrs},
                      {"view_renderer_setup_seconds", result.viewRendererSetupSeconds},
                      {"options", std::move(options)}};
}

Result<RegistrationResult> RegistrationResultJson::read(const nlohmann::json& object, const std::string& where) {
  JsonReader reader(object, where);
  const int version = reader.has("format") ? reader.formatVersion(kFormat, "registration result", kVersion) : 1;
  if (!reader.ok()) return fail(reader.error());
  const Keys& keys = version == 1 && reader.has("T_initial") ? kSessionVersion1Keys : kKeys;

  RegistrationResult r;
  if (auto T = PoseFile::readKey(reader, "T_world_from_ct")) r.T_world_from_ct = *T;
  if (auto T = PoseFile::readKey(reader, keys.initialPose)) r.T_initial = *T;
  r.cancelled = reader.boolean("cancelled");
  r.rotationCentre_ct_mm = reader.vector("rotation_centre_ct_mm", 3);
  r.viewNames = readViewNames(reader, object, version);
  r.totalSeconds = reader.number("total_seconds");
  r.totalDrrs = count(reader, "total_drrs");
  if (version >= 2) r.viewRendererSetupSeconds = reader.number("view_renderer_setup_seconds");
  r.drrMethod = text(reader, keys.method);
  const nlohmann::json* stages = reader.array("stages", "an array of stage reports");
  for (std::size_t i = 0; reader.ok() && i < stages->size(); ++i) {
    r.stages.push_back(readStage((*stages)[i], fmt::format("{}: stages[{}]", where, i), r.viewNames, reader));
  }
  const nlohmann::json* schedule = reader.find(keys.schedule);
  if (reader.ok() && !schedule) reader.rejectKey(keys.schedule, "is missing");
  if (!reader.ok()) return fail(reader.error());
  auto parsed = RegistrationSchedule::fromJson(*schedule, fmt::format("{}: {}", where, keys.schedule));
  if (!parsed) return fail(parsed.error());
  r.schedule = std::move(parsed).value();
  return r;
}

}  // namespace fct
