// fluoroct tre: JSON keys and values for known pose differences, a register RESULT.json as estimate, bad poses.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "Base/JsonDocument.h"
#include "Base/TextFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "Simulation/PhantomBuilder.h"
#include "TestSupport.h"

namespace {

std::filesystem::path writeSmallPhantom(const std::filesystem::path& dir) {
  fct::PhantomOptions small;
  small.dims = Eigen::Vector3i(48, 48, 36);
  small.spacing_mm = 3.0;
  EXPECT_TRUE(fct::VolumeFileIO::write(fct::PhantomBuilder::build(small).value(), dir / "ct.nrrd").ok());
  return dir / "ct.nrrd";
}

nlohmann::json treJson(const std::filesystem::path& ct, const std::filesystem::path& truth,
                       const std::filesystem::path& estimate) {
  const auto run = fct::test::runCli(fmt::format("tre --ct '{}' --truth '{}' --estimate '{}' --json", ct.string(),
                                                 truth.string(), estimate.string()));
  EXPECT_EQ(run.exitCode, 0) << run.err;
  return nlohmann::json::parse(run.out);
}

}  // namespace

TEST(TreCommand, IdenticalPosesPrintZerosAndATranslationItsLength) {
  const auto dir = fct::test::scratchDir();
  const auto ct = writeSmallPhantom(dir);
  Eigen::Isometry3d T_truth = Eigen::Isometry3d::Identity();
  T_truth.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  Eigen::Isometry3d T_moved = T_truth;
  T_moved.pretranslate(Eigen::Vector3d(0.0, 3.0, 4.0));
  ASSERT_TRUE(fct::PoseFile::write(T_truth, dir / "truth.json").ok());
  ASSERT_TRUE(fct::PoseFile::write(T_moved, dir / "moved.json").ok());

  const nlohmann::json same = treJson(ct, dir / "truth.json", dir / "truth.json");
  ASSERT_EQ(same.size(), 5u);
  for (const char* key : {"stre_mean_mm", "stre_max_mm", "mtre_mm", "rotation_deg", "translation_mm"}) {
    ASSERT_TRUE(same.contains(key)) << key;
    EXPECT_NEAR(same[key].get<double>(), 0.0, 1e-6) << key;
  }
  const nlohmann::json moved = treJson(ct, dir / "truth.json", dir / "moved.json");
  for (const char* key : {"stre_mean_mm", "stre_max_mm", "mtre_mm", "translation_mm"}) {
    EXPECT_NEAR(moved[key].get<double>(), 5.0, 1e-6) << key;
  }
  EXPECT_NEAR(moved["rotation_deg"].get<double>(), 0.0, 1e-6);
}

TEST(TreCommand, AcceptsARegisterResultAsTheEstimate) {
  const auto dir = fct::test::scratchDir();
  const auto ct = writeSmallPhantom(dir);
  ASSERT_TRUE(fct::PoseFile::write(Eigen::Isometry3d::Identity(), dir / "truth.json").ok());
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(0, 3) = 1.5;
  const nlohmann::ordered_json result{{"T_world_from_ct", fct::JsonDocument::array(T)},
                                      {"cancelled", false},
                                      {"stages", nlohmann::ordered_json::array()},
                                      {"total_seconds", 3.2}};
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "result.json", result.dump(2)).ok());
  const auto run = fct::test::runCli(fmt::format("tre --ct '{}' --truth '{}' --estimate '{}'", ct.string(),
                                                 (dir / "truth.json").string(), (dir / "result.json").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("mean 1.500 mm, max 1.500 mm"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("success    yes"), std::string::npos) << run.out;
}

TEST(TreCommand, NonRotationPoseGivesOneErrorLine) {
  const auto dir = fct::test::scratchDir();
  const auto ct = writeSmallPhantom(dir);
  ASSERT_TRUE(fct::PoseFile::write(Eigen::Isometry3d::Identity(), dir / "truth.json").ok());
  ASSERT_TRUE(fct::TextFile::writeAtomically(
                  dir / "scaled.json", R"({"T_world_from_ct": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})")
                  .ok());
  const auto run = fct::test::runCli(fmt::format("tre --ct '{}' --truth '{}' --estimate '{}'", ct.string(),
                                                 (dir / "truth.json").string(), (dir / "scaled.json").string()));
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_EQ(run.err.rfind("error: --estimate: ", 0), 0u) << run.err;
  EXPECT_NE(run.err.find("rotation"), std::string::npos) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}
