#pragma once
// The built-in case for the widget tests: a small phantom CT and two simulated C-arm views at a known pose, made
// once per test run with the fluoroct CLI, in the case-folder layout fluoroct-studio --case reads
// (ct.nrrd, views.json with the X-ray images, truth_pose.json, initial_pose.json).

#include <filesystem>

namespace fct::test {

/// The folder of the built-in case (built on first call; an empty path if the CLI failed, with a test failure).
const std::filesystem::path& builtinCaseDir();

}  // namespace fct::test
