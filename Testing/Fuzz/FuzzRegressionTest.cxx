// Replays, through the fuzz entry points, every kept input of Testing/Fuzz/regressions/<target>/ (inputs that once
// crashed a loader, minimized), the seeds the project's writers make and the crafted inputs of fixed defects (FuzzSeedWriter), and a few real files of ../shared/data: none
// may crash, hang or break a loader's contract (that aborts the program).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "FuzzSeedWriter.h"
#include "FuzzStudioTargets.h"
#include "FuzzTargets.h"
#include "TestSupport.h"

namespace fs = std::filesystem;
using fct::fuzz::FuzzTarget;

namespace {

std::vector<FuzzTarget> allTargets() {
  std::vector<FuzzTarget> targets = fct::fuzz::loaderTargets();
  const auto& studio = fct::fuzz::studioTargets();
  targets.insert(targets.end(), studio.begin(), studio.end());
  return targets;
}

/// The seeds the project's writers make, written once per test program into the first test's own folder (CTest runs
/// the targets as parallel processes, which must not share a folder).
const fs::path& writtenSeeds() {
  static const fs::path root = [] {
    const fs::path folder = fct::test::scratchDir() / "fuzz_seeds";
    std::error_code ec;
    fs::remove_all(folder, ec);
    const fct::Status loaders = fct::fuzz::writeLoaderSeeds(folder);
    const fct::Status studio = fct::fuzz::writeStudioSeeds(folder);
    EXPECT_TRUE(loaders.ok()) << loaders.error();
    EXPECT_TRUE(studio.ok()) << studio.error();
    return folder;
  }();
  return root;
}

/// Real files of ../shared/data that seed a target with no writer in the project (absent data: none).
std::vector<fs::path> sharedDataInputsOf(const std::string& target) {
  std::error_code ec;
  if (target == "nifti" && fs::exists(fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz", ec)) {
    return {fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz"};
  }
  const fs::path series = fct::test::dataDir() / "ct/head_phantom_philips_bone";
  if (target != "dicom_slice" || !fs::is_directory(series, ec)) return {};
  std::vector<fs::path> slices;
  for (const auto& entry : fs::directory_iterator(series)) {
    if (entry.is_regular_file()) slices.push_back(entry.path());
  }
  std::sort(slices.begin(), slices.end());
  return slices.empty() ? slices : std::vector<fs::path>{slices.front()};
}

std::vector<fs::path> inputsOf(const std::string& target) {
  std::vector<fs::path> inputs = sharedDataInputsOf(target);
  for (const fs::path& root : {fs::path(FCT_FUZZ_DIR) / "regressions", writtenSeeds()}) {
    std::error_code ec;
    if (!fs::is_directory(root / target, ec)) continue;
    for (const auto& entry : fs::directory_iterator(root / target)) {
      if (entry.is_regular_file()) inputs.push_back(entry.path());
    }
  }
  return inputs;
}

}  // namespace

namespace fct::fuzz {
/// Prints a target by its name in test names and messages.
void PrintTo(const FuzzTarget& target, std::ostream* out) { *out << target.name; }
}  // namespace fct::fuzz

namespace {

class FuzzRegressions : public ::testing::TestWithParam<FuzzTarget> {};

}  // namespace

TEST_P(FuzzRegressions, ReplaysEveryKeptInputWithoutACrash) {
  const FuzzTarget target = GetParam();
  const std::vector<fs::path> inputs = inputsOf(target.name);
  if (inputs.empty() && std::string(target.name) == "dicom_slice") {
    GTEST_SKIP() << "the dicom_slice target is seeded from ../shared/data (ct/head_phantom_philips_bone), not found under "
                 << fct::test::dataDir();
  }
  ASSERT_FALSE(inputs.empty()) << "no regression or seed input for the fuzz target '" << target.name
                               << "'; add one to FuzzSeedWriter or under Testing/Fuzz/regressions/" << target.name << "/";
  for (const fs::path& input : inputs) {
    std::ifstream in(input, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(target.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0) << input;
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzRegressions, ::testing::ValuesIn(allTargets()),
                         [](const ::testing::TestParamInfo<FuzzTarget>& info) { return std::string(info.param.name); });
