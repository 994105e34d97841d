// LandmarkPairFile: a pair set written then read gives the same landmarks and method; a hand-written file with the
// default method; bad pair files and bad landmark files are refused naming the file and key.
#include <gtest/gtest.h>

#include "Base/TextFile.h"
#include "IO/Project/LandmarkFile.h"
#include "IO/Project/LandmarkPairFile.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

fct::LandmarkPairSet pairSet() {
  fct::LandmarkPairSet set;
  set.ctFile = "landmarks/points.mrk.json";
  set.imageFile = "clicks.json";
  set.method = fct::LandmarkPoseMethod::Triangulation;
  set.landmarks.ct = {{"A", {30, 10, 20}}, {"B", {-25, 15, -10.5}}};
  set.landmarks.imageByView["ap"] = {{"A", {12.5, 40.0}}, {"B", {100.25, 7.0}}};
  set.landmarks.imageByView["lateral"] = {{"B", {3.0, 4.0}}};
  return set;
}

std::string errorOf(const fs::path& dir, const std::string& pairText) {
  EXPECT_TRUE(fct::TextFile::writeAtomically(dir / "lm.json", pairText).ok());
  auto read = fct::LandmarkPairFile::read(dir / "lm.json");
  EXPECT_FALSE(read.ok()) << pairText;
  return read.error();
}

}  // namespace

TEST(LandmarkPairFile, WriteThenReadGivesTheSameLandmarksAndMethod) {
  const fs::path dir = fct::test::scratchDir();
  const fct::LandmarkPairSet written = pairSet();
  fs::create_directories(dir / "landmarks");
  const fct::Status status = fct::LandmarkPairFile::write(written, dir / "lm.json");
  ASSERT_TRUE(status.ok()) << status.error();
  EXPECT_TRUE(fs::exists(dir / "landmarks" / "points.mrk.json")) << "landmark files are relative to the pair file";

  auto read = fct::LandmarkPairFile::read(dir / "lm.json");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(read.warnings().empty());
  const fct::LandmarkPairSet& set = read.value();
  EXPECT_EQ(set.method, fct::LandmarkPoseMethod::Triangulation);
  EXPECT_EQ(set.ctFile, dir / "landmarks" / "points.mrk.json");
  EXPECT_EQ(set.imageFile, dir / "clicks.json");
  ASSERT_EQ(set.landmarks.ct.size(), 2u);
  EXPECT_EQ(set.landmarks.ct[1].name, "B");
  EXPECT_EQ(set.landmarks.ct[1].p_ct_mm, Eigen::Vector3d(-25, 15, -10.5));
  ASSERT_EQ(set.landmarks.imageByView.size(), 2u);
  EXPECT_EQ(set.landmarks.imageByView.at("ap")[1].uv_px, Eigen::Vector2d(100.25, 7.0));
  EXPECT_EQ(set.landmarks.imageByView.at("lateral")[0].name, "B");
}

TEST(LandmarkPairFile, ReadsAHandWrittenFileWithTheDefaultMethodAndWarnsAboutExtraKeys) {
  const fs::path dir = fct::test::scratchDir();
  const fct::LandmarkPairSet set = pairSet();
  ASSERT_TRUE(fct::LandmarkFile::writeCt(set.landmarks.ct, dir / "points.mrk.json").ok());
  ASSERT_TRUE(fct::LandmarkFile::writeImage(set.landmarks.imageByView, dir / "clicks.json").ok());
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "lm.json",
                                             R"({"ct": "points.mrk.json", "image": "clicks.json", "note": 1})")
                  .ok());
  auto read = fct::LandmarkPairFile::read(dir / "lm.json");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().method, fct::LandmarkPoseMethod::Reprojection);
  EXPECT_EQ(read.value().landmarks.ct.size(), 2u);
  ASSERT_EQ(read.warnings().size(), 1u);
  EXPECT_NE(read.warnings()[0].find("unknown key 'note'"), std::string::npos) << read.warnings()[0];
}

TEST(LandmarkPairFile, RefusesBadPairFilesNamingTheFileAndKey) {
  const fs::path dir = fct::test::scratchDir();
  const fct::LandmarkPairSet set = pairSet();
  ASSERT_TRUE(fct::LandmarkFile::writeCt(set.landmarks.ct, dir / "points.mrk.json").ok());
  ASSERT_TRUE(fct::LandmarkFile::writeImage(set.landmarks.imageByView, dir / "clicks.json").ok());
  const std::string lm = (dir / "lm.json").string();

  EXPECT_NE(errorOf(dir, R"({"image": "clicks.json"})").find(lm + ": key 'ct' is missing"), std::string::npos);
  EXPECT_NE(errorOf(dir, R"({"ct": "points.mrk.json", "image": ""})").find("key 'image' must not be empty"),
            std::string::npos);
  EXPECT_NE(errorOf(dir, R"({"ct": "points.mrk.json", "image": "clicks.json", "method": "guess"})")
                .find("key 'method' is 'guess'; use 'reprojection' or 'triangulation'"),
            std::string::npos);
  EXPECT_NE(errorOf(dir, R"({"ct": "points.mrk.json", "image": "clicks.json", "method": 2})")
                .find("key 'method' must be a string"),
            std::string::npos);
  EXPECT_NE(errorOf(dir, R"({"ct": "points.mrk.json", "image": "gone.json"})").find("gone.json"), std::string::npos);
  EXPECT_NE(errorOf(dir, "[1, 2]").find("must be a JSON object"), std::string::npos);
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "clicks.json", R"({"views": {"ap": [{"name": "A"}]}})").ok());
  EXPECT_NE(errorOf(dir, R"({"ct": "points.mrk.json", "image": "clicks.json"})").find("uv_px"), std::string::npos)
      << "the landmark files' errors come through";
}

TEST(LandmarkPairFile, WriteRefusesAMissingFileNameAndWritesNoPairFileAfterAFailedLandmarkFile) {
  const fs::path dir = fct::test::scratchDir();
  fct::LandmarkPairSet set = pairSet();
  set.imageFile.clear();
  const fct::Status unnamed = fct::LandmarkPairFile::write(set, dir / "lm.json");
  ASSERT_FALSE(unnamed.ok());
  EXPECT_NE(unnamed.error().find("need a name"), std::string::npos) << unnamed.error();

  set = pairSet();
  set.landmarks.ct.push_back(set.landmarks.ct.front());  // a duplicate name
  const fct::Status duplicate = fct::LandmarkPairFile::write(set, dir / "lm.json");
  ASSERT_FALSE(duplicate.ok());
  EXPECT_NE(duplicate.error().find("used twice"), std::string::npos) << duplicate.error();
  EXPECT_FALSE(fs::exists(dir / "lm.json"));
}
