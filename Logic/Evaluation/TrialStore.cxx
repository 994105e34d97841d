#include "Evaluation/TrialStore.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>

#include "Base/NameTable.h"
#include "Base/TextFile.h"

namespace fct {

namespace {

/// The CSV names of the statuses.
constexpr NameTable<TrialStatus, 3> kStatusNames{
    {{"ok", TrialStatus::Ok}, {"failed", TrialStatus::Failed}, {"cancelled", TrialStatus::Cancelled}}};

std::string number(double value) {
  if (std::isnan(value)) return "nan";
  return fmt::format("{:.6g}", value);
}

/// Splits one CSV line into fields (RFC 4180 quoting, no embedded line breaks).
std::vector<std::string> splitLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool inQuotes = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (inQuotes) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        inQuotes = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      inQuotes = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

bool parseDouble(const std::string& text, double& out) {
  if (text == "nan") {
    out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size();
}

template <typename Int>
bool parseInt(const std::string& text, Int& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size() && !text.empty();
}

}  // namespace

std::string_view trialStatusName(TrialStatus status) { return nameOf(status, kStatusNames); }

std::string TrialStore::csvField(const std::string& field) {
  if (field.find_first_of(",\"\n\r") == std::string::npos) return field;
  std::string out = "\"";
  for (char c : field) {
    if (c == '"') out += '"';
    out += c == '\n' || c == '\r' ? ' ' : c;
  }
  return out + "\"";
}

Result<TrialStatus> parseTrialStatus(std::string_view text) {
  if (const auto status = valueNamed(text, kStatusNames)) return *status;
  return fail(fmt::format("unknown trial status '{}'; the status is ok, failed or cancelled", text));
}

const std::vector<std::string>& TrialStore::columns() {
  static const std::vector<std::string> kColumns{
      "study",        "ct",           "condition",       "scenario",          "variant",         "views",
      "trial",        "seed",         "truth_offset_mm", "initial_target_mm", "initial_stre_mm", "stre_mean_mm",
      "stre_max_mm",  "mtre_mm",      "rotation_deg",    "translation_mm",    "success",         "seconds",
      "setup_seconds", "drrs",        "status",          "reason"};
  return kColumns;
}

std::string TrialStore::toCsv(const std::vector<TrialRecord>& records) {
  std::string text;
  for (std::size_t c = 0; c < columns().size(); ++c) text += (c ? "," : "") + columns()[c];
  text += '\n';
  for (const TrialRecord& r : records) {
    text += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", csvField(r.study),
                        csvField(r.ct), csvField(r.condition), csvField(r.scenario), csvField(r.variant), r.views,
                        r.trial, r.seed, number(r.truthOffset_mm), number(r.initialTarget_mm), number(r.initialStre_mm), number(r.error.streMean_mm),
                        number(r.error.streMax_mm), number(r.error.mtre_mm), number(r.error.rotation_deg),
                        number(r.error.translation_mm), r.success ? 1 : 0, number(r.seconds), number(r.setupSeconds), r.drrs,
                        trialStatusName(r.status), csvField(r.reason));
  }
  return text;
}

Result<std::vector<TrialRecord>> TrialStore::fromCsv(const std::string& text, const std::string& where) {
  std::vector<TrialRecord> records;
  std::size_t start = 0;
  int lineNumber = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    ++lineNumber;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::vector<std::string> f = splitLine(line);
    if (lineNumber == 1) {
      if (f != columns()) {
        return fail(fmt::format("{}: the header is not that of a FluoroCT trials file ({} columns expected, starting "
                                "'study,ct,condition'); use another output folder or delete the file",
                                where, columns().size()));
      }
      continue;
    }
    if (f.size() != columns().size()) {
      return fail(fmt::format("{} line {}: {} fields, expected {}; fix or delete the line to resume", where, lineNumber,
                              f.size(), columns().size()));
    }
    TrialRecord r;
    r.study = f[0];
    r.ct = f[1];
    r.condition = f[2];
    r.scenario = f[3];
    r.variant = f[4];
    int success = 0;
    const bool ok = parseInt(f[5], r.views) && parseInt(f[6], r.trial) && parseInt(f[7], r.seed) &&
                    parseDouble(f[8], r.truthOffset_mm) && parseDouble(f[9], r.initialTarget_mm) && parseDouble(f[10], r.initialStre_mm) &&
                    parseDouble(f[11], r.error.streMean_mm) && parseDouble(f[12], r.error.streMax_mm) &&
                    parseDouble(f[13], r.error.mtre_mm) && parseDouble(f[14], r.error.rotation_deg) &&
                    parseDouble(f[15], r.error.translation_mm) && parseInt(f[16], success) &&
                    parseDouble(f[17], r.seconds) && parseDouble(f[18], r.setupSeconds) && parseInt(f[19], r.drrs);
    if (!ok) {
      return fail(fmt::format("{} line {}: a number field cannot be read; fix or delete the line to resume", where,
                              lineNumber));
    }
    auto status = parseTrialStatus(f[20]);
    if (!status) {
      return fail(fmt::format("{} line {}: {}; fix or delete the line to resume", where, lineNumber, status.error()));
    }
    r.success = success != 0;
    r.status = status.value();
    r.reason = f[21];
    records.push_back(std::move(r));
  }
  return records;
}

Result<TrialStore> TrialStore::open(const std::filesystem::path& csvPath) {
  TrialStore store;
  store.m_path = csvPath;
  std::error_code ec;
  if (!std::filesystem::exists(csvPath, ec)) return store;
  auto text = TextFile::read(csvPath);
  if (!text) return fail(text.error());
  auto records = fromCsv(text.value(), csvPath.string());
  if (!records) return fail(records.error());
  store.m_records = std::move(records).value();
  return store;
}

bool TrialStore::isDone(const std::string& study, const std::string& condition, int trial) const {
  for (const TrialRecord& r : m_records) {
    if (r.study == study && r.condition == condition && r.trial == trial) {
      return r.status == TrialStatus::Ok || r.status == TrialStatus::Failed;
    }
  }
  return false;
}

Status TrialStore::add(const TrialRecord& record) {
  bool replaced = false;
  for (TrialRecord& r : m_records) {
    if (r.study == record.study && r.condition == record.condition && r.trial == record.trial) {
      r = record;
      replaced = true;
    }
  }
  if (!replaced) m_records.push_back(record);
  return TextFile::writeAtomically(m_path, toCsv(m_records));
}

}  // namespace fct
