#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "IO/Xray/XrayImageFileReader.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

// µ_water at 60 keV in 1/mm, as documented for `--values attenuation`.
constexpr double kWater_per_mm = 0.02059;

/// A scratch folder with a uniform 1000 HU slab CT (20 x 24 x 30 voxels of 2 mm, centred at the origin, so 60 mm
/// thick along z) and a view file with an axial view "AP" (pixel (32,24) on the axis through the centre) and an
/// oblique view "Left lat".
struct DrrFixture {
  fs::path dir = fct::test::scratchDir();
  fs::path ct = dir / "ct.nrrd";
  fs::path views = dir / "views.json";
  fs::path out = dir / "out";

  DrrFixture() {
    fct::Volume volume = fct::Volume::create({20, 24, 30}, {2.0, 2.0, 2.0}, {-19.0, -23.0, -29.0}, Eigen::Matrix3d::Identity(),
                                             1000.0f)
                             .value();
    EXPECT_TRUE(fct::VolumeFileIO::write(volume, ct).ok());
    fct::ViewSpec ap{"AP", {}, 0, fct::Camera::lookingAt(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 600.0,
                                                         1000.0, 65, 49, 1.0),
                     {}, {}, false, std::nullopt};
    fct::ViewSpec lat{"Left lat", {}, 0,
                      fct::Camera::lookingAt(Eigen::Vector3d::Zero(),
                                             Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitY()).toRotationMatrix(), 600.0,
                                             1000.0, 40, 30, 1.5),
                      {}, {}, false, std::nullopt};
    EXPECT_TRUE(fct::ViewFile::write({ap, lat}, views).ok());
    fs::create_directories(out);
  }
  std::string baseArguments() const { return fmt::format("drr --ct '{}' --views '{}'", ct.string(), views.string()); }
};

fct::XrayImage readTiff(const fs::path& path) {
  auto image = fct::XrayImageFileReader::read(path);
  EXPECT_TRUE(image.ok()) << image.error();
  return image.ok() ? image.value() : fct::XrayImage{};
}

}  // namespace

TEST(DrrCommand, WritesOneFloatImagePerViewWithTheSlabLineIntegral) {
  const DrrFixture f;
  const auto run = fct::test::runCli(f.baseArguments() + fmt::format(" --out '{}'", (f.out / "drr.tif").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 2) << run.out;
  const fct::XrayImage ap = readTiff(f.out / "drr_AP.tif");
  ASSERT_EQ(ap.cols, 65);
  ASSERT_EQ(ap.rows, 49);
  // The central ray crosses 60 mm of 1000 HU: ∫µ dl = 2 µ_water · 60 mm.
  EXPECT_NEAR(ap.at(32, 24), 2.0 * kWater_per_mm * 60.0, 1e-4);
  const fct::XrayImage lat = readTiff(f.out / "drr_Left_lat.tif");
  EXPECT_EQ(lat.cols, 40);
  EXPECT_GT(*std::max_element(lat.pixels.begin(), lat.pixels.end()), 1.0f);
}

TEST(DrrCommand, RendersOneViewAtALevelWithRawValuesAndAPose) {
  const DrrFixture f;
  const auto raw = fct::test::runCli(f.baseArguments() + fmt::format(" --view AP --level 1 --values raw --method raycast "
                                                                     "--out '{}'",
                                                                     (f.out / "raw.tif").string()));
  ASSERT_EQ(raw.exitCode, 0) << raw.err;
  EXPECT_FALSE(fs::exists(f.out / "raw_Left_lat.tif"));
  const fct::XrayImage level1 = readTiff(f.out / "raw_AP.tif");
  ASSERT_EQ(level1.cols, 32);
  ASSERT_EQ(level1.rows, 24);
  EXPECT_NEAR(level1.at(16, 12), 1000.0 * 60.0, 1.0);  // raw: 1000 HU x 60 mm

  // Moving the CT 500 mm sideways takes it out of the AP view: all zeros.
  const fs::path pose = f.dir / "pose.json";
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(500.0, 0.0, 0.0);
  ASSERT_TRUE(fct::PoseFile::write(T, pose).ok());
  const auto moved = fct::test::runCli(f.baseArguments() + fmt::format(" --view AP --pose '{}' --out '{}'", pose.string(),
                                                                       (f.out / "moved.tif").string()));
  ASSERT_EQ(moved.exitCode, 0) << moved.err;
  const fct::XrayImage empty = readTiff(f.out / "moved_AP.tif");
  EXPECT_EQ(*std::max_element(empty.pixels.begin(), empty.pixels.end()), 0.0f);
}

TEST(DrrCommand, TransgraphMethodMatchesSiddonAndCachesItsTable) {
  const DrrFixture f;
  const fs::path cache = f.dir / "cache";
  const std::string transgraph = fmt::format(" --view AP --method transgraph --transgraph-spacing-mm 2 "
                                             "--transgraph-cache '{}' --out '{}'",
                                             cache.string(), (f.out / "tg.tif").string());
  const auto first = fct::test::runCli(f.baseArguments() + transgraph);
  ASSERT_EQ(first.exitCode, 0) << first.err;
  ASSERT_TRUE(fs::is_directory(cache));
  EXPECT_EQ(std::distance(fs::directory_iterator(cache), fs::directory_iterator{}), 1);
  const auto second = fct::test::runCli(f.baseArguments() + transgraph);  // loads the cached table
  ASSERT_EQ(second.exitCode, 0) << second.err;
  const auto exact = fct::test::runCli(f.baseArguments() + fmt::format(" --view AP --out '{}'", (f.out / "ex.tif").string()));
  ASSERT_EQ(exact.exitCode, 0) << exact.err;
  const fct::XrayImage table = readTiff(f.out / "tg_AP.tif");
  const fct::XrayImage siddon = readTiff(f.out / "ex_AP.tif");
  ASSERT_EQ(table.pixels.size(), siddon.pixels.size());
  EXPECT_NEAR(table.at(32, 24), siddon.at(32, 24), 0.01 * siddon.at(32, 24));
}

TEST(DrrCommand, WritesPfmNrrdAndWindowedPng) {
  const DrrFixture f;
  for (const char* ext : {"pfm", "nrrd", "png"}) {
    SCOPED_TRACE(ext);
    const auto run = fct::test::runCli(f.baseArguments() + fmt::format(" --view AP --out '{}'",
                                                                       (f.out / fmt::format("d.{}", ext)).string()));
    ASSERT_EQ(run.exitCode, 0) << run.err;
    const fs::path written = f.out / fmt::format("d_AP.{}", ext);
    ASSERT_TRUE(fs::exists(written));
    if (std::string(ext) == "pfm") {
      EXPECT_GE(fs::file_size(written), 65u * 49u * 4u);
    }
  }
  const auto png = fct::XrayImageFileReader::read(f.out / "d_AP.png");
  ASSERT_TRUE(png.ok()) << png.error();
  EXPECT_EQ(png.value().cols, 65);
  EXPECT_EQ(*std::max_element(png.value().pixels.begin(), png.value().pixels.end()), 65535.0f);
}

TEST(DrrCommand, FailsWithOneErrorLineAndWritesNothingOnBadInput) {
  const DrrFixture f;
  const std::string out = (f.out / "bad.tif").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {fmt::format("drr --ct '{}' --views '{}' --out '{}'", (f.dir / "missing.nrrd").string(), f.views.string(), out),
       "missing.nrrd"},
      {fmt::format("drr --ct '{}' --views '{}' --out '{}'", f.ct.string(), (f.dir / "none.json").string(), out),
       "none.json"},
      {f.baseArguments() + fmt::format(" --view PA --out '{}'", out), "AP, Left lat"},
      {f.baseArguments() + fmt::format(" --method raytrace --out '{}'", out), "'raycast' or 'transgraph'"},
      {f.baseArguments() + fmt::format(" --values hu --out '{}'", out), "'attenuation' or 'raw'"},
      {f.baseArguments() + fmt::format(" --out '{}'", (f.out / "bad.jpg").string()), ".nrrd, .pfm, .tif or .png"},
      {f.baseArguments() + fmt::format(" --out '{}'", (f.out / "no" / "d.tif").string()), "does not exist"},
      {f.baseArguments() + fmt::format(" --level 6 --out '{}'", out), "leaves no pixels"},
      {f.baseArguments() + fmt::format(" --level -1 --out '{}'", out), "--level"},
      {f.baseArguments() + fmt::format(" --pose '{}' --out '{}'", f.views.string(), out), "error: "},
      {f.baseArguments(), "--out"},
  };
  for (const auto& [arguments, expected] : cases) {
    SCOPED_TRACE(arguments);
    const auto run = fct::test::runCli(arguments);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(run.err.rfind("error: ", 0), 0u) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
  }
  EXPECT_TRUE(fs::is_empty(f.out)) << "nothing may be written after a failure";
}

TEST(DrrCommand, RefusesANonPositiveTransgraphSpacingWithOneErrorLine) {
  const DrrFixture f;
  for (const char* spacing : {"0", "-3", "abc"}) {
    SCOPED_TRACE(spacing);
    const auto run = fct::test::runCli(f.baseArguments() + fmt::format(" --method transgraph --transgraph-spacing-mm {} --out '{}'",
                                                                      spacing, (f.out / "tg.tif").string()));
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_NE(run.err.find("--transgraph-spacing-mm: must be a positive number"), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(f.out / "tg_AP.tif"));
  }
}
