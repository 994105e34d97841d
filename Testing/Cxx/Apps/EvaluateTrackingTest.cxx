// fluoroct evaluate --study tracking: the quick version end to end on the built-in phantom (every frame stored with
// its errors, the summary and the report), resume by sequence, and the options the tracking study refuses.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "Base/TextFile.h"
#include "Evaluation/TrackingFrameStore.h"
#include "Evaluation/TrackingStudy.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

int lineCount(const fs::path& path) {
  std::ifstream in(path);
  int lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  return lines;
}

}  // namespace

TEST(EvaluateTracking, QuickStudyStoresEveryFrameWithItsErrorsAndWritesTheSummaryAndReport) {
  const fs::path out = fct::test::scratchDir() / "tracking-quick";
  const auto run = fct::test::runCli(fmt::format("evaluate --study tracking --quick --out '{}'", out.string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("[2/2]"), std::string::npos) << run.err;

  const fct::TrackingStudyDefinition study = fct::TrackingStudy::define(true, {"phantom"}).value();
  const int frames = study.motion.frames;
  const auto store = fct::TrackingFrameStore::open(out);
  ASSERT_TRUE(store.ok()) << store.error();
  ASSERT_EQ(static_cast<int>(store.value().records().size()), frames * static_cast<int>(study.conditions.size()));
  for (const fct::TrackingFrameRecord& r : store.value().records()) {
    SCOPED_TRACE(fmt::format("{} frame {}", r.condition, r.frame));
    EXPECT_TRUE(r.status == "tracked" || r.status == "recovered" || r.status == "lost") << r.status << " " << r.reason;
    EXPECT_FALSE(r.cancelled);
    EXPECT_GT(r.drrs, 0);
    EXPECT_TRUE(std::isfinite(r.streMean_mm));
    EXPECT_LE(r.streMean_mm, r.streMax_mm + 1e-9);
    if (r.frame > 0) {
      EXPECT_GT(r.motionFromFirst_mm, 0.0) << "the bone moves";
    }
    if (r.views == 1) {
      EXPECT_LE(r.inPlane_mm, r.streMean_mm + 1e-6);
      EXPECT_LE(r.outOfPlane_mm, r.streMean_mm + 1e-6);
    } else {
      EXPECT_TRUE(std::isnan(r.inPlane_mm));
    }
  }
  EXPECT_EQ(lineCount(out / "frames.csv"), 1 + static_cast<int>(store.value().records().size()));
  EXPECT_EQ(lineCount(out / "summary.csv"), 1 + static_cast<int>(study.conditions.size()));
  const std::string report = fct::TextFile::read(out / "report.md").value();
  for (const fct::TrackingCondition& c : study.conditions) {
    EXPECT_NE(report.find("| " + c.name + " |"), std::string::npos) << report;
  }
  EXPECT_NE(report.find("frames/s"), std::string::npos);

  // Resume: every sequence is stored, so nothing runs again and the frames stay as they were.
  const std::string before = fct::TextFile::read(out / "frames.json").value();
  const auto again = fct::test::runCli(fmt::format("evaluate --study tracking --quick --out '{}'", out.string()));
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_NE(again.out.find("ran 0 sequences, skipped 2"), std::string::npos) << again.out;
  EXPECT_EQ(fct::TextFile::read(out / "frames.json").value(), before);
}

TEST(EvaluateTracking, OptionsTheTrackingStudyDoesNotTakeAreRefusedBeforeAnythingIsWritten) {
  const fs::path out = fct::test::scratchDir() / "tracking-refused";
  for (const char* extra : {"--shard 1/2", "--detector 64x64", "--jobs 2", "--preset nosuchpreset"}) {
    SCOPED_TRACE(extra);
    const auto run =
        fct::test::runCli(fmt::format("evaluate --study tracking --quick --out '{}' {}", out.string(), extra));
    EXPECT_NE(run.exitCode, 0);
    EXPECT_FALSE(run.err.empty());
    EXPECT_FALSE(fs::exists(out / "frames.json"));
  }
  EXPECT_FALSE(fs::exists(out / "setup.txt"));
}
