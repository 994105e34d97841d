#pragma once
// The small simulated phantom case the CLI tests register (made with `fluoroct phantom`, `views` and `simulate`),
// and the check of the CLI's one-line errors.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <filesystem>

#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
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

/// A small simulated biplane sequence in `dir` for `fluoroct track`: ct.nrrd, `frames` frames of 128x128 at 2.4 mm
/// (frame f simulated into frame<f>/ with the bone moved by f * (1, -0.5, 0.5) mm and turned by f * 0.4 deg), and
/// track_views.json whose views give the frames as "sequence" lists. Returns the true pose of every frame.
inline std::vector<Eigen::Isometry3d> makeTrackCase(const std::filesystem::path& dir, int frames) {
  auto run = runCli(fmt::format("phantom --out '{}' --dims 80 80 60 --spacing-mm 2", (dir / "ct.nrrd").string()));
  EXPECT_EQ(run.exitCode, 0) << run.err;
  run = runCli(fmt::format("views --ct '{}' --out '{}' --count 2 --detector 128x128 --pixel-mm 2.4 --sid-mm 1000 "
                           "--sad-mm 700",
                           (dir / "ct.nrrd").string(), (dir / "views.json").string()));
  EXPECT_EQ(run.exitCode, 0) << run.err;
  std::vector<Eigen::Isometry3d> truth;
  for (int f = 0; f < frames; ++f) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(0.007 * f, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    pose.translation() = Eigen::Vector3d(2.0 + f, -1.0 - 0.5 * f, 3.0 + 0.5 * f);
    const std::filesystem::path poseFile = dir / fmt::format("truth{}.json", f);
    EXPECT_TRUE(PoseFile::write(pose, poseFile).ok());
    run = runCli(fmt::format("simulate --ct '{}' --views '{}' --pose '{}' --out '{}' --model physical "
                             "--noise-photons 20000 --seed {}",
                             (dir / "ct.nrrd").string(), (dir / "views.json").string(), poseFile.string(),
                             (dir / fmt::format("frame{}", f)).string(), 1 + 2 * f));
    EXPECT_EQ(run.exitCode, 0) << run.err;
    truth.push_back(pose);
  }
  auto views = ViewFile::read(dir / "frame0" / "views.json");
  EXPECT_TRUE(views.ok()) << views.error();
  for (ViewSpec& view : views.value()) {
    ViewSequence sequence;
    for (int f = 0; f < frames; ++f) sequence.files.push_back(dir / fmt::format("frame{}", f) / (view.name + ".png"));
    view.sequence = std::move(sequence);
  }
  EXPECT_TRUE(ViewFile::write(views.value(), dir / "track_views.json").ok());
  return truth;
}

/// True when the command failed with status 2 and printed exactly one line "error: ..." on stderr.
inline bool oneErrorLine(const ProcessResult& run) {
  return run.exitCode == 2 && run.err.rfind("error: ", 0) == 0 && std::count(run.err.begin(), run.err.end(), '\n') == 1;
}

}  // namespace fct::test
