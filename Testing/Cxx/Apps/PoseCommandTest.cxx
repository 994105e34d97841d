#include <fmt/core.h>
#include <gtest/gtest.h>

#include "Image/BoneSurface.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "Simulation/PhantomBuilder.h"
#include "TestSupport.h"

TEST(PoseCommand, WritesARandomStartPoseAtTheRequestedSurfaceDistance) {
  const auto dir = fct::test::scratchDir();
  fct::PhantomOptions small;
  small.dims = Eigen::Vector3i(64, 64, 48);
  small.spacing_mm = 2.0;
  const fct::Volume ct = fct::PhantomBuilder::build(small).value();
  ASSERT_TRUE(fct::VolumeFileIO::write(ct, dir / "ct.nrrd").ok());
  const auto run = fct::test::runCli(fmt::format("pose --ct '{}' --rotate-deg 0 0 5 --out '{}' ", (dir / "ct.nrrd").string(),
                                                 (dir / "truth.json").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto start = fct::test::runCli(fmt::format("pose --ct '{}' --from '{}' --random-offset-mm 10 --seed 2 --out '{}'",
                                                   (dir / "ct.nrrd").string(), (dir / "truth.json").string(),
                                                   (dir / "start.json").string()));
  ASSERT_EQ(start.exitCode, 0) << start.err;
  const auto truth = fct::PoseFile::read(dir / "truth.json");
  const auto initial = fct::PoseFile::read(dir / "start.json");
  ASSERT_TRUE(truth.ok() && initial.ok());
  const auto bone = fct::BoneSurface::extract(ct).value();
  EXPECT_NEAR(bone.meanDistance_mm(initial.value(), truth.value()), 10.0, 1e-2);
  EXPECT_NE(start.out.find("10.000 mm"), std::string::npos) << start.out;
}

TEST(PoseCommand, BadInputGivesOneErrorLine) {
  const auto dir = fct::test::scratchDir();
  for (const std::string& arguments :
       {fmt::format("pose --ct /nonexistent.nrrd --out '{}'", (dir / "p.json").string()),
        fmt::format("pose --ct /nonexistent.nrrd --from /nonexistent.json --out '{}'", (dir / "p.json").string())}) {
    const auto run = fct::test::runCli(arguments);
    EXPECT_EQ(run.exitCode, 2) << arguments;
    EXPECT_EQ(run.err.rfind("error: ", 0), 0u) << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "p.json"));
  }
}
