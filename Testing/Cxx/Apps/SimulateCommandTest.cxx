#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "Base/JsonDocument.h"
#include "Base/TextFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "IO/Xray/XrayImageFileReader.h"
#include "TestSupport.h"

namespace {

/// Writes a small phantom, a 3-view file with a small detector and a pose into `dir`.
void makeInputs(const std::filesystem::path& dir) {
  ASSERT_EQ(fct::test::runCli(fmt::format("phantom --out '{}' --dims 40 40 30 --spacing-mm 4", (dir / "ct.nrrd").string()))
                .exitCode,
            0);
  const auto views = fct::test::runCli(fmt::format(
      "views --ct '{}' --out '{}' --count 3 --detector 100x80 --pixel-mm 3", (dir / "ct.nrrd").string(),
      (dir / "views.json").string()));
  ASSERT_EQ(views.exitCode, 0) << views.err;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(Eigen::Vector3d(2.0, -1.0, 3.0));
  ASSERT_TRUE(fct::PoseFile::write(pose, dir / "pose.json").ok());
}

/// The whole text of `path` ("" if unreadable; the expectations on its content then fail).
std::string fileText(const std::filesystem::path& path) {
  auto text = fct::TextFile::read(path);
  return text.ok() ? text.value() : std::string();
}

/// Runs `command` and expects exit status 2 with exactly one line on stderr starting with "error: ".
void expectOneErrorLine(const std::string& command) {
  const auto run = fct::test::runCli(command);
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_EQ(run.err.rfind("error: ", 0), 0u) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}

/// `simulate` with the inputs of makeInputs(dir) and output folder `out`.
std::string simulateCommand(const std::filesystem::path& dir, const std::filesystem::path& out) {
  return fmt::format("simulate --ct '{}' --views '{}' --pose '{}' --out '{}'", (dir / "ct.nrrd").string(),
                     (dir / "views.json").string(), (dir / "pose.json").string(), out.string());
}

}  // namespace

TEST(ViewsCommand, WritesStandardViewsAroundTheCtCentre) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  auto views = fct::ViewFile::read(dir / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(views.value().size(), 3u);
  EXPECT_EQ(views.value()[0].name, "ap");
  EXPECT_EQ(views.value()[1].name, "lateral");
  EXPECT_EQ(views.value()[2].name, "oblique45");
  EXPECT_TRUE(views.value()[1].imagePath.empty());
  EXPECT_EQ(views.value()[0].camera.intrinsics().cols, 100);
  EXPECT_EQ(views.value()[0].camera.intrinsics().rows, 80);
  EXPECT_DOUBLE_EQ(views.value()[0].camera.intrinsics().pixelSpacing_mm.x(), 3.0);
}

TEST(ViewsCommand, ImagesOptionNamesOneImagePerView) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto run = fct::test::runCli(fmt::format("views --ct '{}' --out '{}' --count 2 --images '{}'",
                                                 (dir / "ct.nrrd").string(), (dir / "named.json").string(),
                                                 (dir / "xray").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const std::string text = fileText(dir / "named.json");
  EXPECT_NE(text.find("\"path\": \"xray_ap.png\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"path\": \"xray_lateral.png\""), std::string::npos) << text;
}

TEST(SimulateCommand, WritesARegistrationCase) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto out = dir / "case";
  const auto run = fct::test::runCli(fmt::format(
      "simulate --ct '{}' --views '{}' --pose '{}' --out '{}' --noise-photons 2000 --seed 4 --method raycast",
      (dir / "ct.nrrd").string(), (dir / "views.json").string(), (dir / "pose.json").string(), out.string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  auto views = fct::ViewFile::read(out / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(views.value().size(), 3u);
  for (const auto& view : views.value()) {
    SCOPED_TRACE(view.name);
    EXPECT_EQ(view.imagePath, out / (view.name + ".png"));
    auto image = fct::XrayImageFileReader::read(view.imagePath);
    ASSERT_TRUE(image.ok()) << image.error();
    EXPECT_EQ(image.value().cols, 100);
    EXPECT_EQ(image.value().rows, 80);
    const auto [lo, hi] = std::minmax_element(image.value().pixels.begin(), image.value().pixels.end());
    EXPECT_LT(*lo, 20000.0f);  // the body attenuates
    EXPECT_GT(*hi, 55000.0f);  // air around it, about I0 = 60000 with noise
  }
  auto truth = fct::PoseFile::read(out / "truth_pose.json");
  ASSERT_TRUE(truth.ok()) << truth.error();
  EXPECT_NEAR(truth.value().translation().z(), 3.0, 1e-12);
  const std::string text = fileText(out / "simulation.json");
  EXPECT_NE(text.find("\"noise_photons\": 2000"), std::string::npos) << text;
  EXPECT_NE(text.find("\"method\": \"raycast\""), std::string::npos) << text;
}

TEST(SimulateCommand, FailsCleanlyOnBadInputs) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto out = dir / "case";
  const std::string base = simulateCommand(dir, out);
  for (const std::string& extra : {std::string(" --method magic"), std::string(" --noise-photons -5"),
                                   std::string(" --i0 70000"), std::string(" --i0 0")}) {
    SCOPED_TRACE(extra);
    expectOneErrorLine(base + extra);
  }
  const auto missingCt = fct::test::runCli(fmt::format("simulate --ct '{}' --views '{}' --pose '{}' --out '{}'",
                                                       (dir / "nope.nrrd").string(), (dir / "views.json").string(),
                                                       (dir / "pose.json").string(), out.string()));
  EXPECT_EQ(missingCt.exitCode, 2);
  EXPECT_NE(missingCt.err.find("nope.nrrd"), std::string::npos) << missingCt.err;
  const auto missingPose = fct::test::runCli(fmt::format("simulate --ct '{}' --views '{}' --pose '{}' --out '{}'",
                                                         (dir / "ct.nrrd").string(), (dir / "views.json").string(),
                                                         (dir / "none.json").string(), out.string()));
  EXPECT_EQ(missingPose.exitCode, 2);
  EXPECT_FALSE(std::filesystem::exists(out)) << "failed runs must not create the case folder";

  const auto badCount = fct::test::runCli(fmt::format("views --ct '{}' --out '{}' --count 7", (dir / "ct.nrrd").string(),
                                                      (dir / "v7.json").string()));
  EXPECT_EQ(badCount.exitCode, 2);
  EXPECT_NE(badCount.err.find("1..5"), std::string::npos) << badCount.err;
  const auto badDetector = fct::test::runCli(fmt::format("views --ct '{}' --out '{}' --detector 800by600",
                                                         (dir / "ct.nrrd").string(), (dir / "vd.json").string()));
  EXPECT_EQ(badDetector.exitCode, 2);
  EXPECT_NE(badDetector.err.find("COLSxROWS"), std::string::npos) << badDetector.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "v7.json"));
  EXPECT_FALSE(std::filesystem::exists(dir / "vd.json"));
}

TEST(SimulateCommand, PhysicalModelWritesObjectsSpheresDistortionFieldAndADegradedCt) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto out = dir / "physical";
  const auto run = fct::test::runCli(fmt::format(
      "simulate --ct '{}' --views '{}' --pose '{}' --out '{}' --model physical --kvp 75 --dose 2000 --psf-px 0.8 "
      "--pincushion 0.03 --vignetting 0.2 --collimator 1.1 --kwires 1 --screws 1 --plate --gas-pockets 1 --spheres "
      "--sphere-pitch-mm 50 --patient-extension-mm 30 --scatter-to-primary 0.2 --scatter-sigma-mm 25 "
      "--ct-slice-mm 8",
      (dir / "ct.nrrd").string(), (dir / "views.json").string(), (dir / "pose.json").string(), out.string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  auto views = fct::ViewFile::read(out / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(views.value().size(), 3u);
  for (const auto& view : views.value()) {
    SCOPED_TRACE(view.name);
    auto image = fct::XrayImageFileReader::read(view.imagePath);
    ASSERT_TRUE(image.ok()) << image.error();
    const auto [lo, hi] = std::minmax_element(image.value().pixels.begin(), image.value().pixels.end());
    EXPECT_EQ(*lo, 0.0f);       // outside the collimator
    EXPECT_GT(*hi, 30000.0f);   // the exposure reference maps to the gain, 50000
    EXPECT_FALSE(view.calibrationSpheres.empty());
    EXPECT_TRUE(std::filesystem::exists(out / (view.name + "_distortion_dcol.nrrd")));
  }
  auto degraded = fct::test::runCli(fmt::format("info '{}'", (out / "ct_registration.nrrd").string()));
  ASSERT_EQ(degraded.exitCode, 0) << degraded.err;
  EXPECT_NE(degraded.out.find("4 x 4 x 8 mm"), std::string::npos) << degraded.out;
  const std::string text = fileText(out / "simulation.json");
  EXPECT_NE(text.find("\"model\": \"physical\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"tube_voltage_kvp\": 75"), std::string::npos) << text;
  EXPECT_NE(text.find("\"slice_spacing_mm\": 8"), std::string::npos) << text;
  EXPECT_NE(text.find("\"kind\": \"plate\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"kind\": \"gas_pocket\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"patient_extension_mm\": 30"), std::string::npos) << text;
  EXPECT_NE(text.find("\"scatter_to_primary\": 0.2"), std::string::npos) << text;
  EXPECT_NE(text.find("\"scatter_sigma_mm\": 25"), std::string::npos) << text;
}

TEST(SimulateCommand, MonochromaticBeamReplacesTheSpectrumAndIsRecorded) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto out = dir / "mono";
  const auto run = fct::test::runCli(simulateCommand(dir, out) + " --model physical --monochromatic-kev 60");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const std::string text = fileText(out / "simulation.json");
  EXPECT_NE(text.find("\"monochromatic_kev\": 60"), std::string::npos) << text;
  EXPECT_NE(text.find("\"spectrum\": \"monochromatic 60 keV\""), std::string::npos) << text;
}

TEST(SimulateCommand, PhysicalModelFailsCleanlyOnBadOptions) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto out = dir / "case";
  const std::string base = simulateCommand(dir, out);
  for (const std::string& extra :
       {std::string(" --model physical --kvp 200"), std::string(" --model physical --dose -1"),
        std::string(" --model physical --pincushion 0.5"), std::string(" --model physical --method raycast"),
        std::string(" --kwires 2"), std::string(" --model xray"), std::string(" --model physical --ct-slice-mm 2"),
        std::string(" --model physical --patient-extension-mm -5"), std::string(" --model physical --scatter-to-primary 6"),
        std::string(" --model physical --scatter-sigma-mm 0.5"), std::string(" --scatter-to-primary 0.1"),
        std::string(" --model physical --monochromatic-kev 5"), std::string(" --monochromatic-kev 60")}) {
    SCOPED_TRACE(extra);
    expectOneErrorLine(base + extra);
  }
  EXPECT_FALSE(std::filesystem::exists(out)) << "failed runs must not create the case folder";
  std::ofstream(dir / "scaled.json") << R"({"T_world_from_ct": [[2,0,0,0],[0,2,0,0],[0,0,2,0],[0,0,0,1]]})";
  const auto notRigid = fct::test::runCli(fmt::format("simulate --ct '{}' --views '{}' --pose '{}' --out '{}' --model physical",
                                                      (dir / "ct.nrrd").string(), (dir / "views.json").string(),
                                                      (dir / "scaled.json").string(), out.string()));
  EXPECT_EQ(notRigid.exitCode, 2);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(SimulateCommand, GasPocketsWithoutSoftTissueNameTheOption) {
  const auto dir = fct::test::workDir();
  // Solid bone: no soft tissue anywhere for a gas pocket.
  const auto bone = fct::Volume::create(Eigen::Vector3i(20, 20, 20), Eigen::Vector3d::Constant(4.0),
                                        Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 1000.0f);
  ASSERT_TRUE(bone.ok()) << bone.error();
  ASSERT_TRUE(fct::VolumeFileIO::write(bone.value(), dir / "ct.nrrd").ok());
  const auto views = fct::test::runCli(fmt::format("views --ct '{}' --out '{}' --count 1 --detector 40x40 --pixel-mm 4",
                                                   (dir / "ct.nrrd").string(), (dir / "views.json").string()));
  ASSERT_EQ(views.exitCode, 0) << views.err;
  ASSERT_TRUE(fct::PoseFile::write(Eigen::Isometry3d::Identity(), dir / "pose.json").ok());
  const auto run = fct::test::runCli(simulateCommand(dir, dir / "case") + " --model physical --gas-pockets 1");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_EQ(run.err.rfind("error: --gas-pockets: found no soft tissue near the bone", 0), 0u) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}

TEST(SimulateCommand, FramesWriteASequenceCaseThatTrackReads) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto out = dir / "sequence";
  const auto run = fct::test::runCli(simulateCommand(dir, out) +
                                     " --model physical --frames 4 --motion-mm 6 --motion-deg 4 --jerk-frame 2 "
                                     "--jerk-mm 3 --jerk-deg 1 --motion-period-frames 8 --noise-photons 5000");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("4 frames; track it with fluoroct track"), std::string::npos) << run.out;

  auto views = fct::ViewFile::read(out / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(views.value().size(), 3u);
  for (const fct::ViewSpec& view : views.value()) {
    ASSERT_TRUE(view.sequence.has_value()) << view.name;
    ASSERT_EQ(view.sequence->frameCount(), 4) << view.name;
    for (int f = 0; f < 4; ++f) {
      auto image = fct::XrayImageFileReader::read(view.sequence->frame(f).first);
      ASSERT_TRUE(image.ok()) << image.error();
      EXPECT_EQ(image.value().cols, 100);
      EXPECT_EQ(image.value().rows, 80);
    }
  }
  // The true poses: frame 0 in truth_pose.json, every frame in truth_track.json; the bone centre moves between frames
  // and stays within the bound (6 mm per axis) of the base pose.
  auto first = fct::PoseFile::read(out / "truth_pose.json");
  ASSERT_TRUE(first.ok()) << first.error();
  auto truth = fct::JsonDocument::parse(out / "truth_track.json");
  ASSERT_TRUE(truth.ok()) << truth.error();
  EXPECT_EQ(truth.value().at("jerk_frame"), 2);
  const auto& frames = truth.value().at("frames");
  ASSERT_EQ(frames.size(), 4u);
  Eigen::Vector3d centre_ct_mm;
  for (int i = 0; i < 3; ++i) centre_ct_mm[i] = truth.value().at("rotation_centre_ct_mm")[i].get<double>();
  auto base = fct::PoseFile::read(dir / "pose.json");
  ASSERT_TRUE(base.ok());
  std::vector<Eigen::Vector3d> centres_world_mm;
  for (const auto& frame : frames) {
    Eigen::Matrix4d T;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) T(r, c) = frame.at("T_world_from_ct")[r][c].get<double>();
    }
    centres_world_mm.push_back((T * centre_ct_mm.homogeneous()).head<3>());
    EXPECT_LE((centres_world_mm.back() - base.value() * centre_ct_mm).cwiseAbs().maxCoeff(), 6.0 + 1e-9);
  }
  EXPECT_TRUE(((first.value() * centre_ct_mm) - centres_world_mm.front()).norm() < 1e-6);
  EXPECT_GT((centres_world_mm[3] - centres_world_mm[0]).norm(), 0.5) << "the bone moved (with a 3 mm jerk)";
  const auto image0 = fct::XrayImageFileReader::read(views.value()[0].sequence->frame(0).first);
  const auto image3 = fct::XrayImageFileReader::read(views.value()[0].sequence->frame(3).first);
  ASSERT_TRUE(image0.ok() && image3.ok());
  EXPECT_NE(image0.value().pixels, image3.value().pixels) << "the bone moved, and every frame has its own noise";
}

TEST(SimulateCommand, FramesFailCleanlyOnOptionsThatDoNotApply) {
  const auto dir = fct::test::workDir();
  makeInputs(dir);
  const auto out = dir / "sequence";
  const std::string base = simulateCommand(dir, out);
  for (const std::string& extra :
       {std::string(" --frames 3"), std::string(" --model physical --frames 3 --grid-pitch-mm 5"),
        std::string(" --model physical --frames 3 --ct-slice-mm 8"), std::string(" --model physical --frames 3 --motion-deg 60"),
        std::string(" --model physical --frames -2")}) {
    SCOPED_TRACE(extra);
    expectOneErrorLine(base + extra);
  }
  EXPECT_FALSE(std::filesystem::exists(out)) << "failed runs must not create the case folder";
}
