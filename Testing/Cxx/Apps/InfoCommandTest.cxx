#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "TestSupport.h"

namespace {

/// Runs `fluoroct info ARGS --json` and parses stdout, which must be exactly one JSON object.
nlohmann::json infoJson(const std::string& arguments) {
  const auto run = fct::test::runCli("info " + arguments + " --json");
  EXPECT_EQ(run.exitCode, 0) << run.err;
  return nlohmann::json::parse(run.out);
}

void expectCleanError(const fct::test::ProcessResult& run, const std::string& needle) {
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_TRUE(run.out.empty()) << run.out;
  EXPECT_EQ(run.err.rfind("error: ", 0), 0u) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find(needle), std::string::npos) << run.err;
}

}  // namespace

TEST(InfoCommand, DescribesPhilipsHeadSeriesAsJson) {
  FCT_REQUIRE_DATA("ct/head_phantom_philips_bone");
  const auto info = infoJson("'" + (fct::test::dataDir() / "ct/head_phantom_philips_bone").string() + "'");
  EXPECT_EQ(info["type"], "ct");
  EXPECT_EQ(info["dims"], nlohmann::json::array({512, 512, 140}));
  EXPECT_NEAR(info["spacing_mm"][0].get<double>(), 0.451, 1e-3);
  EXPECT_NEAR(info["spacing_mm"][2].get<double>(), 1.0, 1e-3);
  EXPECT_EQ(info["origin_lps_mm"].size(), 3u);
  EXPECT_LE(info["hu_range"][0].get<double>(), -1000.0);
  EXPECT_EQ(info["series"].size(), 1u);
}

TEST(InfoCommand, DescribesPelvisNiftiInLps) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  const auto info = infoJson("'" + (fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz").string() + "'");
  EXPECT_EQ(info["dims"], nlohmann::json::array({122, 101, 112}));
  EXPECT_NEAR(info["hu_range"][0].get<double>(), -1207.0, 0.5);
  EXPECT_NEAR(info["hu_range"][1].get<double>(), 3382.0, 0.5);
}

TEST(InfoCommand, ReportsXrayGeometryFoundAndMissing) {
  FCT_REQUIRE_DATA("xray/dx_thorax_canine.dcm");
  const auto dx = infoJson("'" + (fct::test::dataDir() / "xray/dx_thorax_canine.dcm").string() + "'");
  EXPECT_EQ(dx["type"], "xray");
  EXPECT_EQ(dx["cols"], 211);
  EXPECT_EQ(dx["rows"], 169);
  EXPECT_EQ(dx["frames"], 1);
  EXPECT_TRUE(dx["geometry"].is_null());
  EXPECT_DOUBLE_EQ(dx["geometry_tags"]["source_to_detector_mm"].get<double>(), 1000.0);
  ASSERT_EQ(dx["missing_geometry"].size(), 1u);
  EXPECT_NE(dx["missing_geometry"][0].get<std::string>().find("DistanceSourceToPatient"), std::string::npos);

  const auto xa = infoJson("'" + (fct::test::dataDir() / "xray/xa_coronary_multiframe_jpeg.dcm").string() + "'");
  EXPECT_EQ(xa["frames"], 96);
  EXPECT_EQ(xa["modality"], "XA");
  EXPECT_DOUBLE_EQ(xa["geometry_tags"]["primary_angle_deg"].get<double>(), -32.0);
}

TEST(InfoCommand, BadInputsGiveOneErrorLineAndExitTwo) {
  const auto dir = fct::test::scratchDir();
  expectCleanError(fct::test::runCli("info /nonexistent/path"), "no such file");
  std::filesystem::create_directories(dir / "empty");
  expectCleanError(fct::test::runCli("info '" + (dir / "empty").string() + "'"), "no DICOM files");
  std::filesystem::create_directories(dir / "text");
  { std::ofstream(dir / "text" / "readme.txt") << "hello"; }
  expectCleanError(fct::test::runCli("info '" + (dir / "text").string() + "'"), "no DICOM files");
  { std::ofstream(dir / "broken.dcm") << std::string(132, '\0'); }
  const auto broken = fct::test::runCli("info '" + (dir / "broken.dcm").string() + "'");
  EXPECT_EQ(broken.exitCode, 2);
  EXPECT_EQ(broken.err.rfind("error: ", 0), 0u) << broken.err;
  expectCleanError(fct::test::runCli("info"), "PATH is required");
}

TEST(InfoCommand, FrameOutOfRangeIsAnError) {
  FCT_REQUIRE_DATA("xray/xa_coronary_multiframe_jpeg.dcm");
  expectCleanError(fct::test::runCli("info '" + (fct::test::dataDir() / "xray/xa_coronary_multiframe_jpeg.dcm").string() +
                                     "' --frame 96"),
                   "96 frame");
}

TEST(InfoCommand, RefusedIrregularSeriesNamesTheOptionThatRefusedIt) {
  FCT_REQUIRE_DATA("ct/head_phantom_philips_tilted");
  const auto run = fct::test::runCli(fmt::format("info '{}' --refuse-irregular",
                                                 (fct::test::dataDir() / "ct/head_phantom_philips_tilted").string()));
  expectCleanError(run, "gantry tilt 16.5");
  EXPECT_EQ(run.err.rfind("error: --refuse-irregular: series ", 0), 0u) << run.err;
  EXPECT_NE(run.err.find("leave out --refuse-irregular"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--resample-mm"), std::string::npos) << run.err;
}
