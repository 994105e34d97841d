#include "Evaluation/StudySetupFile.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cstdint>
#include <sstream>
#include <string_view>

#include "Base/TextFile.h"
#include "Drr/DrrRendererFactory.h"

namespace fct {

namespace fs = std::filesystem;

namespace {

/// Each line that differs between setup texts `now` and `stored`, as "'now line' NOW_WORD, 'stored line' STORED_WORD"
/// joined by "; " ("(none)" for a line one of them lacks); empty when they are equal.
std::string differences(const std::string& now, const std::string& stored, std::string_view nowWord,
                        std::string_view storedWord) {
  std::string out;
  const auto add = [&](const std::string& a, const std::string& b) {
    out += fmt::format("{}'{}' {}, '{}' {}", out.empty() ? "" : "; ", b, nowWord, a, storedWord);
  };
  std::istringstream was(stored), is(now);
  for (std::string a, b; std::getline(is, b);) {
    if (!std::getline(was, a)) a = "(none)";
    if (a != b) add(a, b);
  }
  for (std::string a; std::getline(was, a);) add(a, "(none)");
  return out;
}

/// `setupText` without its shard line.
std::string withoutShard(const std::string& setupText) {
  const std::string prefix = std::string(StudySetupFile::kShardKey) + ": ";
  std::string out;
  std::istringstream lines(setupText);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(prefix, 0) != 0) out += line + "\n";
  }
  return out;
}

}  // namespace

std::string StudySetupFile::text(const StudyDefinition& study, const std::vector<std::string>& ctPaths,
                                 const StudyShard* shard) {
  const StudySetup& setup = study.setup;
  const StandardViewOptions& d = setup.detector;
  std::string preset = setup.preset;
  if (fs::is_regular_file(preset)) {  // a preset file: its text matters, not only its name
    auto text = TextFile::read(preset);
    if (text) {
      std::uint64_t hash = 14695981039346656037ull;  // FNV-1a of the file's text
      for (unsigned char c : text.value()) hash = (hash ^ c) * 1099511628211ull;
      preset += fmt::format(" (file, {} bytes, FNV-1a {:016x})", text.value().size(), hash);
    }
  }
  return fmt::format("study: {}\nquick: {}\ncts: {}\npreset: {}\ndetector: {}x{}\npixel_mm: {:g}\nsid_mm: {:g}\n"
                     "sad_mm: {:g}\nmethod: {}\ntransgraph_spacing_mm: {:g}\nseed: {}\nxrays: {}\n{}",
                     study.name, study.quick ? "yes" : "no",
                     ctPaths.empty() ? "default" : fmt::format("{}", fmt::join(ctPaths, " ")), preset, d.cols, d.rows,
                     d.pixelSpacing_mm, d.sourceToDetector_mm, d.sourceToIsocentre_mm,
                     DrrRendererFactory::methodName(setup.method), setup.transgraphSpacing_mm, setup.seed,
                     setup.xraysPerTrial ? "per trial" : "one set",
                     shard && shard->count() > 1
                         ? fmt::format("{}: {} of {} trials\n", kShardKey, shard->text(), shard->totalTrials())
                         : "");
}

Status StudySetupFile::checkOrWrite(const fs::path& folder, const std::string& setupText, bool hasTrials) {
  const fs::path file = folder / kFileName;
  if (!hasTrials) return TextFile::writeAtomically(file, setupText);
  auto stored = TextFile::read(file);
  if (!stored) {
    return fail(fmt::format("{} holds trials but no {} (made by an older fluoroct?), so the options it was run with "
                            "are unknown; use another output folder",
                            folder.string(), kFileName));
  }
  if (stored.value() == setupText) return Ok{};
  return fail(fmt::format("{} holds trials run with other options ({}); resume with the same options as in {}, or use "
                          "another output folder",
                          folder.string(), differences(setupText, stored.value(), "now", "stored"), file.string()));
}

Status StudySetupFile::checkShard(const fs::path& folder, const std::string& setupText) {
  const fs::path file = folder / kFileName;
  auto stored = TextFile::read(file);
  if (!stored) {
    return fail(fmt::format("{} has no {}, so it is not the output folder of a study shard (or made by an older "
                            "fluoroct); give the folders that `fluoroct evaluate --shard K/N --out DIR` wrote",
                            folder.string(), kFileName));
  }
  const std::string found = differences(setupText, withoutShard(stored.value()), "for the merge", "in the shard");
  if (found.empty()) return Ok{};
  return fail(fmt::format("shard folder {} was run with other options than this merge ({}); merge with the options the "
                          "shards were run with (see {}), and only shards of one study run",
                          folder.string(), found, file.string()));
}

}  // namespace fct
