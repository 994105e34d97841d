#include "Evaluation/StudySetupFile.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cstdint>
#include <sstream>

#include "Base/TextFile.h"
#include "Drr/DrrRendererFactory.h"

namespace fct {

namespace fs = std::filesystem;

std::string StudySetupFile::text(const StudyDefinition& study, const std::vector<std::string>& ctPaths) {
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
                     "sad_mm: {:g}\nmethod: {}\ntransgraph_spacing_mm: {:g}\nseed: {}\n",
                     study.name, study.quick ? "yes" : "no",
                     ctPaths.empty() ? "default" : fmt::format("{}", fmt::join(ctPaths, " ")), preset, d.cols, d.rows,
                     d.pixelSpacing_mm, d.sourceToDetector_mm, d.sourceToIsocentre_mm,
                     DrrRendererFactory::methodName(setup.method), setup.transgraphSpacing_mm, setup.seed);
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
  std::string differences;
  std::istringstream was(stored.value()), now(setupText);
  for (std::string a, b; std::getline(now, b);) {
    if (!std::getline(was, a)) a = "(none)";
    if (a != b) differences += fmt::format("{}'{}' now, '{}' stored", differences.empty() ? "" : "; ", b, a);
  }
  for (std::string a; std::getline(was, a);) {
    differences += fmt::format("{}'(none)' now, '{}' stored", differences.empty() ? "" : "; ", a);
  }
  return fail(fmt::format("{} holds trials run with other options ({}); resume with the same options as in {}, or use "
                          "another output folder",
                          folder.string(), differences, file.string()));
}

}  // namespace fct
