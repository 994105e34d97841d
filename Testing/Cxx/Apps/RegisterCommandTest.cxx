// fluoroct register: end to end on a case made by `fluoroct phantom`, `views` and `simulate`, from a pose file and
// from landmarks; and its errors.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>

#include "Base/JsonDocument.h"
#include "IO/Dicom/DicomRegistrationReader.h"
#include "IO/Project/LandmarkFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationResultJson.h"
#include "SimulatedCliCase.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using fct::test::makeCase;
using fct::test::oneErrorLine;
using fct::test::perturbed;

}  // namespace

TEST(RegisterCommand, RegistersASimulatedCaseFromAPoseFileAndWritesTheResult) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(perturbed(truth), dir / "init.json").ok());
  ASSERT_TRUE(fct::PoseFile::write(truth, dir / "truth.json").ok());
  const auto run = fct::test::runCli(fmt::format(
      "register --ct '{}' --views '{}' --init '{}' --preset fast --seed 3 --out '{}' --progress --overlays '{}' "
      "--truth '{}' --masks '{}'",
      (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "init.json").string(),
      (dir / "result.json").string(), (dir / "overlays").string(), (dir / "truth.json").string(),
      (dir / "masks").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("registered"), std::string::npos) << run.out;
  EXPECT_NE(run.err.find("stage 1/4"), std::string::npos) << "progress bar on stderr: " << run.err;

  auto result = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(result.ok()) << result.error();
  const auto& json = result.value();
  auto registered = fct::PoseFile::read(dir / "result.json");  // T_world_from_ct reads like a pose file
  ASSERT_TRUE(registered.ok()) << registered.error();
  EXPECT_LT((registered.value().translation() - truth.translation()).norm(), 0.5);
  EXPECT_LT(Eigen::AngleAxisd(registered.value().linear() * truth.linear().transpose()).angle() * 180.0 / M_PI, 0.3);
  EXPECT_FALSE(json["cancelled"].get<bool>());
  EXPECT_NE(run.out.find("pose error vs truth"), std::string::npos) << run.out;
  EXPECT_GT(json["error_vs_truth"]["initial_mean_surface_mm"].get<double>(), 1.0);
  EXPECT_LT(json["error_vs_truth"]["final_mean_surface_mm"].get<double>(), 0.5);
  ASSERT_EQ(json["stages"].size(), 4u);
  for (const auto& stage : json["stages"]) {
    for (const char* key : {"name", "seconds", "drrs", "similarity", "kept_fraction"}) {
      EXPECT_TRUE(stage.contains(key)) << key;
    }
    EXPECT_EQ(stage["kept_fraction"].size(), 3u);
  }
  EXPECT_GT(json["total_seconds"].get<double>(), 0.0);
  EXPECT_EQ(json["options"]["preset"], "fast");
  EXPECT_EQ(json["options"]["seed"], 3);
  EXPECT_EQ(json["options"]["method"], "siddon");
  EXPECT_EQ(json["options"]["schedule"]["stages"].size(), 4u);
  EXPECT_EQ(json["initial_pose"]["source"], "pose file");
  EXPECT_EQ(json["initial_pose"]["T_world_from_ct"].size(), 4u);
  EXPECT_TRUE(json["options"]["metal_mask"].get<bool>());
  EXPECT_NE(run.out.find("view ap: metal mask excludes"), std::string::npos) << run.out;
  for (const char* view : {"ap", "lateral", "oblique45"}) {
    EXPECT_GT(fs::file_size(dir / "overlays" / (std::string(view) + ".png")), 1000u) << view;
    EXPECT_TRUE(fs::exists(dir / "masks" / (std::string(view) + "_mask.png"))) << view;
    EXPECT_LT(json["metal_fraction"][view].get<double>(), 0.05) << "the phantom has no metal: " << view;
  }
  // The default cut-face margin (5 mm): each view's metal share of the field whose rays clear the CT's cut faces.
  EXPECT_EQ(json["options"]["cut_face_margin_mm"].get<double>(), 5.0);
  EXPECT_EQ(json["options"]["bone_contrast"].get<double>(), fct::RegistrationCaseOptions::kDefaultBoneContrast);
  EXPECT_NE(run.out.find("of the field whose rays clear the CT's cut faces) at the final pose"), std::string::npos)
      << run.out;
  for (const char* view : {"ap", "lateral", "oblique45"}) {
    ASSERT_TRUE(json["metal_fraction_covered"].contains(view)) << view;
    const double covered = json["metal_fraction_covered"][view].get<double>();
    EXPECT_GE(covered, 0.0) << view;
    EXPECT_LT(covered, 0.05) << "the phantom has no metal: " << view;
  }
}

TEST(RegisterCommand, ResultFileReadsBackAsARegistrationResult) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(perturbed(truth), dir / "init.json").ok());
  const auto run = fct::test::runCli(fmt::format("register --ct '{}' --views '{}' --init '{}' --preset fast --local-only "
                                                 "--cut-face-margin-mm -1 --out '{}'",
                                                 (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(),
                                                 (dir / "init.json").string(), (dir / "result.json").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  auto json = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(json.ok()) << json.error();
  EXPECT_EQ(json.value()["format"], fct::RegistrationResultJson::kFormat);
  EXPECT_FALSE(json.value().contains("metal_fraction_covered")) << "no cut-face margin, no covered field";
  auto result = fct::RegistrationResultJson::read(json.value(), "result.json");
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().T_initial.isApprox(perturbed(truth), 1e-12));
  EXPECT_EQ(result.value().viewNames, (std::vector<std::string>{"ap", "lateral", "oblique45"}));
  EXPECT_EQ(result.value().stages.size(), 4u);
  EXPECT_EQ(result.value().drrMethod, "siddon");
  auto pose = fct::PoseFile::read(dir / "result.json");
  ASSERT_TRUE(pose.ok()) << pose.error();
  EXPECT_TRUE(pose.value().isApprox(result.value().T_world_from_ct, 1e-12));
}

TEST(RegisterCommand, WritesTheFinalPoseAsADicomRegistration) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(perturbed(truth), dir / "init.json").ok());
  const std::string base = fmt::format("register --ct '{}' --views '{}' --init '{}' --preset fast --local-only --out '{}'",
                                       (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(),
                                       (dir / "init.json").string(), (dir / "result.json").string());
  const auto run = fct::test::runCli(base + fmt::format(" --dicom-reg '{}'", (dir / "reg.dcm").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("wrote DICOM registration"), std::string::npos) << run.out;
  EXPECT_NE(run.err.find("generated Frame of Reference UID"), std::string::npos) << "a NRRD CT: " << run.err;
  auto pose = fct::PoseFile::read(dir / "result.json");
  ASSERT_TRUE(pose.ok()) << pose.error();
  auto registration = fct::DicomRegistrationReader::read(dir / "reg.dcm");
  ASSERT_TRUE(registration.ok()) << registration.error();
  EXPECT_TRUE(registration.value().T_world_from_ct.matrix().isApprox(pose.value().matrix(), 1e-8));

  // An unwritable REG path fails with one error line, after the result file is safely written.
  fs::remove(dir / "result.json");
  const auto refused = fct::test::runCli(base + fmt::format(" --dicom-reg '{}'", (dir / "no" / "reg.dcm").string()));
  EXPECT_TRUE(oneErrorLine(refused)) << refused.err;
  EXPECT_NE(refused.err.find("--dicom-reg"), std::string::npos) << refused.err;
  EXPECT_TRUE(fs::exists(dir / "result.json"));
}

TEST(RegisterCommand, EstimatesTheInitialPoseFromLandmarks) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = makeCase(dir);
  auto views = fct::ViewFile::read(dir / "sim" / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  const std::vector<fct::CtLandmark> ct{{"A", {30, 10, 20}}, {"B", {-25, 15, -10}}, {"C", {5, -30, 25}},
                                        {"D", {-10, -5, -30}}, {"E", {20, 25, -20}}};
  std::map<std::string, std::vector<fct::ImageLandmark>> clicks;
  for (const auto& view : views.value()) {
    for (const auto& landmark : ct) {
      clicks[view.name].push_back({landmark.name, view.camera.project(truth * landmark.p_ct_mm) + Eigen::Vector2d(0.6, -0.4)});
    }
  }
  ASSERT_TRUE(fct::LandmarkFile::writeCt(ct, dir / "points.mrk.json").ok());
  ASSERT_TRUE(fct::LandmarkFile::writeImage(clicks, dir / "clicks.json").ok());
  std::ofstream(dir / "lm.json") << R"({"ct": "points.mrk.json", "image": "clicks.json"})";
  const auto run = fct::test::runCli(fmt::format(
      "register --ct '{}' --views '{}' --landmarks '{}' --preset fast --local-only --out '{}'",
      (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "lm.json").string(),
      (dir / "result.json").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  auto result = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value()["initial_pose"]["source"], "landmarks");
  EXPECT_EQ(result.value()["initial_pose"]["residuals"].size(), 5u);
  EXPECT_EQ(result.value()["options"]["ablation"][0], "local-only");
  auto registered = fct::PoseFile::read(dir / "result.json");
  ASSERT_TRUE(registered.ok()) << registered.error();
  EXPECT_LT((registered.value().translation() - truth.translation()).norm(), 0.5);
}

TEST(RegisterCommand, RegistersWithTransgraphTablesCachedForTheNextRun) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(perturbed(truth), dir / "init.json").ok());
  const std::string command = fmt::format(
      "register --ct '{}' --views '{}' --init '{}' --preset fast --method transgraph --transgraph-cache '{}' "
      "--transgraph-spacing-mm 5 --out '{}'",
      (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "init.json").string(),
      (dir / "cache").string(), (dir / "result.json").string());
  auto run = fct::test::runCli(command);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("built in"), std::string::npos) << run.out;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "cache"), fs::directory_iterator{}), 3) << "one table per view";
  run = fct::test::runCli(command);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("loaded from the cache"), std::string::npos) << run.out;

  auto result = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(result.ok()) << result.error();
  const auto& json = result.value();
  EXPECT_EQ(json["options"]["method"], "transgraph");
  EXPECT_TRUE(json["transgraph"]["views"]["lateral"]["loaded_from_cache"].get<bool>());
  for (const auto& stage : json["stages"]) EXPECT_EQ(stage["fallback_rays"], 0) << stage["name"];
  auto registered = fct::PoseFile::read(dir / "result.json");
  ASSERT_TRUE(registered.ok()) << registered.error();
  EXPECT_LT((registered.value().translation() - truth.translation()).norm(), 0.5);

  // The ablation switch: exact DRRs, no table needed (and every level's DRRs from the full CT).
  run = fct::test::runCli(command + " --no-transgraph --local-only --no-ct-pyramid");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  result = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value()["options"]["method"], "siddon");
  EXPECT_TRUE(result.value()["transgraph"].is_null());
  EXPECT_EQ(result.value()["options"]["ablation"][1], "no-transgraph");
  EXPECT_EQ(result.value()["options"]["ablation"][2], "no-ct-pyramid");
}

TEST(RegisterCommand, RegistersWithTrilinearDrrsAtTheChosenStep) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(perturbed(truth), dir / "init.json").ok());
  const auto run = fct::test::runCli(fmt::format(
      "register --ct '{}' --views '{}' --init '{}' --preset fast --seed 3 --method raycast --raycast-step-mm 2 "
      "--out '{}'",
      (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "init.json").string(),
      (dir / "result.json").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("raycast method"), std::string::npos) << run.out;
  auto result = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value()["options"]["method"], "raycast");
  EXPECT_DOUBLE_EQ(result.value()["options"]["raycast_step_mm"].get<double>(), 2.0);
  auto registered = fct::PoseFile::read(dir / "result.json");
  ASSERT_TRUE(registered.ok()) << registered.error();
  EXPECT_LT((registered.value().translation() - truth.translation()).norm(), 1.0);
}

TEST(RegisterCommand, FailsWithOneErrorLineOnBadInput) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(truth, dir / "init.json").ok());
  const std::string base = fmt::format("register --ct '{}' --views '{}'", (dir / "ct.nrrd").string(),
                                       (dir / "sim" / "views.json").string());
  const std::string init = fmt::format(" --init '{}'", (dir / "init.json").string());

  const auto noInit = fct::test::runCli(base);
  EXPECT_TRUE(oneErrorLine(noInit)) << noInit.err;
  EXPECT_NE(noInit.err.find("--init"), std::string::npos) << noInit.err;

  const auto badPreset = fct::test::runCli(base + init + " --preset fastest");
  EXPECT_TRUE(oneErrorLine(badPreset)) << badPreset.err;
  EXPECT_NE(badPreset.err.find("fast, paper"), std::string::npos) << badPreset.err;

  const auto badMethod = fct::test::runCli(base + init + " --method magic");
  EXPECT_TRUE(oneErrorLine(badMethod)) << badMethod.err;

  const auto badStep = fct::test::runCli(base + init + " --method raycast --raycast-step-mm -1");
  EXPECT_TRUE(oneErrorLine(badStep)) << badStep.err;
  EXPECT_NE(badStep.err.find("--raycast-step-mm"), std::string::npos) << badStep.err;
  // The step of trilinear sampling means nothing to the exact renderer: refused, not silently ignored.
  const auto stepWithSiddon = fct::test::runCli(base + init + " --raycast-step-mm 3");
  EXPECT_TRUE(oneErrorLine(stepWithSiddon)) << stepWithSiddon.err;
  EXPECT_NE(stepWithSiddon.err.find("it has no effect with --method siddon"), std::string::npos) << stepWithSiddon.err;

  const auto badMetal = fct::test::runCli(base + init + " --metal-min-excess 0");
  EXPECT_TRUE(oneErrorLine(badMetal)) << badMetal.err;
  EXPECT_NE(badMetal.err.find("minimum excess"), std::string::npos) << badMetal.err;

  // A cut-face margin beyond the largest, or not a number: refused by the flag, before anything is read.
  for (const std::string margin : {"600", "nan"}) {
    const auto badMargin = fct::test::runCli(base + init + " --cut-face-margin-mm " + margin);
    EXPECT_TRUE(oneErrorLine(badMargin)) << badMargin.err;
    EXPECT_NE(badMargin.err.find("--cut-face-margin-mm"), std::string::npos) << badMargin.err;
    EXPECT_NE(badMargin.err.find("up to 500"), std::string::npos) << badMargin.err;
  }
  // A bone contrast of 0, beyond the largest, or not a number: refused by the flag.
  for (const std::string contrast : {"0", "11", "nan"}) {
    const auto badContrast = fct::test::runCli(base + init + " --bone-contrast " + contrast);
    EXPECT_TRUE(oneErrorLine(badContrast)) << badContrast.err;
    EXPECT_NE(badContrast.err.find("--bone-contrast"), std::string::npos) << badContrast.err;
    EXPECT_NE(badContrast.err.find("above 0 and up to 10"), std::string::npos) << badContrast.err;
  }

  Eigen::Isometry3d far = truth;
  far.translation().z() += 900.0;
  ASSERT_TRUE(fct::PoseFile::write(far, dir / "far.json").ok());
  const auto noOverlap = fct::test::runCli(base + fmt::format(" --init '{}' --out '{}'", (dir / "far.json").string(),
                                                              (dir / "never.json").string()));
  EXPECT_TRUE(oneErrorLine(noOverlap)) << noOverlap.err;
  EXPECT_NE(noOverlap.err.find("do not overlap"), std::string::npos) << noOverlap.err;
  EXPECT_FALSE(fs::exists(dir / "never.json")) << "nothing written on failure";

  // Landmarks clicked in a view the view file does not have.
  ASSERT_TRUE(fct::LandmarkFile::writeCt({{"A", {0, 0, 0}}, {"B", {10, 0, 0}}, {"C", {0, 10, 0}}, {"D", {0, 0, 10}}},
                                         dir / "points.mrk.json")
                  .ok());
  ASSERT_TRUE(fct::LandmarkFile::writeImage({{"nosuchview", {{"A", {1, 1}}, {"B", {2, 2}}, {"C", {3, 1}}, {"D", {5, 5}}}}},
                                            dir / "clicks.json")
                  .ok());
  std::ofstream(dir / "lm.json") << R"({"ct": "points.mrk.json", "image": "clicks.json"})";
  const auto badView = fct::test::runCli(base + fmt::format(" --landmarks '{}'", (dir / "lm.json").string()));
  EXPECT_TRUE(oneErrorLine(badView)) << badView.err;
  EXPECT_NE(badView.err.find("nosuchview"), std::string::npos) << badView.err;
}
