#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "Base/TextFile.h"
#include "IO/Project/LandmarkFile.h"
#include "TestSupport.h"

namespace {

using nlohmann::json;

std::filesystem::path writeText(const std::string& name, const std::string& text) {
  const auto path = fct::test::scratchDir() / name;
  EXPECT_TRUE(fct::TextFile::writeAtomically(path, text).ok());
  return path;
}

/// A Slicer markups file with one point list in `system` holding the given control points.
std::string slicerFile(const std::string& system, const json& controlPoints) {
  return json{{"@schema",
               "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/"
               "markups-schema-v1.0.3.json#"},
              {"markups",
               {{{"type", "Fiducial"},
                 {"coordinateSystem", system},
                 {"coordinateUnits", "mm"},
                 {"controlPoints", controlPoints}}}}}
      .dump(4);
}

std::string ctError(const std::string& text) {
  const auto result = fct::LandmarkFile::readCt(writeText("ct.mrk.json", text));
  EXPECT_FALSE(result.ok());
  return result.error();
}

std::string imageError(const json& document) {
  const auto result = fct::LandmarkFile::readImage(writeText("xray.json", document.dump()));
  EXPECT_FALSE(result.ok());
  return result.error();
}

}  // namespace

TEST(LandmarkFile, CtLandmarksRoundTripAsAnLpsSlicerPointList) {
  const std::vector<fct::CtLandmark> landmarks = {
      {"L1 pedicle", {12.5, -40.25, 301.0}}, {"L2", {-3.0, 0.1, 280.75}}, {"tip", {0.0, 0.0, -1e-3}}};
  const auto path = fct::test::scratchDir() / "ct.mrk.json";
  ASSERT_TRUE(fct::LandmarkFile::writeCt(landmarks, path).ok());
  const json written = json::parse(fct::TextFile::read(path).value());
  EXPECT_NE(written["@schema"].get<std::string>().find("markups-schema-v1.0.3.json#"), std::string::npos);
  EXPECT_EQ(written["markups"][0]["type"], "Fiducial");
  EXPECT_EQ(written["markups"][0]["coordinateSystem"], "LPS");
  EXPECT_EQ(written["markups"][0]["controlPoints"][1]["positionStatus"], "defined");

  const auto read = fct::LandmarkFile::readCt(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(read.warnings().empty());
  ASSERT_EQ(read.value().size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(read.value()[i].name, landmarks[i].name);
    EXPECT_EQ(read.value()[i].p_ct_mm, landmarks[i].p_ct_mm);
  }
}

TEST(LandmarkFile, ReadsASlicerRasFileAsLps) {
  const json points = {
      {{"id", "1"}, {"label", "F-1"}, {"position", {10.0, 20.0, 30.0}}, {"positionStatus", "defined"}},
      {{"id", "2"}, {"label", "F-2"}, {"position", {0.0, 0.0, 0.0}}, {"positionStatus", "undefined"}},
      {{"id", "3"}, {"label", "F-3"}, {"position", {-1.5, 2.5, -3.5}}}};
  json document = json::parse(slicerFile("RAS", points));
  document["markups"].push_back({{"type", "Line"}, {"controlPoints", json::array()}});
  const auto read = fct::LandmarkFile::readCt(writeText("ras.mrk.json", document.dump()));
  ASSERT_TRUE(read.ok()) << read.error();
  ASSERT_EQ(read.value().size(), 2u);
  EXPECT_EQ(read.value()[0].name, "F-1");
  EXPECT_EQ(read.value()[0].p_ct_mm, Eigen::Vector3d(-10.0, -20.0, 30.0));
  EXPECT_EQ(read.value()[1].name, "F-3");
  EXPECT_EQ(read.value()[1].p_ct_mm, Eigen::Vector3d(1.5, -2.5, -3.5));
  ASSERT_EQ(read.warnings().size(), 2u);  // the undefined point and the line
  EXPECT_NE(read.warnings()[0].find("landmark 'F-2'"), std::string::npos) << read.warnings()[0];
  EXPECT_NE(read.warnings()[1].find("type 'Line' ignored"), std::string::npos) << read.warnings()[1];
}

TEST(LandmarkFile, MissingCoordinateSystemMeansLpsAndMicrometresAreScaled) {
  json document = json::parse(slicerFile("LPS", {{{"label", "A"}, {"position", {1000.0, -2000.0, 500.0}}}}));
  document["markups"][0].erase("coordinateSystem");
  document["markups"][0]["coordinateUnits"] = {"um", "UCUM", "micrometer"};
  const auto read = fct::LandmarkFile::readCt(writeText("um.mrk.json", document.dump()));
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_LT((read.value()[0].p_ct_mm - Eigen::Vector3d(1.0, -2.0, 0.5)).norm(), 1e-12);
}

TEST(LandmarkFile, RejectsBadCtFiles) {
  std::string error = ctError(slicerFile("LPS", {{{"label", "A"}, {"position", {1, 2, 3}}},
                                                 {{"label", "A"}, {"position", {4, 5, 6}}}}));
  EXPECT_NE(error.find("landmark label 'A' is used twice"), std::string::npos) << error;
  error = ctError(slicerFile("LPS", {{{"label", "A"}, {"positionStatus", "defined"}}}));
  EXPECT_NE(error.find("ct.mrk.json: landmark 'A': key 'position' is missing"), std::string::npos) << error;
  error = ctError(slicerFile("LPS", {{{"label", "A"}, {"position", {1, "NaN", 3}}}}));
  EXPECT_NE(error.find("landmark 'A': key 'position[1]' must be a number"), std::string::npos) << error;
  std::string text = slicerFile("LPS", {{{"label", "A"}, {"position", {1, 2, 12345}}}});
  text.replace(text.find("12345"), 5, "NaN");
  error = ctError(text);
  EXPECT_NE(error.find("markups[0].controlPoints[0].position[2]"), std::string::npos) << error;
  error = ctError(slicerFile("IJK", {{{"label", "A"}, {"position", {1, 2, 3}}}}));
  EXPECT_NE(error.find("key 'coordinateSystem' must be \"LPS\" or \"RAS\", got \"IJK\""), std::string::npos) << error;
  error = ctError(slicerFile("LPS", {{{"label", ""}, {"position", {1, 2, 3}}}}));
  EXPECT_NE(error.find("control point 0: key 'label' must not be empty"), std::string::npos) << error;
  error = ctError(R"({"views": {}})");
  EXPECT_NE(error.find("not a 3D Slicer markups file"), std::string::npos) << error;
}

TEST(LandmarkFile, ImageLandmarksRoundTrip) {
  const std::map<std::string, std::vector<fct::ImageLandmark>> byView = {
      {"AP", {{"L1", {120.25, 88.5}}, {"L2", {401.0, 299.75}}}}, {"LAT", {{"L1", {17.0, 5.125}}}}, {"OBL", {}}};
  const auto path = fct::test::scratchDir() / "xray.json";
  ASSERT_TRUE(fct::LandmarkFile::writeImage(byView, path).ok());
  const auto read = fct::LandmarkFile::readImage(path);
  ASSERT_TRUE(read.ok()) << read.error();
  ASSERT_EQ(read.value().size(), 3u);
  for (const auto& [view, landmarks] : byView) {
    ASSERT_EQ(read.value().at(view).size(), landmarks.size()) << view;
    for (std::size_t i = 0; i < landmarks.size(); ++i) {
      EXPECT_EQ(read.value().at(view)[i].name, landmarks[i].name);
      EXPECT_EQ(read.value().at(view)[i].uv_px, landmarks[i].uv_px);
    }
  }
}

TEST(LandmarkFile, RejectsBadImageFiles) {
  std::string error = imageError({{"views", {{"AP", {{{"name", "L1"}, {"uv_px", {1, 2}}},
                                                     {{"name", "L1"}, {"uv_px", {3, 4}}}}}}}});
  EXPECT_NE(error.find("view 'AP': landmark name 'L1' is used twice"), std::string::npos) << error;
  error = imageError({{"views", {{"AP", {{{"name", "L1"}}}}}}});
  EXPECT_NE(error.find("view 'AP': landmark 'L1': key 'uv_px' is missing"), std::string::npos) << error;
  error = imageError({{"views", {{"AP", {{{"name", "L1"}, {"uv_px", {1, "Infinity"}}}}}}}});
  EXPECT_NE(error.find("landmark 'L1': key 'uv_px[1]' must be a number"), std::string::npos) << error;
  error = imageError({{"views", {1, 2}}});
  EXPECT_NE(error.find("key 'views' must be an object"), std::string::npos) << error;
}

TEST(LandmarkFile, WritesRejectDuplicateNamesNaNAndUnwritablePaths) {
  const auto dir = fct::test::scratchDir();
  EXPECT_FALSE(fct::LandmarkFile::writeCt({{"A", {1, 2, 3}}, {"A", {4, 5, 6}}}, dir / "ct.mrk.json").ok());
  EXPECT_FALSE(fct::LandmarkFile::writeCt({{"A", {1, std::nan(""), 3}}}, dir / "ct.mrk.json").ok());
  EXPECT_FALSE(fct::LandmarkFile::writeImage({{"AP", {{"B", {1, 2}}, {"B", {1, 2}}}}}, dir / "xray.json").ok());
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  const auto status = fct::LandmarkFile::writeCt({{"A", {1, 2, 3}}}, dir / "missing" / "ct.mrk.json");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("missing/ct.mrk.json"), std::string::npos) << status.error();
}
