// fluoroct track: end to end on a tiny simulated biplane sequence (outputs exist and parse, statuses, accuracy), and
// clear errors on bad inputs. Ctrl-C during tracking: FaultTest.cxx.
#include <gtest/gtest.h>

#include <fstream>

#include "Base/JsonDocument.h"
#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "SimulatedCliCase.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

std::string trackArgs(const fs::path& dir, const std::string& views, const std::string& out) {
  return fmt::format("track --ct '{}' --views '{}' --init '{}' --out '{}' --preset fast",
                     (dir / "ct.nrrd").string(), views, (dir / "init.json").string(), out);
}

}  // namespace

TEST(TrackCommand, TracksATinyBiplaneSequenceAndWritesJsonCsvAndPlot) {
  const fs::path dir = fct::test::scratchDir();
  const std::vector<Eigen::Isometry3d> truth = fct::test::makeTrackCase(dir, 4);
  ASSERT_TRUE(fct::PoseFile::write(fct::test::perturbed(truth[0]), dir / "init.json").ok());
  const auto run =
      fct::test::runCli(trackArgs(dir, (dir / "track_views.json").string(), (dir / "out").string()) +
                        " --level 0 --cut-face-margin-mm 2 --bone-contrast 1.5");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("tracked 4 of 4 frames"), std::string::npos) << run.out;
  EXPECT_NE(run.err.find("frame    3/4"), std::string::npos) << run.err;

  auto json = fct::JsonDocument::parse(dir / "out" / "track.json");
  ASSERT_TRUE(json.ok()) << json.error();
  const auto& frames = json.value().at("frames");
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(json.value().at("cancelled"), false);
  EXPECT_EQ(json.value().at("options").at("frame_drr"), "siddon") << "the automatic choice for two views";
  EXPECT_EQ(json.value().at("options").at("depth_scale"), 10.0);
  EXPECT_EQ(json.value().at("options").at("cut_face_margin_mm"), 2.0);
  EXPECT_EQ(json.value().at("options").at("bone_contrast"), 1.5);
  EXPECT_GT(json.value().at("frames_per_second").get<double>(), 0.0);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    EXPECT_EQ(frames[f].at("index"), static_cast<int>(f));
    EXPECT_EQ(frames[f].at("status"), "tracked") << "frame " << f;
    Eigen::Matrix4d T;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) T(r, c) = frames[f].at("T_world_from_ct")[r][c].get<double>();
    }
    EXPECT_LT((T.topRightCorner<3, 1>() - truth[f].translation()).norm(), 1.5) << "frame " << f;
  }
  std::ifstream csv(dir / "out" / "track.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header, "index,rx_deg,ry_deg,rz_deg,tx_mm,ty_mm,tz_mm,similarity,seconds,cpu_seconds,drrs,status");
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 4);
  EXPECT_GT(fs::file_size(dir / "out" / "track.png"), 1000u);
}

TEST(TrackCommand, BadInputsGiveOneClearErrorLine) {
  const fs::path dir = fct::test::scratchDir();
  fct::test::makeTrackCase(dir, 2);
  ASSERT_TRUE(fct::PoseFile::write(Eigen::Isometry3d::Identity(), dir / "init.json").ok());
  // A view file without sequences.
  auto run = fct::test::runCli(trackArgs(dir, (dir / "frame0" / "views.json").string(), (dir / "out").string()));
  EXPECT_TRUE(fct::test::oneErrorLine(run)) << run.err;
  EXPECT_NE(run.err.find("has no \"sequence\""), std::string::npos) << run.err;
  // Views whose sequences differ in length.
  auto views = fct::ViewFile::read(dir / "track_views.json");
  ASSERT_TRUE(views.ok()) << views.error();
  views.value()[0].sequence->files.pop_back();
  ASSERT_TRUE(fct::ViewFile::write(views.value(), dir / "uneven.json").ok());
  run = fct::test::runCli(trackArgs(dir, (dir / "uneven.json").string(), (dir / "out").string()));
  EXPECT_TRUE(fct::test::oneErrorLine(run)) << run.err;
  EXPECT_NE(run.err.find("same number of frames"), std::string::npos) << run.err;
  // No initial pose.
  run = fct::test::runCli(fmt::format("track --ct '{}' --views '{}' --out '{}'", (dir / "ct.nrrd").string(),
                                      (dir / "track_views.json").string(), (dir / "out").string()));
  EXPECT_TRUE(fct::test::oneErrorLine(run)) << run.err;
  EXPECT_NE(run.err.find("--init"), std::string::npos) << run.err;
  // Bad options, each with the words its one error line must hold.
  const std::vector<std::pair<std::string, std::string>> badOptions{
      {" --level 5", "level 5"},
      {" --igtl nohost", "--igtl"},
      {" --depth-velocity 2", "depth velocity"},
      {" --depth-scale 0.5", "depth scale"},
      {" --frame-drr transgraph", "--frame-drr"},
      {" --frame-drr box", "--frame-drr"},
      {" --confirm-mm 0", "confirmation tolerances"},
      {" --cut-face-margin-mm 600", "--cut-face-margin-mm"},
      {" --bone-contrast 0", "--bone-contrast"}};
  for (const auto& [option, expected] : badOptions) {
    run = fct::test::runCli(trackArgs(dir, (dir / "track_views.json").string(), (dir / "out").string()) + option);
    EXPECT_TRUE(fct::test::oneErrorLine(run)) << option << ": " << run.err;
    EXPECT_NE(run.err.find(expected), std::string::npos) << option << ": " << run.err;
  }
  EXPECT_FALSE(fs::exists(dir / "out")) << "a run that stops on bad input leaves no output folder";
}
