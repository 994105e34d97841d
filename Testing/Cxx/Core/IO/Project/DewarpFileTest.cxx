#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "Base/JsonDocument.h"
#include "Base/TextFile.h"
#include "IO/Project/DewarpFile.h"
#include "TestSupport.h"

namespace {

/// A degree-4 field of a 320x240 detector with arbitrary small coefficients and a calibration record.
fct::DewarpFileContents sampleContents() {
  const auto count = static_cast<Eigen::Index>(fct::DewarpField::terms(4).size());
  Eigen::VectorXd col(count), row(count);
  for (Eigen::Index i = 0; i < count; ++i) {
    col[i] = 0.001 * (i + 1);
    row[i] = -0.0007 * (i + 2);
  }
  fct::DewarpCalibration calibration;
  calibration.gridImage = "ap_grid.png";
  calibration.pitch_mm = 10.0;
  calibration.latticePitch_px = 12.75;
  calibration.beadCount = 420;
  calibration.rmsResidual_px = 0.031;
  calibration.maxResidual_px = 0.12;
  return {fct::DewarpField::create(320, 240, 4, col, row).value(), calibration};
}

/// The written sample file as JSON, for editing into a bad file.
nlohmann::json sampleJson(const std::filesystem::path& path) {
  EXPECT_TRUE(fct::DewarpFile::write(sampleContents(), path).ok());
  return fct::JsonDocument::parse(path).value();
}

/// Writes `document` to `path` and returns the read error ("" when it reads).
std::string readError(const nlohmann::json& document, const std::filesystem::path& path) {
  EXPECT_TRUE(fct::TextFile::writeAtomically(path, document.dump(2)).ok());
  auto read = fct::DewarpFile::read(path);
  return read.ok() ? std::string() : read.error();
}

}  // namespace

TEST(DewarpFile, RoundTripsTheFieldAndItsCalibrationRecord) {
  const auto path = fct::test::scratchDir() / "dewarp.json";
  const fct::DewarpFileContents written = sampleContents();
  ASSERT_TRUE(fct::DewarpFile::write(written, path).ok());
  auto read = fct::DewarpFile::read(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(read.warnings().empty());
  const fct::DewarpField& field = read.value().field;
  EXPECT_EQ(field.cols(), 320);
  EXPECT_EQ(field.rows(), 240);
  EXPECT_EQ(field.degree(), 4);
  EXPECT_LT((field.colCoefficients_px() - written.field.colCoefficients_px()).norm(), 1e-15);
  EXPECT_LT((field.rowCoefficients_px() - written.field.rowCoefficients_px()).norm(), 1e-15);
  const Eigen::Vector2d p(17.5, 201.25);
  EXPECT_LT((field.ideal(p) - written.field.ideal(p)).norm(), 1e-12);
  EXPECT_EQ(read.value().calibration.gridImage, "ap_grid.png");
  EXPECT_EQ(read.value().calibration.beadCount, 420);
  EXPECT_DOUBLE_EQ(read.value().calibration.rmsResidual_px, 0.031);
}

TEST(DewarpFile, BadFilesGiveErrorsNamingTheKey) {
  const auto dir = fct::test::scratchDir();
  const auto path = dir / "bad.json";
  nlohmann::json other = sampleJson(path);
  other["format"] = "fluoroct-studio-session";
  EXPECT_NE(readError(other, path).find("not a FluoroCT dewarp file"), std::string::npos) << readError(other, path);
  nlohmann::json newer = sampleJson(path);
  newer["version"] = 99;
  EXPECT_NE(readError(newer, path).find("update FluoroCT"), std::string::npos);
  nlohmann::json model = sampleJson(path);
  model["model"] = "thin-plate";
  EXPECT_NE(readError(model, path).find("'model'"), std::string::npos);
  nlohmann::json shortCoefficients = sampleJson(path);
  shortCoefficients["col_coefficients_px"].erase(0);
  EXPECT_NE(readError(shortCoefficients, path).find("col_coefficients_px"), std::string::npos);
  nlohmann::json terms = sampleJson(path);
  terms["terms"][0] = {1, 1};
  EXPECT_NE(readError(terms, path).find("'terms' row 0"), std::string::npos);
  nlohmann::json size = sampleJson(path);
  size["image_size"] = {640, 240};
  EXPECT_NE(readError(size, path).find("centre_px"), std::string::npos) << readError(size, path);
  nlohmann::json missing = sampleJson(path);
  missing.erase("image_size");
  EXPECT_NE(readError(missing, path).find("image_size"), std::string::npos);
  EXPECT_FALSE(fct::DewarpFile::read(dir / "absent.json").ok());
}
