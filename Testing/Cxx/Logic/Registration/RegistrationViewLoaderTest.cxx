// RegistrationViewLoader: a view file with its PNG images becomes registration views; a view without an image, an
// unreadable image and an image of the wrong size are refused naming the file and the view; a view's dewarp file
// resamples its image and moves its spheres.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "Base/JsonDocument.h"
#include "IO/Project/DewarpFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Xray/ImageFileWriter.h"
#include "Registration/RegistrationViewLoader.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

fct::Camera camera(int cols, int rows, double angle_rad) {
  const Eigen::Matrix3d R_world_from_camera = Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitY()).matrix();
  return fct::Camera::lookingAt(Eigen::Vector3d::Zero(), R_world_from_camera, 700.0, 1000.0, cols, rows, 1.0);
}

/// A gradient image of `cols` x `rows` pixels written as PNG.
void writeImage(const fs::path& path, int cols, int rows) {
  fct::FloatImage image = fct::FloatImage::filled(cols, rows);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<float>(i % 97) / 97.0f;
  ASSERT_TRUE(fct::ImageFileWriter::writePng16(image, path, 0.0f, 1.0f).ok());
}

/// Two views "ap" and "lat" (48 x 32 detectors); "lat" has a calibration sphere.
std::vector<fct::ViewSpec> twoViews(const fs::path& dir) {
  fct::ViewSpec ap{"ap", dir / "ap.png", 0, camera(48, 32, 0.0), {}, {}, false, std::nullopt};
  fct::ViewSpec lat{"lat", dir / "lat.png", 0, camera(48, 32, 1.5707963), {{{10.5, 12.0}, 3.0}}, {}, false,
                    std::nullopt};
  return {ap, lat};
}

}  // namespace

TEST(RegistrationViewLoader, LoadsEveryViewWithItsImageCameraAndSpheresInFileOrder) {
  const fs::path dir = fct::test::scratchDir();
  writeImage(dir / "ap.png", 48, 32);
  writeImage(dir / "lat.png", 48, 32);
  const std::vector<fct::ViewSpec> specs = twoViews(dir);
  ASSERT_TRUE(fct::ViewFile::write(specs, dir / "views.json").ok());

  auto views = fct::RegistrationViewLoader::load(dir / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(views.value().size(), 2u);
  EXPECT_EQ(views.value()[0].name, "ap");
  EXPECT_EQ(views.value()[1].name, "lat");
  EXPECT_EQ(views.value()[1].xray.cols, 48);
  EXPECT_EQ(views.value()[1].xray.rows, 32);
  EXPECT_TRUE(views.value()[1].camera.P_px_from_world().isApprox(specs[1].camera.P_px_from_world(), 1e-9));
  EXPECT_TRUE(views.value()[0].spheres.empty());
  ASSERT_EQ(views.value()[1].spheres.size(), 1u);
  EXPECT_EQ(views.value()[1].spheres[0].centre_px, Eigen::Vector2d(10.5, 12.0));
  EXPECT_EQ(views.value()[1].spheres[0].radius_px, 3.0);
}

TEST(RegistrationViewLoader, FlipsAViewMarkedMirrorColumnsLeftRight) {
  const fs::path dir = fct::test::scratchDir();
  writeImage(dir / "ap.png", 48, 32);
  writeImage(dir / "lat.png", 48, 32);
  std::vector<fct::ViewSpec> specs = twoViews(dir);
  specs[1].mirrorColumns = true;
  ASSERT_TRUE(fct::ViewFile::write(specs, dir / "views.json").ok());
  auto views = fct::RegistrationViewLoader::load(dir / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  const fct::XrayImage& plain = views.value()[0].xray;
  const fct::XrayImage& mirrored = views.value()[1].xray;  // the same gradient, flipped
  for (int row : {0, 17, 31}) {
    for (int col : {0, 5, 47}) EXPECT_FLOAT_EQ(mirrored.at(col, row), plain.at(47 - col, row)) << col << "," << row;
  }
}

TEST(RegistrationViewLoader, RefusesAViewWithoutAnImageNamingFileAndView) {
  const fs::path dir = fct::test::scratchDir();
  writeImage(dir / "ap.png", 48, 32);
  std::vector<fct::ViewSpec> specs = twoViews(dir);
  specs[1].imagePath.clear();
  ASSERT_TRUE(fct::ViewFile::write(specs, dir / "views.json").ok());
  auto views = fct::RegistrationViewLoader::load(dir / "views.json");
  ASSERT_FALSE(views.ok());
  EXPECT_NE(views.error().find((dir / "views.json").string() + ": view 'lat' has no image"), std::string::npos)
      << views.error();
  EXPECT_NE(views.error().find("\"image\""), std::string::npos) << "says which key to add: " << views.error();
}

TEST(RegistrationViewLoader, RefusesAMissingImageAndOneOfTheWrongSize) {
  const fs::path dir = fct::test::scratchDir();
  writeImage(dir / "ap.png", 48, 32);
  ASSERT_TRUE(fct::ViewFile::write(twoViews(dir), dir / "views.json").ok());
  auto missing = fct::RegistrationViewLoader::load(dir / "views.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("view 'lat'"), std::string::npos) << missing.error();
  EXPECT_NE(missing.error().find("lat.png"), std::string::npos) << missing.error();

  writeImage(dir / "lat.png", 40, 32);
  auto wrongSize = fct::RegistrationViewLoader::load(dir / "views.json");
  ASSERT_FALSE(wrongSize.ok());
  EXPECT_NE(wrongSize.error().find("view 'lat': the image is 40x32 pixels but the detector is 48x32"),
            std::string::npos)
      << wrongSize.error();
}

TEST(RegistrationViewLoader, PassesOnViewFileErrorsAndWarnings) {
  const fs::path dir = fct::test::scratchDir();
  std::ofstream(dir / "broken.json") << "{\"views\": [";
  auto broken = fct::RegistrationViewLoader::load(dir / "broken.json");
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.error().find("broken.json"), std::string::npos) << broken.error();

  writeImage(dir / "ap.png", 48, 32);
  writeImage(dir / "lat.png", 48, 32);
  ASSERT_TRUE(fct::ViewFile::write(twoViews(dir), dir / "views.json").ok());
  auto json = fct::JsonDocument::parse(dir / "views.json");
  ASSERT_TRUE(json.ok()) << json.error();
  nlohmann::json withNote = json.value();
  withNote["note"] = "made by hand";
  std::ofstream(dir / "noted.json") << withNote.dump(2);
  auto noted = fct::RegistrationViewLoader::load(dir / "noted.json");
  ASSERT_TRUE(noted.ok()) << noted.error();
  ASSERT_EQ(noted.warnings().size(), 1u);
  EXPECT_NE(noted.warnings()[0].find("'note'"), std::string::npos) << noted.warnings()[0];
}

namespace {

/// A degree-3 dewarp of a 48 x 32 detector that moves pixels towards the centre by 0.05 R rho^2.
fct::DewarpFileContents barrelCorrection(int cols, int rows) {
  const auto terms = fct::DewarpField::terms(3);
  Eigen::VectorXd col = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(terms.size())), row = col;
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const auto i = static_cast<Eigen::Index>(t);
    if (terms[t] == std::array<int, 2>{3, 0} || terms[t] == std::array<int, 2>{1, 2}) col[i] = -0.05;
    if (terms[t] == std::array<int, 2>{0, 3} || terms[t] == std::array<int, 2>{2, 1}) row[i] = -0.05;
  }
  return {fct::DewarpField::create(cols, rows, 3, col, row).value(), {}};
}

}  // namespace

TEST(RegistrationViewLoader, AViewsDewarpResamplesItsImageAndMovesItsSpheres) {
  const fs::path dir = fct::test::scratchDir();
  writeImage(dir / "ap.png", 48, 32);
  writeImage(dir / "lat.png", 48, 32);
  const fct::DewarpFileContents dewarp = barrelCorrection(48, 32);
  ASSERT_TRUE(fct::DewarpFile::write(dewarp, dir / "ii.dewarp.json").ok());
  std::vector<fct::ViewSpec> specs = twoViews(dir);
  specs[1].dewarpPath = dir / "ii.dewarp.json";
  ASSERT_TRUE(fct::ViewFile::write(specs, dir / "views.json").ok());
  auto views = fct::RegistrationViewLoader::load(dir / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  EXPECT_TRUE(views.value()[0].xray.fovMask.empty());
  const fct::XrayImage& lat = views.value()[1].xray;
  ASSERT_EQ(lat.fovMask.size(), 48u * 32u);
  // Ideal pixel u shows the stored pixel d(u); the stored image is i % 97 / 97, read back from 16-bit PNG (x 65535).
  const Eigen::Vector2d u(40.0, 5.0);
  const Eigen::Vector2d d = dewarp.field.distorted(u).value();
  ASSERT_GT((d - u).norm(), 0.5);
  const auto stored = [&](int c, int r) { return std::round(65535.0f * static_cast<float>((r * 48 + c) % 97) / 97.0f); };
  const int c0 = static_cast<int>(d.x()), r0 = static_cast<int>(d.y());
  const float fc = static_cast<float>(d.x() - c0), fr = static_cast<float>(d.y() - r0);
  const float expected = (1 - fr) * ((1 - fc) * stored(c0, r0) + fc * stored(c0 + 1, r0)) +
                         fr * ((1 - fc) * stored(c0, r0 + 1) + fc * stored(c0 + 1, r0 + 1));
  EXPECT_NEAR(lat.at(40, 5), expected, 0.5);
  ASSERT_EQ(views.value()[1].spheres.size(), 1u);
  EXPECT_LT((views.value()[1].spheres[0].centre_px - dewarp.field.ideal(Eigen::Vector2d(10.5, 12.0))).norm(), 1e-12);
}

TEST(RegistrationViewLoader, RefusesADewarpCalibratedForAnotherImageSize) {
  const fs::path dir = fct::test::scratchDir();
  writeImage(dir / "ap.png", 48, 32);
  writeImage(dir / "lat.png", 48, 32);
  ASSERT_TRUE(fct::DewarpFile::write(barrelCorrection(64, 48), dir / "ii.dewarp.json").ok());
  std::vector<fct::ViewSpec> specs = twoViews(dir);
  specs[0].dewarpPath = dir / "ii.dewarp.json";
  ASSERT_TRUE(fct::ViewFile::write(specs, dir / "views.json").ok());
  auto views = fct::RegistrationViewLoader::load(dir / "views.json");
  ASSERT_FALSE(views.ok());
  EXPECT_NE(views.error().find("view 'ap'"), std::string::npos) << views.error();
  EXPECT_NE(views.error().find("calibrated for 64x48"), std::string::npos) << views.error();
}
