#include <gtest/gtest.h>

#include "Base/TextFile.h"
#include "IO/Project/PoseFile.h"
#include "TestSupport.h"

namespace {

Eigen::Isometry3d obliquePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(-12.25, 40.5, 1003.125);
  return T;
}

fct::Result<Eigen::Isometry3d> readText(const std::string& text) {
  const auto path = fct::test::scratchDir() / "pose.json";
  EXPECT_TRUE(fct::TextFile::writeAtomically(path, text).ok());
  return fct::PoseFile::read(path);
}

}  // namespace

TEST(PoseFile, RoundTripsAnObliquePoseExactly) {
  const auto path = fct::test::scratchDir() / "pose.json";
  ASSERT_TRUE(fct::PoseFile::write(obliquePose(), path).ok());
  const auto read = fct::PoseFile::read(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().matrix(), obliquePose().matrix());
  EXPECT_TRUE(read.warnings().empty());
}

TEST(PoseFile, ReadsAHandWrittenFileAndWarnsAboutExtraKeys) {
  const auto read = readText(R"({"T_world_from_ct": [[1,0,0,5],[0,1,0,6],[0,0,1,7],[0,0,0,1]], "note": "x"})");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().translation(), Eigen::Vector3d(5, 6, 7));
  ASSERT_EQ(read.warnings().size(), 1u);
  EXPECT_NE(read.warnings()[0].find("unknown key 'note'"), std::string::npos);
}

TEST(PoseFile, RejectsANonRotationNaNAndAMissingKey) {
  auto read = readText(R"({"T_world_from_ct": [[1,0,0,0],[0,2,0,0],[0,0,1,0],[0,0,0,1]]})");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("pose.json: T_world_from_ct is not a rigid transform"), std::string::npos) << read.error();
  read = readText(R"({"T_world_from_ct": [[1,0,0,0],[0,1,0,"NaN"],[0,0,1,0],[0,0,0,1]]})");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("key 'T_world_from_ct[1][3]' must be a number"), std::string::npos) << read.error();
  read = readText(R"({"T_world_from_ct": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]})");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("must be 4 rows of 4 numbers"), std::string::npos) << read.error();
  read = readText(R"({"pose": []})");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("key 'T_world_from_ct' is missing"), std::string::npos) << read.error();
}

TEST(PoseFile, FailedWriteLeavesTheOldFileUntouched) {
  const auto path = fct::test::scratchDir() / "pose.json";
  ASSERT_TRUE(fct::PoseFile::write(obliquePose(), path).ok());
  const std::string before = fct::TextFile::read(path).value();
  Eigen::Isometry3d bad = obliquePose();
  bad.matrix()(0, 0) = std::nan("");
  const auto status = fct::PoseFile::write(bad, path);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("NaN"), std::string::npos) << status.error();
  EXPECT_EQ(fct::TextFile::read(path).value(), before);
  EXPECT_FALSE(fct::PoseFile::write(obliquePose(), path.parent_path() / "missing" / "pose.json").ok());
}

TEST(PoseFile, ReadsTheRegisteredPoseOfAResultFileOfFormat1) {
  // A RESULT.json of `fluoroct register` in format 1 (no "format" key), kept in Testing/Data/compat.
  const auto read = fct::PoseFile::read(fct::test::fixtureDir() / "compat" / "RESULT-v1.json");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_NEAR(read.value().translation().x(), 1.928635690899748, 1e-12);
  EXPECT_NEAR(read.value().translation().z(), 2.4187276194543705, 1e-12);
  EXPECT_NEAR(read.value().linear()(0, 1), -0.03713716818520369, 1e-12);
}

TEST(PoseFile, ReadKeyReadsANestedPoseAndRecordsWhatIsWrong) {
  const nlohmann::json object = {{"initial", {{"T", {{1, 0, 0, 5}, {0, 1, 0, 6}, {0, 0, 1, 7}, {0, 0, 0, 1}}}}},
                                 {"bad", {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {1, 0, 0, 1}}}};
  fct::JsonReader reader(object, "x.json");
  const auto pose = fct::PoseFile::readKey(reader, "initial.T");
  ASSERT_TRUE(pose) << reader.error();
  EXPECT_EQ(pose->translation(), Eigen::Vector3d(5, 6, 7));
  EXPECT_FALSE(fct::PoseFile::readKey(reader, "bad"));
  EXPECT_EQ(reader.error(), "x.json: bad's last row must be [0, 0, 0, 1]");
  EXPECT_FALSE(fct::PoseFile::readKey(reader, "initial.T")) << "nothing is read after an error";
}
