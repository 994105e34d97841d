#include <gtest/gtest.h>

#include "OptimizerTestFunctions.h"
#include "Search/BobyqaOptimizer.h"
#include "Search/GeneticSearchOptimizer.h"
#include "Search/NelderMeadOptimizer.h"

using fct::BobyqaOptimizer;
using fct::LocalSearchOptions;
using fct::PoseVector;
namespace t = fct::test;

TEST(BobyqaOptimizer, MinimizesTheScaledBowlWithinToleranceInFewerEvaluationsThanTheSimplex) {
  const PoseVector scales = fct::PoseOptimizer::scalesForBoneRadius(100.0).value();
  const PoseVector target = t::targetPose();
  LocalSearchOptions options;
  options.tolerance = 0.001;
  const auto bobyqa = BobyqaOptimizer(options).minimize(t::bowl(target, scales), PoseVector::Zero(), scales);
  const auto simplex =
      fct::NelderMeadOptimizer(options).minimize(t::bowl(target, scales), PoseVector::Zero(), scales);
  ASSERT_TRUE(bobyqa.ok()) << bobyqa.error();
  ASSERT_TRUE(simplex.ok()) << simplex.error();
  EXPECT_TRUE(bobyqa.value().converged);
  EXPECT_LT(t::scaledDistance(bobyqa.value().params, target, scales), 0.01);
  EXPECT_LT(bobyqa.value().value, 1e-4);
  EXPECT_LT(bobyqa.value().evaluations, simplex.value().evaluations);
}

TEST(BobyqaOptimizer, ConvergesOnSixDimensionalRosenbrock) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  LocalSearchOptions options;
  options.initialStep = 0.5;
  options.tolerance = 1e-7;
  options.maxEvaluations = 5000;
  const auto result = BobyqaOptimizer(options).minimize(t::rosenbrock(target, scales), target, scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().converged);
  EXPECT_LT(t::scaledDistance(result.value().params, target + scales, scales), 1e-3);
}

TEST(BobyqaOptimizer, StopsAtTheEvaluationCap) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  LocalSearchOptions options;
  options.tolerance = 1e-9;
  options.maxEvaluations = 40;
  int calls = 0;
  const auto rosenbrock = t::rosenbrock(target, scales);
  const fct::PoseObjective counted = [&](const PoseVector& p) {
    ++calls;
    return rosenbrock(p);
  };
  const auto result = BobyqaOptimizer(options).minimize(counted, PoseVector::Zero(), scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().evaluations, 40);
  EXPECT_EQ(calls, 40);
  EXPECT_FALSE(result.value().converged);
  EXPECT_LT(result.value().value, rosenbrock(PoseVector::Zero()));
}

TEST(BobyqaOptimizer, RefinesTheGuessesOfTheGeneticSearchWhenTheOptionsNameIt) {
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
  fct::GeneticSearchOptions options;
  options.randomGuesses = 2;
  options.local.tolerance = 0.001;
  const auto simplex = fct::GeneticSearchOptimizer(options).minimize(t::bowl(target, scales), PoseVector::Zero(), scales);
  options.local.method = fct::LocalSearchMethod::Bobyqa;
  const auto bobyqa = fct::GeneticSearchOptimizer(options).minimize(t::bowl(target, scales), PoseVector::Zero(), scales);
  ASSERT_TRUE(simplex.ok()) << simplex.error();
  ASSERT_TRUE(bobyqa.ok()) << bobyqa.error();
  EXPECT_LT(t::scaledDistance(bobyqa.value().params, target, scales), 0.01);
  EXPECT_LT(bobyqa.value().evaluations, simplex.value().evaluations);
}
