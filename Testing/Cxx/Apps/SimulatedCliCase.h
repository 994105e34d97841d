#pragma once
// The small simulated phantom case the CLI tests register (made with `fluoroct phantom`, `views` and `simulate`),
// and the check of the CLI's one-line errors.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <filesystem>

#include "IO/Project/PoseFile.h"
#include "TestSupport.h"

namespace fct::test {

/// A small simulated phantom case in `dir`: ct.nrrd, views.json (3 views, 160x160 at 2 mm), sim/ (images, view file,
/// truth pose). Returns the truth pose.
inline Eigen::Isometry3d makeCase(const std::filesystem::path& dir) {
  auto run = runCli(fmt::format("phantom --out '{}' --dims 80 80 60 --spacing-mm 2", (dir / "ct.nrrd").string()));
  EXPECT_EQ(run.exitCode, 0) << run.err;
  run = runCli(fmt::format("views --ct '{}' --out '{}' --detector 160x160 --pixel-mm 2 --sid-mm 1000 --sad-mm 700",
                           (dir / "ct.nrrd").string(), (dir / "views.json").string()));
  EXPECT_EQ(run.exitCode, 0) << run.err;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  truth.translation() = Eigen::Vector3d(2.0, -1.0, 3.0);
  EXPECT_TRUE(PoseFile::write(truth, dir / "truth.json").ok());
  run = runCli(fmt::format("simulate --ct '{}' --views '{}' --pose '{}' --out '{}' --noise-photons 3000",
                           (dir / "ct.nrrd").string(), (dir / "views.json").string(), (dir / "truth.json").string(),
                           (dir / "sim").string()));
  EXPECT_EQ(run.exitCode, 0) << run.err;
  return truth;
}

/// The truth moved by about 2.7 mm and 1.7 degrees: a start the fast preset recovers from.
inline Eigen::Isometry3d perturbed(const Eigen::Isometry3d& truth) {
  Eigen::Isometry3d start = truth;
  start.translation() += Eigen::Vector3d(2.0, -1.5, 1.0);
  start.linear() = Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ()).toRotationMatrix() * start.linear();
  return start;
}

/// True when the command failed with status 2 and printed exactly one line "error: ..." on stderr.
inline bool oneErrorLine(const ProcessResult& run) {
  return run.exitCode == 2 && run.err.rfind("error: ", 0) == 0 && std::count(run.err.begin(), run.err.end(), '\n') == 1;
}

}  // namespace fct::test
