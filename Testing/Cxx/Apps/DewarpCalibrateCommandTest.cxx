#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "IO/Project/DewarpFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Xray/ImageFileWriter.h"
#include "TestSupport.h"

namespace {

/// A one-view simulated case with pincushion and S-distortion and its grid plate image DIR/case/ap_grid.png.
void simulateDistortedCase(const std::filesystem::path& dir) {
  ASSERT_EQ(fct::test::runCli(fmt::format("phantom --out '{}' --dims 40 40 30 --spacing-mm 4", (dir / "ct.nrrd").string()))
                .exitCode,
            0);
  const auto views = fct::test::runCli(fmt::format("views --ct '{}' --out '{}' --count 1 --detector 192x144 --pixel-mm 0.8",
                                                   (dir / "ct.nrrd").string(), (dir / "views.json").string()));
  ASSERT_EQ(views.exitCode, 0) << views.err;
  ASSERT_TRUE(fct::PoseFile::write(Eigen::Isometry3d::Identity(), dir / "pose.json").ok());
  const auto simulated = fct::test::runCli(fmt::format(
      "simulate --model physical --ct '{}' --views '{}' --pose '{}' --out '{}' --pincushion 0.05 --s-distortion-deg 3 "
      "--dose 20000 --psf-px 0.7 --grid-pitch-mm 10",
      (dir / "ct.nrrd").string(), (dir / "views.json").string(), (dir / "pose.json").string(), (dir / "case").string()));
  ASSERT_EQ(simulated.exitCode, 0) << simulated.err;
  EXPECT_NE(simulated.out.find("ap_grid.png (dewarp calibration grid, pitch 10 mm)"), std::string::npos) << simulated.out;
  ASSERT_TRUE(std::filesystem::exists(dir / "case" / "ap_grid.png"));
}

/// Runs `command` and expects exit status 2 with exactly one line on stderr starting with "error: "; returns it.
std::string oneErrorLine(const std::string& command) {
  const auto run = fct::test::runCli(command);
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_EQ(run.err.rfind("error: ", 0), 0u) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  return run.err;
}

}  // namespace

TEST(DewarpCalibrateCommand, CalibratesTheSimulatedGridWithinAThirdOfAPixelAndWritesTheFile) {
  const auto dir = fct::test::workDir();
  simulateDistortedCase(dir);
  const auto out = dir / "ii.dewarp.json";
  const auto run = fct::test::runCli(fmt::format("dewarp-calibrate '{}' --pitch-mm 10 --pixel-spacing-mm 0.8 --out '{}'",
                                                 (dir / "case" / "ap_grid.png").string(), out.string()));
  ASSERT_EQ(run.exitCode, 0) << run.err << run.out;
  EXPECT_NE(run.out.find("cross-validated RMS"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("wrote"), std::string::npos) << run.out;
  auto read = fct::DewarpFile::read(out);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().field.cols(), 192);
  EXPECT_EQ(read.value().field.rows(), 144);
  EXPECT_EQ(read.value().calibration.gridImage, "ap_grid.png");
  EXPECT_LE(read.value().calibration.rmsResidual_px, 0.3);
  EXPECT_LE(read.value().calibration.maxResidual_px, 0.3);
  EXPECT_NEAR(read.value().calibration.magnification, 1000.0 / 980.0, 0.01);
}

TEST(DewarpCalibrateCommand, WrongPitchNoGridAndMissingImageAreOneLineErrorsThatWriteNothing) {
  const auto dir = fct::test::workDir();
  simulateDistortedCase(dir);
  const auto out = dir / "never.json";
  const std::string wrongPitch = oneErrorLine(fmt::format("dewarp-calibrate '{}' --pitch-mm 25 --pixel-spacing-mm 0.8 "
                                                          "--out '{}'",
                                                          (dir / "case" / "ap_grid.png").string(), out.string()));
  EXPECT_NE(wrongPitch.find("magnification"), std::string::npos) << wrongPitch;
  fct::FloatImage ramp = fct::FloatImage::filled(64, 48);
  for (int row = 0; row < 48; ++row) {
    for (int col = 0; col < 64; ++col) ramp.at(col, row) = 20000.0f + 300.0f * static_cast<float>(col);
  }
  ASSERT_TRUE(fct::ImageFileWriter::writePng16(ramp, dir / "blank.png", 0.0f, 65535.0f).ok());
  const std::string noGrid = oneErrorLine(
      fmt::format("dewarp-calibrate '{}' --pitch-mm 10 --pixel-spacing-mm 0.8 --out '{}'", (dir / "blank.png").string(),
                  out.string()));
  EXPECT_NE(noGrid.find("no calibration grid found"), std::string::npos) << noGrid;
  oneErrorLine(fmt::format("dewarp-calibrate '{}' --pitch-mm 10 --out '{}'", (dir / "absent.png").string(), out.string()));
  oneErrorLine(fmt::format("dewarp-calibrate '{}' --pitch-mm 0 --out '{}'", (dir / "case" / "ap_grid.png").string(),
                           out.string()));
  EXPECT_FALSE(std::filesystem::exists(out));
}
