#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>

#include "OptimizerTestFunctions.h"
#include "Search/NelderMeadOptimizer.h"

using fct::NelderMeadOptimizer;
using fct::NelderMeadOptions;
using fct::PoseVector;
namespace t = fct::test;

TEST(NelderMeadOptimizer, ConvergesOnScaledBowlWithinTolerance) {
  const PoseVector scales = fct::PoseOptimizer::scalesForBoneRadius(100.0).value();
  const PoseVector target = t::targetPose();
  PoseVector start = target;
  start << 0, 0, 0, 0, 0, 0;
  NelderMeadOptions options;
  options.tolerance = 0.001;
  std::vector<fct::ProgressUpdate> updates;
  const fct::ProgressMonitor monitor([&](const fct::ProgressUpdate& u) { updates.push_back(u); }, nullptr);
  const auto result = NelderMeadOptimizer(options).minimize(t::bowl(target, scales), start, scales, monitor);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().converged);
  ASSERT_GE(updates.size(), 2u);  // periodic reports and the final one
  EXPECT_EQ(updates.front().stage, "nelder-mead");
  EXPECT_EQ(updates.front().message.rfind("25 evaluations", 0), 0u) << updates.front().message;
  EXPECT_FALSE(result.value().cancelled);
  EXPECT_LT((result.value().params - target).cwiseQuotient(scales).cwiseAbs().maxCoeff(), 0.01);
  EXPECT_LT(result.value().value, 1e-4);
  EXPECT_GT(result.value().evaluations, 7);
  EXPECT_LE(result.value().evaluations, options.maxEvaluations);
}

TEST(NelderMeadOptimizer, StartAtMinimumStaysThere) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  const auto result = NelderMeadOptimizer().minimize(t::bowl(target, scales), target, scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().value, 0.0);
  EXPECT_EQ(result.value().params, target);
}

TEST(NelderMeadOptimizer, ConvergesOnSixDimensionalRosenbrock) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  NelderMeadOptions options;
  options.initialStep = 1.0;
  options.tolerance = 1e-6;
  options.maxEvaluations = 20000;
  options.restarts = 3;
  const auto result = NelderMeadOptimizer(options).minimize(t::rosenbrock(target, scales), target, scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().converged);
  EXPECT_LT(t::scaledDistance(result.value().params, target + scales, scales), 1e-3);
}

TEST(NelderMeadOptimizer, IsTrappedInLocalMinimumOfBumpyBowl) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  const auto result =
      NelderMeadOptimizer().minimize(t::bumpyBowl(target, scales), t::trappedStart(target, scales), scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_GT(t::scaledDistance(result.value().params, target, scales), 3.0);
  EXPECT_GT(result.value().value, 1.0);
}

TEST(NelderMeadOptimizer, CancelReturnsBestSoFarMarkedCancelled) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  std::atomic<bool> cancel{false};
  int calls = 0;
  const auto bowl = t::bowl(target, scales);
  const fct::PoseObjective objective = t::cancellingAt(50, bowl, calls, cancel);
  const PoseVector start = PoseVector::Zero();
  const auto result =
      NelderMeadOptimizer().minimize(objective, start, scales, fct::ProgressMonitor(nullptr, &cancel));
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().cancelled);
  EXPECT_FALSE(result.value().converged);
  EXPECT_EQ(result.value().evaluations, 50);
  EXPECT_LT(result.value().value, bowl(start));
  EXPECT_DOUBLE_EQ(result.value().value, bowl(result.value().params));
}

TEST(NelderMeadOptimizer, FailsWhenObjectiveIsNanEverywhere) {
  const fct::PoseObjective objective = [](const PoseVector&) { return std::numeric_limits<double>::quiet_NaN(); };
  const auto result = NelderMeadOptimizer().minimize(objective, PoseVector::Zero(), t::unitScales());
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("NaN"), std::string::npos) << result.error();
}

TEST(NelderMeadOptimizer, RejectsBadInput) {
  const PoseVector scales = t::unitScales();
  const auto bowl = t::bowl(t::targetPose(), scales);
  PoseVector nanStart = PoseVector::Zero();
  nanStart[4] = std::numeric_limits<double>::quiet_NaN();
  auto r = NelderMeadOptimizer().minimize(bowl, nanStart, scales);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("ty"), std::string::npos) << r.error();

  PoseVector zeroScale = scales;
  zeroScale[1] = 0.0;
  r = NelderMeadOptimizer().minimize(bowl, PoseVector::Zero(), zeroScale);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("scale of pose parameter ry"), std::string::npos) << r.error();

  r = NelderMeadOptimizer().minimize(fct::PoseObjective(), PoseVector::Zero(), scales);
  EXPECT_FALSE(r.ok());

  NelderMeadOptions options;
  options.tolerance = 0.0;
  r = NelderMeadOptimizer(options).minimize(bowl, PoseVector::Zero(), scales);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("tolerance"), std::string::npos) << r.error();

  options = {};
  options.maxEvaluations = 0;
  EXPECT_FALSE(NelderMeadOptimizer(options).minimize(bowl, PoseVector::Zero(), scales).ok());

  EXPECT_FALSE(fct::PoseOptimizer::scalesForBoneRadius(0.0).ok());
  EXPECT_FALSE(fct::PoseOptimizer::scalesForBoneRadius(std::nan("")).ok());
}

TEST(PoseOptimizer, ScalesForBoneRadiusMatchSurfaceMotion) {
  const auto scales = fct::PoseOptimizer::scalesForBoneRadius(100.0);
  ASSERT_TRUE(scales.ok()) << scales.error();
  // One scaled unit of rotation moves a point 100 mm from the centre by 1 mm (arc length).
  EXPECT_NEAR(scales.value()[0] * M_PI / 180.0 * 100.0, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(scales.value()[2], scales.value()[0]);
  EXPECT_DOUBLE_EQ(scales.value()[3], 1.0);
}
