#include <gtest/gtest.h>

#include <atomic>
#include <limits>

#include "OptimizerTestFunctions.h"
#include "Search/CmaEsOptimizer.h"

using fct::CmaEsOptimizer;
using fct::CmaEsOptions;
using fct::PoseVector;
namespace t = fct::test;

TEST(CmaEsOptimizer, ConvergesOnScaledBowl) {
  const PoseVector scales = fct::PoseOptimizer::scalesForBoneRadius(60.0).value();
  const PoseVector target = t::targetPose();
  CmaEsOptions options;
  options.tolerance = 0.001;
  const auto result = CmaEsOptimizer(options).minimize(t::bowl(target, scales), PoseVector::Zero(), scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().converged);
  EXPECT_LT(t::scaledDistance(result.value().params, target, scales), 0.01);
  EXPECT_FALSE(result.value().generations.empty());
}

TEST(CmaEsOptimizer, ConvergesOnSixDimensionalRosenbrock) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  CmaEsOptions options;
  options.initialSigma = 1.0;
  options.tolerance = 1e-7;
  options.maxEvaluations = 20000;
  const auto result = CmaEsOptimizer(options).minimize(t::rosenbrock(target, scales), target, scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_LT(t::scaledDistance(result.value().params, target + scales, scales), 1e-3);
}

TEST(CmaEsOptimizer, EscapesLocalMinimumWhereSimplexIsTrapped) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  const auto objective = t::bumpyBowl(target, scales);
  const PoseVector start = t::trappedStart(target, scales);
  CmaEsOptions options;
  options.initialSigma = 4.0;
  options.seed = 2;  // seed 1 is one of the few that stop in a neighbouring minimum
  const auto result = CmaEsOptimizer(options).minimize(objective, start, scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_LT(t::scaledDistance(result.value().params, target, scales), 0.05);
  int found = 0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    options.seed = seed;
    const auto r = CmaEsOptimizer(options).minimize(objective, start, scales);
    ASSERT_TRUE(r.ok()) << r.error();
    found += t::scaledDistance(r.value().params, target, scales) < 0.05;
  }
  EXPECT_GE(found, 15);
}

TEST(CmaEsOptimizer, SameSeedGivesIdenticalResult) {
  const PoseVector scales = t::unitScales();
  const auto objective = t::bumpyBowl(t::targetPose(), scales);
  const PoseVector start = t::trappedStart(t::targetPose(), scales);
  CmaEsOptions options;
  options.seed = 42;
  const auto a = CmaEsOptimizer(options).minimize(objective, start, scales);
  const auto b = CmaEsOptimizer(options).minimize(objective, start, scales);
  options.seed = 43;
  const auto c = CmaEsOptimizer(options).minimize(objective, start, scales);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(a.value().params, b.value().params);
  EXPECT_EQ(a.value().evaluations, b.value().evaluations);
  EXPECT_NE(a.value().params, c.value().params);
}

TEST(CmaEsOptimizer, CancelReturnsBestSoFarMarkedCancelled) {
  const PoseVector scales = t::unitScales();
  const auto bowl = t::bowl(t::targetPose(), scales);
  std::atomic<bool> cancel{false};
  int calls = 0;
  const fct::PoseObjective objective = t::cancellingAt(40, bowl, calls, cancel);
  const auto result =
      CmaEsOptimizer().minimize(objective, PoseVector::Zero(), scales, fct::ProgressMonitor(nullptr, &cancel));
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().cancelled);
  EXPECT_EQ(result.value().evaluations, 40);
  EXPECT_DOUBLE_EQ(result.value().value, bowl(result.value().params));
}

TEST(CmaEsOptimizer, TreatsNanAsWorstAndRejectsBadInput) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  const auto bowl = t::bowl(target, scales);
  const fct::PoseObjective holes = [&](const PoseVector& p) {
    return p[1] > 0.0 ? std::numeric_limits<double>::quiet_NaN() : bowl(p);
  };
  const auto ok = CmaEsOptimizer().minimize(holes, target, scales);
  ASSERT_TRUE(ok.ok()) << ok.error();
  EXPECT_LT(t::scaledDistance(ok.value().params, target, scales), 0.05);

  CmaEsOptions options;
  options.populationSize = 2;
  auto r = CmaEsOptimizer(options).minimize(bowl, PoseVector::Zero(), scales);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("population size"), std::string::npos) << r.error();
  options = {};
  options.initialSigma = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(CmaEsOptimizer(options).minimize(bowl, PoseVector::Zero(), scales).ok());
  PoseVector nanStart = PoseVector::Zero();
  nanStart[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(CmaEsOptimizer().minimize(bowl, nanStart, scales).ok());
  PoseVector zeroScale = scales;
  zeroScale[3] = 0.0;
  EXPECT_FALSE(CmaEsOptimizer().minimize(bowl, PoseVector::Zero(), zeroScale).ok());
  const fct::PoseObjective allNan = [](const PoseVector&) { return std::numeric_limits<double>::quiet_NaN(); };
  EXPECT_FALSE(CmaEsOptimizer().minimize(allNan, PoseVector::Zero(), scales).ok());
}
