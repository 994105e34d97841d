// LocalPoseOptimizer: what both local searches (the own simplex, BOBYQA) must do beyond the PoseOptimizer contract,
// and the factory that picks one from the options.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "OptimizerTestFunctions.h"
#include "Search/BobyqaOptimizer.h"
#include "Search/NelderMeadOptimizer.h"

namespace {

using fct::PoseVector;
namespace t = fct::test;

template <typename Optimizer>
class LocalPoseOptimizerSuite : public ::testing::Test {};

using LocalOptimizers = ::testing::Types<fct::NelderMeadOptimizer, fct::BobyqaOptimizer>;
TYPED_TEST_SUITE(LocalPoseOptimizerSuite, LocalOptimizers);

}  // namespace

TYPED_TEST(LocalPoseOptimizerSuite, TreatsNanAsWorstAndAvoidsThatRegion) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  const auto bowl = t::bowl(target, scales);
  // NaN wherever tx > 12 mm (e.g. the bone projected off the detector); the minimum (tx = 10) is still reachable.
  const fct::PoseObjective objective = [&](const PoseVector& p) {
    return p[3] > 12.0 ? std::numeric_limits<double>::quiet_NaN() : bowl(p);
  };
  PoseVector start = target;
  start[3] = 11.5;
  start[0] += 3.0;
  const auto result = TypeParam().minimize(objective, start, scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(std::isfinite(result.value().value));
  EXPECT_LT(t::scaledDistance(result.value().params, target, scales), 0.05);
}

TEST(LocalPoseOptimizer, CreateMakesTheSearchTheOptionsName) {
  fct::LocalSearchOptions options;
  EXPECT_EQ(fct::LocalPoseOptimizer::create(options)->name(), "nelder-mead");
  options.method = fct::LocalSearchMethod::Bobyqa;
  options.maxEvaluations = 77;
  const auto bobyqa = fct::LocalPoseOptimizer::create(options);
  EXPECT_EQ(bobyqa->name(), "bobyqa");
  EXPECT_EQ(bobyqa->options().maxEvaluations, 77);
}
