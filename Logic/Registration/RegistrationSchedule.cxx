#include "Registration/RegistrationSchedule.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <optional>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"
#include "Base/NameTable.h"
#include "RegistrationPresetsEmbedded.h"

namespace fct {

namespace {

/// The value named by `key`; rejects the key (naming the accepted names) for any other text.
template <typename Enum, std::size_t N>
Enum parseName(JsonReader& reader, std::string_view key, const NameTable<Enum, N>& names) {
  return readNamed(reader, key, names, "one of " + namesOf(names)).value_or(names[0].second);
}

constexpr NameTable<SimilarityMetric, 3> kMetrics{
    {{"ncc", SimilarityMetric::Ncc}, {"vlnc", SimilarityMetric::Vlnc}, {"gc", SimilarityMetric::GradientCorrelation}}};
constexpr NameTable<SearchStrategy, 3> kSearches{
    {{"genetic", SearchStrategy::Genetic}, {"cmaes", SearchStrategy::CmaEs}, {"local", SearchStrategy::Local}}};
constexpr NameTable<LocalSearchMethod, 2> kLocalMethods{
    {{"simplex", LocalSearchMethod::Simplex}, {"bobyqa", LocalSearchMethod::Bobyqa}}};
/// The exact methods a stage may name in "drr" (the Transgraph is built per view and case, not per stage).
constexpr NameTable<DrrMethod, 2> kStageDrrMethods{{{"siddon", DrrMethod::Siddon}, {"raycast", DrrMethod::RayCast}}};
constexpr NameTable<CtSliceModel, 2> kCtSliceModels{
    {{"samples", CtSliceModel::Samples}, {"slab_averages", CtSliceModel::SlabAverages}}};
constexpr NameTable<VlncDomain, 2> kVlncDomains{
    {{"line_integral", VlncDomain::LineIntegral}, {"intensity", VlncDomain::Intensity}}};
constexpr NameTable<VlncWeightSource, 2> kVlncWeightSources{
    {{"xray", VlncWeightSource::Xray}, {"drr", VlncWeightSource::Drr}}};
constexpr NameTable<PixelSetKind, 2> kPixelSets{
    {{"whole", PixelSetKind::WholeImage}, {"rois", PixelSetKind::Rois}}};

/// Reads an optional number into `value` (kept when the key is absent).
void optionalNumber(JsonReader& reader, std::string_view key, double& value) {
  if (reader.has(key)) value = reader.number(key);
}
void optionalInteger(JsonReader& reader, std::string_view key, int minimum, int& value) {
  if (reader.has(key)) value = reader.integer(key, minimum);
}

void readSimplex(const nlohmann::json& object, const std::string& where, JsonReader& parent, LocalSearchOptions& o) {
  JsonReader reader(object, where);
  if (reader.has("method")) o.method = parseName(reader, "method", kLocalMethods);
  optionalNumber(reader, "initial_step", o.initialStep);
  optionalNumber(reader, "tolerance", o.tolerance);
  optionalInteger(reader, "max_evaluations", 1, o.maxEvaluations);
  optionalInteger(reader, "restarts", 0, o.restarts);
  optionalInteger(reader, "stall_window", 0, o.stall.window);
  optionalNumber(reader, "stall_improvement", o.stall.relativeImprovement);
  parent.adoptError(reader);
}

void readCmaEs(const nlohmann::json& object, const std::string& where, JsonReader& parent, CmaEsOptions& o) {
  JsonReader reader(object, where);
  optionalNumber(reader, "sigma", o.initialSigma);
  optionalNumber(reader, "tolerance", o.tolerance);
  optionalInteger(reader, "population", 0, o.populationSize);
  optionalInteger(reader, "max_evaluations", 1, o.maxEvaluations);
  if (reader.has("seed")) o.seed = static_cast<std::uint32_t>(reader.integer("seed", 0));
  parent.adoptError(reader);
}

/// Reads a stage's "rotation_sweep" object; rejects a radius outside (0, 180], a step outside (0, radius], or counts
/// below 1 (seeds above aligned).
void readRotationSweep(const nlohmann::json& object, const std::string& where, JsonReader& parent,
                       RotationSweepSpec& o) {
  JsonReader reader(object, where + ": rotation_sweep");
  if (!reader.has("max_deg")) reader.rejectKey("max_deg", "is missing; give the grid's radius in degrees, e.g. 60");
  optionalNumber(reader, "max_deg", o.maxRotation_deg);
  optionalNumber(reader, "step_deg", o.step_deg);
  optionalInteger(reader, "aligned", 1, o.aligned);
  optionalInteger(reader, "seeds", 1, o.seeds);
  optionalInteger(reader, "max_pixels", 16, o.maxPixels);
  if (reader.ok() && !(o.maxRotation_deg > 0.0 && o.maxRotation_deg <= 180.0)) {
    reader.rejectKey("max_deg", fmt::format("is {}; use a radius above 0 and at most 180 deg", o.maxRotation_deg));
  }
  if (reader.ok() && !(o.step_deg > 0.0 && o.step_deg <= o.maxRotation_deg)) {
    reader.rejectKey("step_deg", fmt::format("is {}; use a step above 0 and at most max_deg ({})", o.step_deg,
                                             o.maxRotation_deg));
  }
  if (reader.ok() && o.seeds > o.aligned) {
    reader.rejectKey("seeds", fmt::format("is {}; use at most aligned ({})", o.seeds, o.aligned));
  }
  parent.adoptError(reader);
}

/// Reads the optional boolean `key` into `flag`; rejects any other type.
void optionalFlag(JsonReader& reader, const char* key, bool& flag) {
  const nlohmann::json* value = reader.find(key);
  if (!value) return;
  if (value->is_boolean()) {
    flag = value->get<bool>();
  } else {
    reader.rejectKey(key, fmt::format("is {}; use true or false", JsonReader::describe(*value)));
  }
}

Result<RegistrationStage> readStage(const nlohmann::json& object, const std::string& where) {
  RegistrationStage stage;
  JsonReader reader(object, where);
  stage.name = reader.string("name");
  stage.metric = parseName(reader, "metric", kMetrics);
  stage.level = reader.integer("level", 0);
  if (reader.ok() && stage.level > 7) reader.rejectKey("level", fmt::format("is {}; use 0 to 7", stage.level));
  if (reader.has("domain")) {
    stage.vlncDomain = parseName(reader, "domain", kVlncDomains);
    if (reader.ok() && stage.metric != SimilarityMetric::Vlnc) {
      reader.rejectKey("domain", "applies only with \"metric\": \"vlnc\"");
    }
  }
  if (reader.has("weights")) {
    stage.vlncWeights = parseName(reader, "weights", kVlncWeightSources);
    if (reader.ok() && stage.metric != SimilarityMetric::Vlnc) {
      reader.rejectKey("weights", "applies only with \"metric\": \"vlnc\"");
    }
  }
  optionalFlag(reader, "exact_drr", stage.exactDrr);
  optionalFlag(reader, "shift_prealign", stage.shiftPrealign);
  optionalFlag(reader, "metal_review", stage.metalReview);
  optionalNumber(reader, "haze_sigma_mm", stage.hazeSigma_mm);
  if (reader.ok() && reader.has("haze_sigma_mm") && !(stage.hazeSigma_mm >= 1.0 && stage.hazeSigma_mm <= 200.0)) {
    reader.rejectKey("haze_sigma_mm", fmt::format("is {}; use 1 to 200 mm on the detector", stage.hazeSigma_mm));
  }
  if (const nlohmann::json* sweep = reader.find("rotation_sweep")) readRotationSweep(*sweep, where, reader, stage.rotationSweep);
  if (reader.has("drr")) stage.drrMethod = parseName(reader, "drr", kStageDrrMethods);
  optionalNumber(reader, "drr_step_voxels", stage.drrStep_voxels);
  if (reader.ok() && reader.has("drr_step_voxels")) {
    if (stage.drrMethod != DrrMethod::RayCast) {
      reader.rejectKey("drr_step_voxels", "applies only with \"drr\": \"raycast\"");
    } else if (!(stage.drrStep_voxels > 0.0 && stage.drrStep_voxels <= 10.0)) {
      reader.rejectKey("drr_step_voxels", fmt::format("is {}; use a step above 0 and at most 10 voxels", stage.drrStep_voxels));
    }
  }
  if (reader.has("drr_slices")) {
    stage.drrSlices = parseName(reader, "drr_slices", kCtSliceModels);
    if (reader.ok() && stage.drrMethod != DrrMethod::RayCast) {
      reader.rejectKey("drr_slices", "applies only with \"drr\": \"raycast\" (exact box voxels already average "
                                     "each slice)");
    }
  }

  if (const nlohmann::json* pixels = reader.find("pixels")) {
    JsonReader pixelReader(*pixels, where + ": pixels");
    stage.pixels.kind = parseName(pixelReader, "set", kPixelSets);
    optionalInteger(pixelReader, "window", 2, stage.pixels.windowSize);
    optionalNumber(pixelReader, "fraction", stage.pixels.targetFraction);
    optionalInteger(pixelReader, "max_pixels", 0, stage.pixels.maxPixels);
    if (pixelReader.ok() && stage.pixels.windowSize > 64) {
      pixelReader.rejectKey("window", fmt::format("is {}; use 2 to 64 pixels", stage.pixels.windowSize));
    }
    if (pixelReader.ok() && !(stage.pixels.targetFraction > 0.0 && stage.pixels.targetFraction <= 1.0)) {
      pixelReader.rejectKey("fraction", fmt::format("is {}; use 0 < fraction <= 1 (the paper: 0.10 to 0.15)",
                                                    stage.pixels.targetFraction));
    }
    reader.adoptError(pixelReader);
  } else {
    reader.rejectKey("pixels", "is missing; give {\"set\": \"whole\"} or {\"set\": \"rois\", \"window\": 7, "
                               "\"fraction\": 0.12}");
  }

  if (const nlohmann::json* search = reader.find("search")) {
    const std::string searchWhere = where + ": search";
    JsonReader s(*search, searchWhere);
    stage.search = parseName(s, "strategy", kSearches);
    stage.maxEvaluations = s.integer("max_evaluations", 1);
    GeneticSearchOptions& g = stage.genetic;
    optionalInteger(s, "guesses", 1, g.randomGuesses);
    optionalNumber(s, "spread_deg", g.spreadRotation_deg);
    optionalNumber(s, "spread_mm", g.spreadTranslation_mm);
    optionalNumber(s, "drop", g.dropThreshold);
    optionalNumber(s, "extrapolation", g.extrapolation);
    optionalInteger(s, "generations", 0, g.maxGenerations);
    if (s.has("seed")) g.seed = static_cast<std::uint32_t>(s.integer("seed", 0));
    if (const nlohmann::json* simplex = s.find("simplex")) readSimplex(*simplex, searchWhere + ".simplex", s, stage.simplex);
    if (const nlohmann::json* cmaes = s.find("cmaes")) readCmaEs(*cmaes, searchWhere + ".cmaes", s, stage.cmaes);
    optionalNumber(s, "depth_scale", stage.depthScale);
    if (s.ok() && s.has("depth_scale")) {
      if (stage.search != SearchStrategy::Local) {
        s.rejectKey("depth_scale", "applies only with \"strategy\": \"local\"");
      } else if (!(stage.depthScale >= 1.0 && stage.depthScale <= 100.0)) {
        s.rejectKey("depth_scale", fmt::format("is {}; use 1 (off) to 100", stage.depthScale));
      }
    }
    reader.adoptError(s);
  } else {
    reader.rejectKey("search", "is missing; give at least {\"strategy\": \"local\", \"max_evaluations\": 500}");
  }
  if (!reader.ok()) return fail(reader.error());

  stage.genetic.maxEvaluations = stage.maxEvaluations;
  stage.genetic.local = stage.simplex;
  for (const Status& status : {LocalPoseOptimizer::create(stage.simplex)->validateOptions(),
                               GeneticSearchOptimizer(stage.genetic).validateOptions(),
                               CmaEsOptimizer(stage.cmaes).validateOptions()}) {
    if (!status) return fail(fmt::format("{}: {}", where, status.error()));
  }
  return stage;
}

}  // namespace

std::vector<std::string> RegistrationAblation::activeNames() const {
  std::vector<std::string> names;
  if (noDynamicRois) names.emplace_back("no-rois");
  if (noPyramid) names.emplace_back("no-pyramid");
  if (nccOnly) names.emplace_back("ncc-only");
  if (localOnly) names.emplace_back("local-only");
  if (cmaesForGenetic) names.emplace_back("cmaes");
  if (noTransgraph) names.emplace_back("no-transgraph");
  if (noCtPyramid) names.emplace_back("no-ct-pyramid");
  return names;
}

std::string_view RegistrationSchedule::metricName(SimilarityMetric metric) { return nameOf(metric, kMetrics); }
std::string_view RegistrationSchedule::searchName(SearchStrategy search) { return nameOf(search, kSearches); }

Result<SimilarityMetric> RegistrationSchedule::parseMetric(std::string_view name) {
  if (const auto metric = valueNamed(name, kMetrics)) return *metric;
  return fail(fmt::format("'{}' is not a similarity metric; use one of {}", name, namesOf(kMetrics)));
}

Result<SearchStrategy> RegistrationSchedule::parseSearch(std::string_view name) {
  if (const auto search = valueNamed(name, kSearches)) return *search;
  return fail(fmt::format("'{}' is not a search strategy; use one of {}", name, namesOf(kSearches)));
}

std::vector<std::string> RegistrationSchedule::builtinNames() {
  std::vector<std::string> names;
  for (const auto& [name, text] : embedded::kRegistrationPresets) names.emplace_back(name);
  return names;
}

Result<RegistrationSchedule> RegistrationSchedule::builtin(std::string_view name) {
  for (const auto& [presetName, text] : embedded::kRegistrationPresets) {
    if (presetName != name) continue;
    const std::string where = fmt::format("built-in preset '{}'", name);
    auto document = JsonDocument::parseText(std::string(text), where);
    if (!document) return fail(document.error());
    return fromJson(document.value(), where);
  }
  return fail(fmt::format("unknown registration preset '{}'; use one of {} or a preset file (.json)", name,
                          fmt::join(builtinNames(), ", ")));
}

Result<RegistrationSchedule> RegistrationSchedule::readFile(const std::filesystem::path& path) {
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  return fromJson(document.value(), path.string());
}

Result<RegistrationSchedule> RegistrationSchedule::resolve(const std::string& nameOrPath) {
  for (const std::string& name : builtinNames()) {
    if (name == nameOrPath) return builtin(name);
  }
  if (!std::filesystem::exists(nameOrPath)) {
    return fail(fmt::format("'{}' is neither a built-in preset ({}) nor an existing preset file", nameOrPath,
                            fmt::join(builtinNames(), ", ")));
  }
  return readFile(nameOrPath);
}

Result<RegistrationSchedule> RegistrationSchedule::fromJson(const nlohmann::json& document, const std::string& where) {
  JsonReader reader(document, where);
  RegistrationSchedule schedule;
  schedule.name = reader.string("name");
  if (const nlohmann::json* description = reader.find("description"); description && description->is_string()) {
    schedule.description = description->get<std::string>();
  }
  const nlohmann::json* stages = reader.find("stages");
  if (reader.ok() && (!stages || !stages->is_array() || stages->empty())) {
    reader.rejectKey("stages", "must be a non-empty array of stages");
  }
  if (!reader.ok()) return fail(reader.error());
  for (std::size_t i = 0; i < stages->size(); ++i) {
    auto stage = readStage((*stages)[i], fmt::format("{}: stages[{}]", where, i));
    if (!stage) return fail(stage.error());
    schedule.stages.push_back(std::move(stage).value());
  }
  return schedule;
}

nlohmann::ordered_json RegistrationSchedule::toJson() const {
  nlohmann::ordered_json stagesJson = nlohmann::ordered_json::array();
  for (const RegistrationStage& s : stages) {
    nlohmann::ordered_json pixels{{"set", nameOf(s.pixels.kind, kPixelSets)}, {"window", s.pixels.windowSize}};
    if (s.pixels.kind == PixelSetKind::Rois) pixels["fraction"] = s.pixels.targetFraction;
    if (s.pixels.maxPixels > 0) pixels["max_pixels"] = s.pixels.maxPixels;
    nlohmann::ordered_json search{{"strategy", searchName(s.search)}, {"max_evaluations", s.maxEvaluations}};
    search["guesses"] = s.genetic.randomGuesses;
    search["spread_deg"] = s.genetic.spreadRotation_deg;
    search["spread_mm"] = s.genetic.spreadTranslation_mm;
    search["drop"] = s.genetic.dropThreshold;
    search["extrapolation"] = s.genetic.extrapolation;
    search["generations"] = s.genetic.maxGenerations;
    search["seed"] = s.genetic.seed;
    search["simplex"] = {{"initial_step", s.simplex.initialStep},
                         {"tolerance", s.simplex.tolerance},
                         {"max_evaluations", s.simplex.maxEvaluations},
                         {"restarts", s.simplex.restarts}};
    if (s.simplex.method != LocalSearchMethod::Simplex) {
      search["simplex"]["method"] = nameOf(s.simplex.method, kLocalMethods);
    }
    if (s.simplex.stall.window > 0) {
      search["simplex"]["stall_window"] = s.simplex.stall.window;
      search["simplex"]["stall_improvement"] = s.simplex.stall.relativeImprovement;
    }
    if (s.depthScale != 1.0) search["depth_scale"] = s.depthScale;
    search["cmaes"] = {{"sigma", s.cmaes.initialSigma},
                       {"tolerance", s.cmaes.tolerance},
                       {"population", s.cmaes.populationSize},
                       {"max_evaluations", s.cmaes.maxEvaluations},
                       {"seed", s.cmaes.seed}};
    nlohmann::ordered_json stageJson{{"name", s.name},
                                     {"metric", metricName(s.metric)},
                                     {"level", s.level},
                                     {"exact_drr", s.exactDrr}};
    if (s.metric == SimilarityMetric::Vlnc && s.vlncDomain != VlncDomain::LineIntegral) {
      stageJson["domain"] = nameOf(s.vlncDomain, kVlncDomains);  // other metrics compare line integrals
    }
    if (s.metric == SimilarityMetric::Vlnc && s.vlncWeights != VlncWeightSource::Xray) {
      stageJson["weights"] = nameOf(s.vlncWeights, kVlncWeightSources);
    }
    if (s.drrMethod) stageJson["drr"] = nameOf(*s.drrMethod, kStageDrrMethods);
    if (s.drrStep_voxels > 0.0) stageJson["drr_step_voxels"] = s.drrStep_voxels;
    if (s.drrSlices != CtSliceModel::Samples) stageJson["drr_slices"] = nameOf(s.drrSlices, kCtSliceModels);
    if (s.shiftPrealign) stageJson["shift_prealign"] = true;
    if (s.metalReview) stageJson["metal_review"] = true;
    if (s.hazeSigma_mm > 0.0) stageJson["haze_sigma_mm"] = s.hazeSigma_mm;
    if (s.rotationSweep.maxRotation_deg > 0.0) {
      stageJson["rotation_sweep"] = {{"max_deg", s.rotationSweep.maxRotation_deg},
                                     {"step_deg", s.rotationSweep.step_deg},
                                     {"aligned", s.rotationSweep.aligned},
                                     {"seeds", s.rotationSweep.seeds},
                                     {"max_pixels", s.rotationSweep.maxPixels}};
    }
    stageJson["pixels"] = std::move(pixels);
    stageJson["search"] = std::move(search);
    stagesJson.push_back(std::move(stageJson));
  }
  return nlohmann::ordered_json{{"name", name}, {"description", description}, {"stages", std::move(stagesJson)}};
}

std::vector<std::string> RegistrationSchedule::stageDrrNotes() const {
  std::vector<std::string> out;
  for (const RegistrationStage& s : stages) {
    if (!s.drrMethod) continue;
    const std::string step =
        s.drrStep_voxels > 0.0 ? fmt::format(" (a sample every {:g} voxel)", s.drrStep_voxels) : std::string();
    const std::string slices = s.drrSlices == CtSliceModel::SlabAverages
                                   ? std::string(", a thick-slice CT's slices read as averages over their thickness")
                                   : std::string();
    out.push_back(fmt::format("stage '{}' renders its DRRs with the {} method{}{}", s.name,
                              nameOf(*s.drrMethod, kStageDrrMethods), step, slices));
  }
  return out;
}

RegistrationSchedule RegistrationSchedule::withAblation(const RegistrationAblation& ablation) const {
  RegistrationSchedule result = *this;
  const auto active = ablation.activeNames();
  if (!active.empty()) result.name = fmt::format("{} ({})", name, fmt::join(active, ", "));
  for (RegistrationStage& stage : result.stages) {
    if (ablation.noDynamicRois) stage.pixels.kind = PixelSetKind::WholeImage;
    if (ablation.noPyramid) stage.level = 0;
    if (ablation.nccOnly) {
      stage.metric = SimilarityMetric::Ncc;
      stage.vlncDomain = VlncDomain::LineIntegral;  // NCC compares line integrals
    }
    if (ablation.localOnly) stage.search = SearchStrategy::Local;
    if (ablation.cmaesForGenetic && stage.search == SearchStrategy::Genetic) stage.search = SearchStrategy::CmaEs;
  }
  return result;
}

RegistrationSchedule RegistrationSchedule::withSeed(std::uint32_t seed) const {
  RegistrationSchedule result = *this;
  for (std::size_t i = 0; i < result.stages.size(); ++i) {
    result.stages[i].genetic.seed = seed + static_cast<std::uint32_t>(i);
    result.stages[i].cmaes.seed = seed + static_cast<std::uint32_t>(i);
  }
  return result;
}

Result<RegistrationSchedule> RegistrationSchedule::withRoiPixels(int windowSize, double targetFraction) const {
  if (windowSize < 2 || windowSize > 64) {
    return fail(fmt::format("ROI window size {} px is outside 2 to 64 px; choose a window in that range", windowSize));
  }
  if (!(targetFraction > 0.0 && targetFraction <= 1.0)) {
    return fail(fmt::format("ROI fraction {} is outside (0, 1]; the paper keeps 0.10 to 0.15 of the pixels",
                            targetFraction));
  }
  RegistrationSchedule result = *this;
  for (RegistrationStage& stage : result.stages) {
    if (stage.pixels.kind != PixelSetKind::Rois) continue;
    stage.pixels.windowSize = windowSize;
    stage.pixels.targetFraction = targetFraction;
  }
  return result;
}

}  // namespace fct
