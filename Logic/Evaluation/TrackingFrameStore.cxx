#include "Evaluation/TrackingFrameStore.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "Base/JsonDocument.h"
#include "Base/TextFile.h"
#include "Evaluation/TrialStore.h"

namespace fct {

namespace {

constexpr const char* kJsonName = "frames.json";
constexpr const char* kCsvName = "frames.csv";

/// JSON has no NaN: a NaN error (a failed frame) is stored as null and read back as NaN.
nlohmann::ordered_json number(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
}

double numberFrom(const nlohmann::json& j, const char* key) {
  const nlohmann::json& v = j.at(key);
  return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>();
}

nlohmann::ordered_json toJson(const TrackingFrameRecord& r) {
  return {{"condition", r.condition},
          {"ct", r.ct},
          {"views", r.views},
          {"sequence", r.sequence},
          {"frames", r.frames},
          {"frame", r.frame},
          {"seed", r.seed},
          {"status", r.status},
          {"cancelled", r.cancelled},
          {"similarity", number(r.similarity)},
          {"seconds", number(r.seconds)},
          {"cpu_seconds", number(r.cpuSeconds)},
          {"drrs", r.drrs},
          {"motion_from_first_mm", number(r.motionFromFirst_mm)},
          {"initial_stre_mm", number(r.initialStre_mm)},
          {"stre_mean_mm", number(r.streMean_mm)},
          {"stre_max_mm", number(r.streMax_mm)},
          {"in_plane_mm", number(r.inPlane_mm)},
          {"out_of_plane_mm", number(r.outOfPlane_mm)},
          {"rotation_deg", number(r.rotation_deg)},
          {"translation_mm", number(r.translation_mm)},
          {"reason", r.reason}};
}

TrackingFrameRecord fromJson(const nlohmann::json& j) {
  TrackingFrameRecord r;
  r.condition = j.at("condition").get<std::string>();
  r.ct = j.at("ct").get<std::string>();
  r.views = j.at("views").get<int>();
  r.sequence = j.at("sequence").get<int>();
  r.frames = j.at("frames").get<int>();
  r.frame = j.at("frame").get<int>();
  r.seed = j.at("seed").get<std::uint32_t>();
  r.status = j.at("status").get<std::string>();
  r.cancelled = j.at("cancelled").get<bool>();
  r.similarity = numberFrom(j, "similarity");
  r.seconds = numberFrom(j, "seconds");
  r.cpuSeconds = numberFrom(j, "cpu_seconds");
  r.drrs = j.at("drrs").get<long>();
  r.motionFromFirst_mm = numberFrom(j, "motion_from_first_mm");
  r.initialStre_mm = numberFrom(j, "initial_stre_mm");
  r.streMean_mm = numberFrom(j, "stre_mean_mm");
  r.streMax_mm = numberFrom(j, "stre_max_mm");
  r.inPlane_mm = numberFrom(j, "in_plane_mm");
  r.outOfPlane_mm = numberFrom(j, "out_of_plane_mm");
  r.rotation_deg = numberFrom(j, "rotation_deg");
  r.translation_mm = numberFrom(j, "translation_mm");
  r.reason = j.at("reason").get<std::string>();
  return r;
}

std::string field(const std::string& text) { return TrialStore::csvField(text); }

std::string csvNumber(double value) { return std::isnan(value) ? "nan" : fmt::format("{:.6g}", value); }

}  // namespace

Result<TrackingFrameStore> TrackingFrameStore::open(const std::filesystem::path& dir) {
  TrackingFrameStore store;
  store.m_dir = dir;
  const std::filesystem::path path = dir / kJsonName;
  if (!std::filesystem::exists(path)) return store;
  auto document = JsonDocument::parse(path);
  if (!document) return fail(document.error());
  try {
    for (const nlohmann::json& frame : document.value().at("frames")) store.m_records.push_back(fromJson(frame));
  } catch (const nlohmann::json::exception& e) {
    return fail(fmt::format("{}: not a tracking study's frame list ({}); move it away to start the study again",
                            path.string(), e.what()));
  }
  return store;
}

bool TrackingFrameStore::isDone(const std::string& condition, int sequence) const {
  int stored = 0, expected = -1;
  for (const TrackingFrameRecord& r : m_records) {
    if (r.condition != condition || r.sequence != sequence) continue;
    if (r.cancelled) return false;
    ++stored;
    expected = r.frames;
  }
  return stored > 0 && stored == expected;
}

Status TrackingFrameStore::addSequence(const std::vector<TrackingFrameRecord>& frames) {
  if (frames.empty()) return Ok{};
  const std::string& condition = frames.front().condition;
  const int sequence = frames.front().sequence;
  const auto sameSequence = [&](const TrackingFrameRecord& r) {
    return r.condition == condition && r.sequence == sequence;
  };
  m_records.erase(std::remove_if(m_records.begin(), m_records.end(), sameSequence), m_records.end());
  m_records.insert(m_records.end(), frames.begin(), frames.end());

  nlohmann::ordered_json document;
  document["frames"] = nlohmann::ordered_json::array();
  for (const TrackingFrameRecord& r : m_records) document["frames"].push_back(toJson(r));
  if (Status saved = JsonDocument::write(document, m_dir / kJsonName); !saved) return saved;
  return TextFile::writeAtomically(m_dir / kCsvName, toCsv(m_records));
}

std::string TrackingFrameStore::toCsv(const std::vector<TrackingFrameRecord>& records) {
  std::string out =
      "condition,ct,views,sequence,frames,frame,seed,status,cancelled,similarity,seconds,cpu_seconds,drrs,"
      "motion_from_first_mm,initial_stre_mm,stre_mean_mm,stre_max_mm,in_plane_mm,out_of_plane_mm,rotation_deg,"
      "translation_mm,reason\n";
  for (const TrackingFrameRecord& r : records) {
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", field(r.condition),
                       field(r.ct), r.views, r.sequence, r.frames, r.frame, r.seed, r.status, r.cancelled ? 1 : 0,
                       csvNumber(r.similarity), csvNumber(r.seconds), csvNumber(r.cpuSeconds), r.drrs,
                       csvNumber(r.motionFromFirst_mm), csvNumber(r.initialStre_mm), csvNumber(r.streMean_mm),
                       csvNumber(r.streMax_mm), csvNumber(r.inPlane_mm), csvNumber(r.outOfPlane_mm),
                       csvNumber(r.rotation_deg), csvNumber(r.translation_mm), field(r.reason));
  }
  return out;
}

}  // namespace fct
