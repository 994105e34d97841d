#include "StudioTestCase.h"

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "TestSupport.h"

namespace fct::test {

namespace {

namespace fs = std::filesystem;

/// Makes the case in `dir` with the CLI; false (with a test failure) if a command fails.
bool makeCase(const fs::path& dir) {
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
      return false;
    }
  }
  return true;
}

/// The case is shared by every test process of a run (CTest runs each test in its own process, in parallel): it is
/// made in a private folder and renamed into place, named after the CLI's build time so a rebuilt CLI remakes it.
fs::path buildCase() {
  std::error_code ec;
  const auto stamp = fs::last_write_time(cliPath(), ec).time_since_epoch().count();
  const fs::path root = fs::temp_directory_path() / "fluoroct_tests";
  const fs::path dir = root / fmt::format("studio_case_{}", stamp);
  if (fs::exists(dir / "initial_pose.json", ec)) return dir;
  const fs::path scratch = root / fmt::format("studio_case_{}.{}", stamp, ::getpid());
  fs::remove_all(scratch, ec);
  fs::create_directories(scratch);
  if (!makeCase(scratch)) return {};
  fs::rename(scratch, dir, ec);  // fails when another process was first: use its case
  fs::remove_all(scratch, ec);
  return fs::exists(dir / "initial_pose.json", ec) ? dir : fs::path();
}

}  // namespace

const std::filesystem::path& builtinCaseDir() {
  static const std::filesystem::path dir = buildCase();
  return dir;
}

}  // namespace fct::test
