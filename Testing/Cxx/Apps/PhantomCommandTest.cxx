#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "IO/Volume/VolumeFileIO.h"
#include "TestSupport.h"

TEST(PhantomCommand, WritesAReadableVolume) {
  const auto dir = fct::test::scratchDir();
  for (const char* name : {"phantom.nrrd", "phantom.mha"}) {
    SCOPED_TRACE(name);
    const auto out = dir / name;
    const auto run = fct::test::runCli(fmt::format("phantom --out '{}' --dims 40 30 20 --spacing-mm 4 --seed 3",
                                                   out.string()));
    ASSERT_EQ(run.exitCode, 0) << run.err;
    EXPECT_NE(run.out.find("wrote"), std::string::npos) << run.out;
    EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << "one summary line expected: " << run.out;
    auto volume = fct::VolumeFileIO::read(out);
    ASSERT_TRUE(volume.ok()) << volume.error();
    EXPECT_EQ(volume.value().dims(), Eigen::Vector3i(40, 30, 20));
    EXPECT_EQ(volume.value().spacing_mm(), Eigen::Vector3d::Constant(4.0));
    EXPECT_NEAR(volume.value().centre_lps_mm().norm(), 0.0, 1e-9);
    EXPECT_EQ(volume.value().valueRange().first, -1000.0f);
    EXPECT_GT(volume.value().valueRange().second, 1000.0f);
  }
}

TEST(PhantomCommand, FailsCleanlyOnBadOutputAndOptions) {
  const auto dir = fct::test::scratchDir();
  const auto missing = fct::test::runCli(fmt::format("phantom --out '{}' --dims 8 8 8", (dir / "nope" / "p.nrrd").string()));
  EXPECT_EQ(missing.exitCode, 2);
  EXPECT_EQ(missing.err.rfind("error: ", 0), 0u) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;

  const auto badExtension = fct::test::runCli(fmt::format("phantom --out '{}' --dims 8 8 8", (dir / "p.png").string()));
  EXPECT_EQ(badExtension.exitCode, 2);
  EXPECT_NE(badExtension.err.find("error: "), std::string::npos);

  const auto badSpacing = fct::test::runCli(fmt::format("phantom --out '{}' --spacing-mm -1", (dir / "p.nrrd").string()));
  EXPECT_EQ(badSpacing.exitCode, 2);
  EXPECT_NE(badSpacing.err.find("spacing"), std::string::npos) << badSpacing.err;

  const auto badDims = fct::test::runCli(fmt::format("phantom --out '{}' --dims 8 0 8", (dir / "p.nrrd").string()));
  EXPECT_EQ(badDims.exitCode, 2);
  EXPECT_NE(badDims.err.find("error: "), std::string::npos);

  const auto noOut = fct::test::runCli("phantom --dims 8 8 8");
  EXPECT_EQ(noOut.exitCode, 2);
  EXPECT_NE(noOut.err.find("--out"), std::string::npos) << noOut.err;

  EXPECT_TRUE(std::filesystem::is_empty(dir)) << "nothing may be left behind after failures";
}
