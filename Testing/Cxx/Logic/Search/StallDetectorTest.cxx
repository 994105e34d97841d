#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "OptimizerTestFunctions.h"
#include "Search/NelderMeadOptimizer.h"
#include "Search/StallDetector.h"

using fct::NelderMeadOptimizer;
using fct::NelderMeadOptions;
using fct::PoseVector;
using fct::StallDetector;
using fct::StallOptions;
namespace t = fct::test;

TEST(StallDetector, StallsOnceTheBestImprovedTooLittleOverTheWindowAndStaysStalled) {
  StallDetector detector(StallOptions{4, 0.01});
  for (const double value : {-1.0, -1.02, -1.0, -1.0}) EXPECT_FALSE(detector.add(value)) << value;
  EXPECT_FALSE(detector.add(-1.005));  // best 4 evaluations ago -1.0, now -1.02: 2 % better than it
  EXPECT_TRUE(detector.add(-1.0));     // best 4 evaluations ago -1.02, now -1.02: no gain
  EXPECT_TRUE(detector.add(-2.0));     // a stall is final
  EXPECT_TRUE(detector.stalled());
}

TEST(StallDetector, KeepsGoingWhileEachWindowImprovesEnough) {
  StallDetector detector(StallOptions{3, 0.01});
  double value = -1.0;
  for (int i = 0; i < 50; ++i) {
    value *= 1.02;  // 2 % better every evaluation
    EXPECT_FALSE(detector.add(value)) << i;
  }
}

TEST(StallDetector, NanAndInfinityCountAsNoImprovement) {
  StallDetector detector(StallOptions{2, 0.0});
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(detector.add(inf));
  EXPECT_FALSE(detector.add(std::nan("")));
  EXPECT_FALSE(detector.add(-1.0));  // best 2 evaluations ago +inf: not a number to compare with
  EXPECT_FALSE(detector.add(-1.5));
  EXPECT_FALSE(detector.add(std::nan("")));  // best 2 ago -1.0, now -1.5
  EXPECT_TRUE(detector.add(inf));            // best 2 ago -1.5, now -1.5
}

TEST(StallDetector, WindowZeroNeverStalls) {
  StallDetector detector;
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(detector.add(1.0));
  EXPECT_TRUE(detector.validate().ok());
}

TEST(StallDetector, RejectsANegativeWindowOrThreshold) {
  auto status = StallDetector(StallOptions{-1, 0.01}).validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("window"), std::string::npos) << status.error();
  status = StallDetector(StallOptions{10, -0.5}).validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("relative improvement"), std::string::npos) << status.error();
  NelderMeadOptions options;
  options.stall = StallOptions{10, std::nan("")};
  status = NelderMeadOptimizer(options).validateOptions();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("stall"), std::string::npos) << status.error();
}

TEST(StallDetector, StopsTheSimplexNearTheMinimumWithFewerEvaluations) {
  // A similarity-like objective: a bowl around -1 (as -NCC near a match), with a tolerance too tight to end the run.
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  const auto bowl = t::bowl(target, scales);
  const fct::PoseObjective objective = [&](const PoseVector& p) { return bowl(p) - 1.0; };
  NelderMeadOptions options;
  options.tolerance = 1e-9;
  options.maxEvaluations = 3000;
  options.restarts = 0;
  const PoseVector start = PoseVector::Zero();
  const auto full = NelderMeadOptimizer(options).minimize(objective, start, scales);
  options.stall = StallOptions{40, 1e-4};
  const auto stalled = NelderMeadOptimizer(options).minimize(objective, start, scales);
  ASSERT_TRUE(full.ok()) << full.error();
  ASSERT_TRUE(stalled.ok()) << stalled.error();
  EXPECT_LT(stalled.value().evaluations, full.value().evaluations / 2);
  EXPECT_FALSE(stalled.value().converged);
  EXPECT_LT(stalled.value().value, -1.0 + 1e-3);
  EXPECT_LT(t::scaledDistance(stalled.value().params, target, scales), 0.1);
}
