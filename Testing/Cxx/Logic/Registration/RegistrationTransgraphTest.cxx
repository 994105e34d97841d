// Registration with the transgraph DRR method: one table per view around the expected pose, served at every pyramid
// level, exact fallback outside the tables, the noTransgraph ablation, and tables built lazily at the initial pose.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>

#include "Registration/Registration.h"
#include "RegistrationTestCase.h"
#include "Simulation/PhantomBuilder.h"
#include "TestSupport.h"

namespace {

/// A coarse phantom case (80x80x60 at 2 mm, 3 views of 128x128 at 2.4 mm): small tables, quick registrations.
fct::test::KnownTruthCase coarseCase() {
  fct::PhantomOptions phantom;
  phantom.dims = Eigen::Vector3i(80, 80, 60);
  phantom.spacing_mm = 2.0;
  fct::test::KnownTruthOptions detector;
  detector.cols = detector.rows = 128;
  detector.pixelSpacing_mm = 2.4;
  auto simulated = fct::test::simulateCase(fct::PhantomBuilder::build(phantom).value(), detector);
  EXPECT_TRUE(simulated.ok()) << simulated.error();
  return std::move(simulated).value();
}

/// Transgraph case options: no disk cache (the tests must not write into the user's cache), 4 mm tables.
fct::RegistrationCaseOptions transgraphOptions() {
  fct::RegistrationCaseOptions options;
  options.drr.method = fct::DrrMethod::Transgraph;
  options.drr.transgraphCacheFolder = std::nullopt;
  options.drr.transgraph.spacing_mm = 4.0;
  return options;
}

fct::RegistrationOptions fastOptions() {
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin("fast").value();
  return options;
}

/// Pearson correlation of two equally sized images.
double correlation(const std::vector<float>& a, const std::vector<float>& b) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sa += a[i];
    sb += b[i];
    saa += double(a[i]) * a[i];
    sbb += double(b[i]) * b[i];
    sab += double(a[i]) * b[i];
  }
  const double n = static_cast<double>(a.size());
  return (sab - sa * sb / n) / std::sqrt((saa - sa * sa / n) * (sbb - sb * sb / n));
}

}  // namespace

TEST(RegistrationTransgraph, RegistersWithOneTablePerViewAroundTheInitialPose) {
  const fct::test::KnownTruthCase sim = coarseCase();
  auto siddonCase = fct::RegistrationCase::create(sim.ct, sim.views);
  ASSERT_TRUE(siddonCase.ok()) << siddonCase.error();
  const Eigen::Isometry3d start = fct::test::startPose(siddonCase.value(), sim.T_truth, 5.0, 21);

  fct::RegistrationCaseOptions options = transgraphOptions();
  options.T_expected_world_from_ct = start;
  auto created = fct::RegistrationCase::create(sim.ct, sim.views, options);
  ASSERT_TRUE(created.ok()) << created.error();
  fct::RegistrationCase& c = created.value();
  EXPECT_TRUE(c.viewRenderersReady());
  EXPECT_EQ(c.renderer().methodName(), "siddon") << "the exact renderer under the tables";
  for (std::size_t v = 0; v < c.viewCount(); ++v) {
    ASSERT_NE(c.transgraph(v), nullptr) << c.viewName(v);
    EXPECT_EQ(c.renderer(v).methodName(), "transgraph");
    EXPECT_GT(c.transgraph(v)->transgraph().rayCount(), 0u);
    if (v > 0) {
      EXPECT_NE(c.transgraph(v), c.transgraph(v - 1)) << "one table per view";
    }
  }

  auto result = fct::Registration::run(c, start, fastOptions());
  ASSERT_TRUE(result.ok()) << result.error();
  const auto& r = result.value();
  EXPECT_EQ(r.drrMethod, "transgraph");
  EXPECT_EQ(r.viewRendererSetupSeconds, 0.0) << "tables were built with the case";
  for (const auto& stage : r.stages) EXPECT_EQ(stage.fallbackRays, 0) << stage.name << ": poses stayed in the range";
  EXPECT_TRUE(r.schedule.stages.back().exactDrr) << "the full-resolution stage renders exactly (README)";
  const double error = c.bone()->meanDistance_mm(r.T_world_from_ct, sim.T_truth);
  std::printf("transgraph registration: 5 mm -> %.3f mm, %ld DRRs, %.2f s\n", error, r.totalDrrs, r.totalSeconds);
  EXPECT_LT(error, 0.5);
}

TEST(RegistrationTransgraph, TablesServeEveryPyramidLevelLikeTheExactRenderer) {
  const fct::test::KnownTruthCase sim = coarseCase();
  fct::RegistrationCaseOptions options = transgraphOptions();
  options.T_expected_world_from_ct = sim.T_truth;
  auto created = fct::RegistrationCase::create(sim.ct, sim.views, options);
  ASSERT_TRUE(created.ok()) << created.error();
  const fct::RegistrationCase& c = created.value();
  // A pose inside the range (3 deg, 4 mm away from the expected one), every view and level.
  Eigen::Isometry3d pose = sim.T_truth;
  pose.linear() = Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d(1, -1, 2).normalized()).toRotationMatrix() *
                  pose.linear();
  pose.translation() += Eigen::Vector3d(4.0, -2.0, 1.0);
  for (std::size_t v = 0; v < c.viewCount(); ++v) {
    for (int level = 0; level < c.levelCount(); ++level) {
      fct::DrrRenderStats stats;
      auto table = c.renderer(v).render(c.camera(v), pose, level, &stats);
      auto exact = c.renderer().render(c.camera(v), pose, level);
      ASSERT_TRUE(table.ok() && exact.ok()) << table.error() << exact.error();
      EXPECT_EQ(table.value().cols, exact.value().cols);
      ASSERT_NE(c.transgraph(v), nullptr);
      EXPECT_EQ(stats.fallbackRays, 0u) << c.viewName(v) << " level " << level;
      EXPECT_GT(correlation(table.value().pixels, exact.value().pixels), 0.99) << c.viewName(v) << " level " << level;
    }
  }
}

TEST(RegistrationTransgraph, PosesOutsideTheTableFallBackToExactRays) {
  const fct::test::KnownTruthCase sim = coarseCase();
  fct::RegistrationCaseOptions options = transgraphOptions();
  options.drr.transgraph.range = {5.0, 5.0};  // a narrow table: ±5 deg, ±5 mm
  options.T_expected_world_from_ct = sim.T_truth;
  auto created = fct::RegistrationCase::create(sim.ct, sim.views, options);
  ASSERT_TRUE(created.ok()) << created.error();
  const fct::RegistrationCase& c = created.value();
  Eigen::Isometry3d outside = sim.T_truth;
  outside.translation() += Eigen::Vector3d(25.0, 0.0, -20.0);
  outside.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix() * outside.linear();
  fct::DrrRenderStats stats;
  auto table = c.renderer(0).render(c.camera(0), outside, 1, &stats);
  auto exact = c.renderer().render(c.camera(0), outside, 1);
  ASSERT_TRUE(table.ok() && exact.ok());
  EXPECT_GT(stats.fallbackRays, 0u) << "rays outside the table are counted";
  EXPECT_GT(correlation(table.value().pixels, exact.value().pixels), 0.99) << "and integrated exactly, not guessed";
}

TEST(RegistrationTransgraph, NoTransgraphAblationRendersExactly) {
  const fct::test::KnownTruthCase sim = coarseCase();
  auto created = fct::RegistrationCase::create(sim.ct, sim.views, transgraphOptions());
  ASSERT_TRUE(created.ok()) << created.error();
  fct::RegistrationCase& c = created.value();
  EXPECT_FALSE(c.viewRenderersReady()) << "no expected pose: tables wait for the first run";
  const Eigen::Isometry3d start = fct::test::startPose(c, sim.T_truth, 3.0, 5);
  fct::RegistrationOptions options = fastOptions();
  for (auto& stage : options.schedule.stages) stage.maxEvaluations = std::min(stage.maxEvaluations, 80);
  options.ablation.noTransgraph = true;
  auto result = fct::Registration::run(c, start, options);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().drrMethod, "siddon");
  EXPECT_NE(result.value().schedule.name.find("no-transgraph"), std::string::npos) << result.value().schedule.name;
  EXPECT_FALSE(c.viewRenderersReady()) << "no table is built when the Transgraph is switched off";
  EXPECT_LT(c.bone()->meanDistance_mm(result.value().T_world_from_ct, sim.T_truth), 3.0);

  // The same case with the Transgraph on builds the tables at this run's initial pose, timed apart.
  options.ablation.noTransgraph = false;
  result = fct::Registration::run(c, start, options);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(c.viewRenderersReady());
  EXPECT_EQ(result.value().drrMethod, "transgraph");
  EXPECT_GT(result.value().viewRendererSetupSeconds, 0.0);
  EXPECT_GT(c.viewRendererSetupSeconds(), 0.0);
}

TEST(RegistrationTransgraph, CancelWhileTheTablesAreBuiltKeepsTheInitialPoseAndNoTable) {
  const fct::test::KnownTruthCase sim = coarseCase();
  auto created = fct::RegistrationCase::create(sim.ct, sim.views, transgraphOptions());
  ASSERT_TRUE(created.ok()) << created.error();
  fct::RegistrationCase& c = created.value();
  ASSERT_FALSE(c.viewRenderersReady());
  const Eigen::Isometry3d start = fct::test::startPose(c, sim.T_truth, 3.0, 5);
  std::atomic<bool> cancel{true};
  auto result = fct::Registration::run(c, start, fastOptions(), {}, &cancel);
  ASSERT_TRUE(result.ok()) << result.error();
  const fct::RegistrationResult& r = result.value();
  EXPECT_TRUE(r.cancelled);
  EXPECT_TRUE(r.stages.empty());
  EXPECT_TRUE(r.T_world_from_ct.isApprox(start));
  EXPECT_TRUE(r.T_initial.isApprox(start));
  EXPECT_EQ(r.viewRendererSetupSeconds, 0.0);
  EXPECT_FALSE(c.viewRenderersReady()) << "a cancelled build leaves no half-built table";
}

TEST(RegistrationTransgraph, FailsClearlyWhenATableCannotBePlanned) {
  const fct::test::KnownTruthCase sim = coarseCase();
  fct::RegistrationCaseOptions options = transgraphOptions();
  options.drr.transgraph.spacing_mm = -1.0;
  options.T_expected_world_from_ct = sim.T_truth;
  auto created = fct::RegistrationCase::create(sim.ct, sim.views, options);
  ASSERT_FALSE(created.ok());
  EXPECT_NE(created.error().find("view 'ap'"), std::string::npos) << created.error();
  EXPECT_NE(created.error().find("spacing"), std::string::npos) << created.error();
}
