// ViewFile "sequence": a list of image files or a range of a multi-frame DICOM file per view; round trip and errors.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "Base/TextFile.h"
#include "IO/Project/ViewFile.h"
#include "SyntheticXrayDicom.h"
#include "TestSupport.h"

namespace {

using nlohmann::json;

json viewWith(const std::string& name, json sequence) {
  return {{"name", name},
          {"sequence", std::move(sequence)},
          {"detector", {{"cols", 5}, {"rows", 4}, {"pixel_spacing_mm", {0.4, 0.4}}}},
          {"source_to_detector_mm", 1500},
          {"principal_point_px", {2, 1.5}},
          {"T_world_from_camera", {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}}};
}

/// A scratch folder with a 6-frame XA file cine.dcm and three image files f0.png..f2.png.
std::filesystem::path sequenceFolder() {
  const auto dir = fct::test::scratchDir();
  fct::test::SyntheticXray xray;
  xray.frames = 6;
  DcmFileFormat file = xray.build();
  fct::test::save(file, dir / "cine.dcm");
  for (int i = 0; i < 3; ++i) std::ofstream(dir / ("f" + std::to_string(i) + ".png")) << "image";
  return dir;
}

fct::Result<std::vector<fct::ViewSpec>> readViews(const std::filesystem::path& dir, const std::vector<json>& views) {
  const auto path = dir / "views.json";
  EXPECT_TRUE(fct::TextFile::writeAtomically(path, json{{"views", json(views)}}.dump(2)).ok());
  return fct::ViewFile::read(path);
}

}  // namespace

TEST(ViewFileSequence, RoundTripsFileListsAndMultiFrameRanges) {
  const auto dir = sequenceFolder();
  auto views = readViews(dir, {viewWith("ap", {"f0.png", "f1.png", "f2.png"}),
                               viewWith("lat", {{"path", "cine.dcm"}, {"frames", {2, 4}}})});
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(views.value().size(), 2u);
  const fct::ViewSpec& ap = views.value()[0];
  const fct::ViewSpec& lat = views.value()[1];
  ASSERT_TRUE(ap.sequence && lat.sequence);
  EXPECT_EQ(ap.sequence->frameCount(), 3);
  EXPECT_EQ(lat.sequence->frameCount(), 3);
  EXPECT_EQ(ap.imagePath, dir / "f0.png");  // the first frame is the view's image
  EXPECT_EQ(lat.imagePath, dir / "cine.dcm");
  EXPECT_EQ(lat.frame, 2);
  EXPECT_EQ(ap.sequence->frame(2).first, dir / "f2.png");
  EXPECT_EQ(lat.sequence->frame(1), std::make_pair(dir / "cine.dcm", 3));

  const auto copy = dir / "copy.json";
  ASSERT_TRUE(fct::ViewFile::write(views.value(), copy).ok());
  const json written = json::parse(fct::test::readText(copy));
  EXPECT_EQ(written["views"][0]["sequence"], json({"f0.png", "f1.png", "f2.png"}));
  EXPECT_EQ(written["views"][1]["sequence"]["frames"], json({2, 4}));
  EXPECT_FALSE(written["views"][0].contains("image"));
  auto again = fct::ViewFile::read(copy);
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value()[1].sequence->firstFrame, 2);
  EXPECT_EQ(again.value()[1].sequence->lastFrame, 4);
  EXPECT_EQ(again.value()[0].sequence->files, ap.sequence->files);
}

TEST(ViewFileSequence, AllFramesOfAMultiFrameFile) {
  const auto dir = sequenceFolder();
  auto views = readViews(dir, {viewWith("ap", {{"path", "cine.dcm"}, {"frames", "all"}})});
  ASSERT_TRUE(views.ok()) << views.error();
  EXPECT_EQ(views.value()[0].sequence->frameCount(), 6);
  EXPECT_TRUE(views.value()[0].sequence->allFrames);
  const auto copy = dir / "copy.json";
  ASSERT_TRUE(fct::ViewFile::write(views.value(), copy).ok());
  EXPECT_EQ(json::parse(fct::test::readText(copy))["views"][0]["sequence"]["frames"], "all");
}

TEST(ViewFileSequence, RejectsMismatchedFrameCountsBadRangesAndMissingFrames) {
  const auto dir = sequenceFolder();
  auto mismatch = readViews(dir, {viewWith("ap", {"f0.png", "f1.png"}),
                                  viewWith("lat", {{"path", "cine.dcm"}, {"frames", "all"}})});
  ASSERT_FALSE(mismatch.ok());
  EXPECT_NE(mismatch.error().find("view 'lat' has 6 frames but view 'ap' has 2 frames"), std::string::npos)
      << mismatch.error();

  json plain = viewWith("lat", nullptr);
  plain.erase("sequence");
  auto oneWithout = readViews(dir, {viewWith("ap", json::array({"f0.png"})), plain});
  ASSERT_FALSE(oneWithout.ok());
  EXPECT_NE(oneWithout.error().find("no sequence"), std::string::npos) << oneWithout.error();

  auto beyond = readViews(dir, {viewWith("ap", {{"path", "cine.dcm"}, {"frames", {3, 6}}})});
  ASSERT_FALSE(beyond.ok());
  EXPECT_NE(beyond.error().find("which has 6 frames"), std::string::npos) << beyond.error();
  auto reversed = readViews(dir, {viewWith("ap", {{"path", "cine.dcm"}, {"frames", {4, 2}}})});
  ASSERT_FALSE(reversed.ok());
  EXPECT_NE(reversed.error().find("first <= last"), std::string::npos) << reversed.error();
  auto badFrames = readViews(dir, {viewWith("ap", {{"path", "cine.dcm"}, {"frames", "some"}})});
  ASSERT_FALSE(badFrames.ok());
  EXPECT_NE(badFrames.error().find("\"all\" or [first, last]"), std::string::npos) << badFrames.error();

  auto missing = readViews(dir, {viewWith("ap", {"f0.png", "nope.png"})});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("nope.png"), std::string::npos) << missing.error();
  auto empty = readViews(dir, {viewWith("ap", json::array())});
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.error().find("non-empty list"), std::string::npos) << empty.error();
  json both = viewWith("ap", json::array({"f0.png"}));
  both["image"] = "f0.png";
  auto twice = readViews(dir, {both});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().find("both \"image\" and \"sequence\""), std::string::npos) << twice.error();
}
