#include "StudioTestCase.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "TestSupport.h"

namespace fct::test {

namespace {

std::filesystem::path buildCase() {
  const auto dir = std::filesystem::temp_directory_path() / "fluoroct_tests" / "studio_case";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string d = dir.string();
  const std::string commands[] = {
      fmt::format("phantom --out '{}/ct.nrrd' --dims 96 96 72 --spacing-mm 1.6", d),
      fmt::format("views --ct '{0}/ct.nrrd' --out '{0}/camera.json' --count 2 --detector 192x144 --pixel-mm 1.6", d),
      fmt::format("pose --ct '{0}/ct.nrrd' --rotate-deg 5 -3 4 --translate-mm 6 -4 5 --out '{0}/truth.json'", d),
      fmt::format("simulate --ct '{0}/ct.nrrd' --views '{0}/camera.json' --pose '{0}/truth.json' --out '{0}' "
                  "--noise-photons 20000 --seed 1",
                  d),
      fmt::format("pose --ct '{0}/ct.nrrd' --from '{0}/truth_pose.json' --random-offset-mm 8 --seed 3 "
                  "--out '{0}/initial_pose.json'",
                  d),
  };
  for (const std::string& command : commands) {
    const ProcessResult r = runCli(command);
    if (r.exitCode != 0) {
      ADD_FAILURE() << "fluoroct " << command << " failed: " << r.err;
      return {};
    }
  }
  return dir;
}

}  // namespace

const std::filesystem::path& builtinCaseDir() {
  static const std::filesystem::path dir = buildCase();
  return dir;
}

}  // namespace fct::test
