#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "Base/TextFile.h"
#include "IO/Project/ViewFile.h"
#include "TestSupport.h"

namespace {

using nlohmann::json;

fct::Camera obliqueCamera(double angle_rad, double principalShift_px) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(angle_rad, Eigen::Vector3d(0.2, 1.0, -0.3).normalized()) *
                             Eigen::AngleAxisd(-0.35, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  fct::CameraIntrinsics in;
  in.cols = 640;
  in.rows = 480;
  in.pixelSpacing_mm = {0.3, 0.31};
  in.sourceToDetector_mm = 1180.5;
  in.principalPoint_px = {319.5 + principalShift_px, 239.5 - principalShift_px};
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(12.5, -30.25, 40.0) - 710.0 * R.col(2);
  return fct::Camera::create(in, T).value();
}

void touch(const std::filesystem::path& path) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << "not really an image";
}

/// A valid view in the intrinsics form (identity pose, 800 x 600 detector).
json validView(const std::string& name) {
  return {{"name", name},
          {"detector", {{"cols", 800}, {"rows", 600}, {"pixel_spacing_mm", {0.4, 0.4}}}},
          {"source_to_detector_mm", 1500},
          {"principal_point_px", {399.5, 299.5}},
          {"T_world_from_camera", {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}}};
}

/// Writes `text` as views.json in a fresh scratch folder and returns what reading it says.
fct::Result<std::vector<fct::ViewSpec>> readText(const std::string& text) {
  const auto path = fct::test::scratchDir() / "views.json";
  EXPECT_TRUE(fct::TextFile::writeAtomically(path, text).ok());
  return fct::ViewFile::read(path);
}

std::string readError(const json& document) {
  const auto result = readText(document.dump(2));
  EXPECT_FALSE(result.ok()) << "expected an error for " << document.dump();
  return result.error();
}

}  // namespace

TEST(ViewFile, RoundTripsObliqueCamerasSpheresAndRelativeImagePaths) {
  const auto dir = fct::test::scratchDir();
  touch(dir / "case" / "xray" / "ap.dcm");
  touch(dir / "elsewhere" / "lat.png");
  std::vector<fct::ViewSpec> views(2);
  views[0].name = "AP";
  views[0].imagePath = dir / "case" / "xray" / "ap.dcm";
  views[0].frame = 3;
  views[0].camera = obliqueCamera(0.3, 4.25);
  views[0].calibrationSpheres = {{{120.5, 88.0}, 6.0}, {{300.25, 410.75}, 5.5}};
  views[1].name = "LAT";
  views[1].imagePath = dir / "elsewhere" / "lat.png";
  views[1].camera = obliqueCamera(1.4, -7.5);

  const auto path = dir / "case" / "views.json";
  ASSERT_TRUE(fct::ViewFile::write(views, path).ok());
  const std::string text = fct::TextFile::read(path).value();
  EXPECT_NE(text.find("\"path\": \"xray/ap.dcm\""), std::string::npos) << text;  // inside the folder: relative
  EXPECT_NE(text.find((dir / "elsewhere" / "lat.png").generic_string()), std::string::npos) << text;  // outside

  const auto read = fct::ViewFile::read(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(read.warnings().empty());
  ASSERT_EQ(read.value().size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const fct::ViewSpec& a = views[i];
    const fct::ViewSpec& b = read.value()[i];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.imagePath, a.imagePath);
    EXPECT_EQ(b.frame, a.frame);
    EXPECT_EQ(b.camera.intrinsics().cols, a.camera.intrinsics().cols);
    EXPECT_EQ(b.camera.intrinsics().rows, a.camera.intrinsics().rows);
    EXPECT_EQ(b.camera.intrinsics().pixelSpacing_mm, a.camera.intrinsics().pixelSpacing_mm);
    EXPECT_EQ(b.camera.intrinsics().sourceToDetector_mm, a.camera.intrinsics().sourceToDetector_mm);
    EXPECT_EQ(b.camera.intrinsics().principalPoint_px, a.camera.intrinsics().principalPoint_px);
    EXPECT_EQ(b.camera.T_world_from_camera().matrix(), a.camera.T_world_from_camera().matrix());  // 17 digits: exact
    ASSERT_EQ(b.calibrationSpheres.size(), a.calibrationSpheres.size());
    for (std::size_t s = 0; s < a.calibrationSpheres.size(); ++s) {
      EXPECT_EQ(b.calibrationSpheres[s].centre_px, a.calibrationSpheres[s].centre_px);
      EXPECT_EQ(b.calibrationSpheres[s].radius_px, a.calibrationSpheres[s].radius_px);
    }
  }
}

TEST(ViewFile, ProjectionMatrixViewProjectsLikeTheIntrinsicsForm) {
  const fct::Camera camera = obliqueCamera(0.8, 12.0);
  const Eigen::Matrix<double, 3, 4> P = -2.5 * camera.P_px_from_world();  // any scale and sign
  json pose = validView("POSE");
  pose["source_to_detector_mm"] = camera.intrinsics().sourceToDetector_mm;
  pose["principal_point_px"] = {camera.intrinsics().principalPoint_px.x(), camera.intrinsics().principalPoint_px.y()};
  pose["detector"] = {{"cols", 640}, {"rows", 480}, {"pixel_spacing_mm", {0.3, 0.31}}};
  json rows = json::array();
  for (int r = 0; r < 4; ++r) {
    const Eigen::Matrix4d& T = camera.T_world_from_camera().matrix();
    rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
  }
  pose["T_world_from_camera"] = rows;
  json matrix = {{"name", "MATRIX"}, {"detector", pose["detector"]}, {"projection_matrix", json::array()}};
  for (int r = 0; r < 3; ++r) matrix["projection_matrix"].push_back({P(r, 0), P(r, 1), P(r, 2), P(r, 3)});

  const auto read = readText(json{{"views", {pose, matrix}}}.dump());
  ASSERT_TRUE(read.ok()) << read.error();
  const fct::Camera& a = read.value()[0].camera;
  const fct::Camera& b = read.value()[1].camera;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(60, -45, 80), Eigen::Vector3d(-90, 30, -20)}) {
    EXPECT_LT((a.project(p) - b.project(p)).norm(), 1e-6) << p.transpose();
  }
  EXPECT_NEAR(b.intrinsics().sourceToDetector_mm, camera.intrinsics().sourceToDetector_mm, 1e-6);
}

TEST(ViewFile, PlainStringImageIsRelativeToTheViewFilesFolder) {
  const auto dir = fct::test::scratchDir();
  touch(dir / "sub" / "lat.png");
  json view = validView("LAT");
  view["image"] = "lat.png";
  const auto path = dir / "sub" / "views.json";
  ASSERT_TRUE(fct::TextFile::writeAtomically(path, json{{"views", {view}}}.dump()).ok());
  const auto read = fct::ViewFile::read(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value()[0].imagePath, std::filesystem::absolute(dir / "sub" / "lat.png").lexically_normal());
  EXPECT_TRUE(read.value()[0].imagePath.is_absolute());
  EXPECT_EQ(read.value()[0].frame, 0);
}

TEST(ViewFile, UnknownKeysAreIgnoredWithAWarning) {
  json view = validView("AP");
  view["colour"] = "blue";
  view["detector"]["vendor"] = "X";
  const auto read = readText(json{{"views", {view}}, {"comment", "hi"}}.dump());
  ASSERT_TRUE(read.ok()) << read.error();
  ASSERT_EQ(read.warnings().size(), 3u);
  EXPECT_NE(read.warnings()[1].find("view 'AP': unknown key 'colour'"), std::string::npos) << read.warnings()[1];
  EXPECT_NE(read.warnings()[2].find("'detector.vendor'"), std::string::npos) << read.warnings()[2];
}

TEST(ViewFile, RejectsNaNNamingLineColumnAndKey) {
  std::string text = json{{"views", {validView("AP")}}}.dump(2);
  text.replace(text.find("1500"), 4, "NaN");
  const auto result = readText(text);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("views.json"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("line "), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("column "), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("views[0].source_to_detector_mm"), std::string::npos) << result.error();
}

TEST(ViewFile, RejectsANumberGivenAsAStringNamingViewAndKey) {
  json view = validView("AP");
  view["principal_point_px"] = {399.5, "Infinity"};
  const std::string error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("view 'AP': key 'principal_point_px[1]' must be a number"), std::string::npos) << error;
}

TEST(ViewFile, RejectsANonRotation) {
  json view = validView("AP");
  view["T_world_from_camera"][0][0] = 2.0;
  const std::string error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("view 'AP': T_world_from_camera's 3x3 part is not a rotation"), std::string::npos) << error;
}

TEST(ViewFile, RejectsAZeroSizedDetectorAndZeroSpacing) {
  json view = validView("AP");
  view["detector"]["cols"] = 0;
  std::string error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("view 'AP': key 'detector.cols' must be a whole number >= 1, got 0"), std::string::npos) << error;
  view = validView("AP");
  view["detector"]["pixel_spacing_mm"] = {0.4, 0.0};
  error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("'detector.pixel_spacing_mm' must be positive"), std::string::npos) << error;
}

TEST(ViewFile, RejectsAnImplausiblePrincipalPoint) {
  json view = validView("AP");
  view["principal_point_px"] = {5000.0, 299.5};
  const std::string error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("view 'AP': principal point"), std::string::npos) << error;
}

TEST(ViewFile, RejectsAMissingImageNamingThePath) {
  json view = validView("AP");
  view["image"] = {{"path", "xray/missing.dcm"}, {"frame", 0}};
  const std::string error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("view 'AP': key 'image'"), std::string::npos) << error;
  EXPECT_NE(error.find("xray/missing.dcm"), std::string::npos) << error;
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
}

TEST(ViewFile, RejectsBothAndNeitherCameraForms) {
  json both = validView("AP");
  both["projection_matrix"] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
  std::string error = readError(json{{"views", {both}}});
  EXPECT_NE(error.find("view 'AP': gives both projection_matrix and T_world_from_camera"), std::string::npos) << error;
  json neither = validView("AP");
  neither.erase("T_world_from_camera");
  neither.erase("source_to_detector_mm");
  neither.erase("principal_point_px");
  error = readError(json{{"views", {neither}}});
  EXPECT_NE(error.find("view 'AP': has no camera"), std::string::npos) << error;
}

TEST(ViewFile, RejectsAnIncompleteIntrinsicsForm) {
  json view = validView("AP");
  view.erase("source_to_detector_mm");
  const std::string error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("view 'AP': key 'source_to_detector_mm' is missing"), std::string::npos) << error;
}

TEST(ViewFile, RejectsBadJsonWithLineAndColumn) {
  const auto result = readText("{\n  \"views\": [\n    {\"name\": \"AP\" \"detector\": {}}\n  ]\n}\n");
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("not valid JSON"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("line 3, column"), std::string::npos) << result.error();
}

TEST(ViewFile, RejectsDuplicateEmptyAndMissingViews) {
  std::string error = readError(json{{"views", {validView("AP"), validView("AP")}}});
  EXPECT_NE(error.find("views[1]: view name 'AP' is used twice"), std::string::npos) << error;
  error = readError(json{{"views", {validView("")}}});
  EXPECT_NE(error.find("views[0]: key 'name' must not be empty"), std::string::npos) << error;
  error = readError(json{{"views", json::array()}});
  EXPECT_NE(error.find("key 'views' must be a non-empty array"), std::string::npos) << error;
  error = readError(json{{"cameras", {validView("AP")}}});
  EXPECT_NE(error.find("key 'views' must be a non-empty array of views, got nothing"), std::string::npos) << error;
}

TEST(ViewFile, ReadFailsOnAMissingFile) {
  const auto result = fct::ViewFile::read(fct::test::scratchDir() / "nope.json");
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("nope.json' not found"), std::string::npos) << result.error();
}

TEST(ViewFile, WriteFailsOnUnwritablePathOrDuplicateNamesAndWritesNothing) {
  const auto dir = fct::test::scratchDir();
  std::vector<fct::ViewSpec> views(1);
  views[0].name = "AP";
  views[0].camera = obliqueCamera(0.2, 0.0);
  auto status = fct::ViewFile::write(views, dir / "no_such_folder" / "views.json");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("no_such_folder/views.json"), std::string::npos) << status.error();

  views.push_back(views[0]);
  status = fct::ViewFile::write(views, dir / "views.json");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("'AP' is used twice"), std::string::npos) << status.error();
  views.pop_back();
  views[0].camera = fct::Camera();  // 0 x 0 detector
  status = fct::ViewFile::write(views, dir / "views.json");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("view 'AP': detector size must be positive"), std::string::npos) << status.error();
  EXPECT_FALSE(fct::ViewFile::write({}, dir / "views.json").ok());
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(ViewFile, DewarpPathIsRelativeToTheViewFileAndRoundTrips) {
  const auto dir = fct::test::scratchDir();
  touch(dir / "sub" / "calibration" / "ii.dewarp.json");
  json view = validView("AP");
  view["dewarp"] = "calibration/ii.dewarp.json";
  const auto path = dir / "sub" / "views.json";
  ASSERT_TRUE(fct::TextFile::writeAtomically(path, json{{"views", {view}}}.dump()).ok());
  const auto read = fct::ViewFile::read(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(read.warnings().empty());
  const auto expected = std::filesystem::absolute(dir / "sub" / "calibration" / "ii.dewarp.json").lexically_normal();
  EXPECT_EQ(read.value()[0].dewarpPath, expected);
  ASSERT_TRUE(fct::ViewFile::write(read.value(), path).ok());
  const json written = json::parse(fct::TextFile::read(path).value());
  EXPECT_EQ(written["views"][0]["dewarp"], "calibration/ii.dewarp.json");
  EXPECT_EQ(fct::ViewFile::read(path).value()[0].dewarpPath, expected);
}

TEST(ViewFile, RejectsAMissingDewarpFileNamingTheCommandThatMakesIt) {
  json view = validView("AP");
  view["dewarp"] = "missing.dewarp.json";
  const std::string error = readError(json{{"views", {view}}});
  EXPECT_NE(error.find("view 'AP': key 'dewarp'"), std::string::npos) << error;
  EXPECT_NE(error.find("dewarp-calibrate"), std::string::npos) << error;
}
