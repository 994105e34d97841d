// PoseOptimizer contract: every optimizer, called through the interface, honours the cancel flag, fails on a
// NaN-everywhere objective and on bad input (naming the parameter or option, before any evaluation), reports progress
// under its name, minimizes a quadratic bowl, and is deterministic (for a fixed seed where it has one). A new
// optimizer joins by adding a traits specialisation and its type to ContractOptimizers.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "OptimizerTestFunctions.h"
#include "Search/BobyqaOptimizer.h"
#include "Search/CmaEsOptimizer.h"
#include "Search/GeneticSearchOptimizer.h"
#include "Search/NelderMeadOptimizer.h"

namespace {

using fct::PoseVector;
namespace t = fct::test;

/// How the contract makes each optimizer: with a seed (ignored where the variant has none) and with one invalid
/// option, whose name the error must contain.
template <typename Optimizer>
struct OptimizerTraits;

template <>
struct OptimizerTraits<fct::NelderMeadOptimizer> {
  static constexpr bool kSeeded = false;  // deterministic by construction: no random numbers at all
  static fct::NelderMeadOptimizer make(std::uint32_t /*seed*/) { return fct::NelderMeadOptimizer(); }
  static constexpr const char* kBadOption = "tolerance";
  static fct::NelderMeadOptimizer withBadOption() {
    fct::NelderMeadOptions options;
    options.tolerance = 0.0;
    return fct::NelderMeadOptimizer(options);
  }
};

template <>
struct OptimizerTraits<fct::BobyqaOptimizer> {
  static constexpr bool kSeeded = false;  // deterministic: BOBYQA draws no random numbers
  static fct::BobyqaOptimizer make(std::uint32_t /*seed*/) { return fct::BobyqaOptimizer(); }
  static constexpr const char* kBadOption = "initial step";
  static fct::BobyqaOptimizer withBadOption() {
    fct::LocalSearchOptions options;
    options.initialStep = options.tolerance;
    return fct::BobyqaOptimizer(options);
  }
};

/// Traits of an optimizer with a random-number seed in its options.
template <class Optimizer, class Options>
struct SeededOptimizerTraits {
  static constexpr bool kSeeded = true;
  static Optimizer make(std::uint32_t seed) {
    Options options;
    options.seed = seed;
    return Optimizer(options);
  }
};

template <>
struct OptimizerTraits<fct::GeneticSearchOptimizer>
    : SeededOptimizerTraits<fct::GeneticSearchOptimizer, fct::GeneticSearchOptions> {
  static constexpr const char* kBadOption = "random guess";
  static fct::GeneticSearchOptimizer withBadOption() {
    fct::GeneticSearchOptions options;
    options.randomGuesses = 0;
    return fct::GeneticSearchOptimizer(options);
  }
};

template <>
struct OptimizerTraits<fct::CmaEsOptimizer> : SeededOptimizerTraits<fct::CmaEsOptimizer, fct::CmaEsOptions> {
  static constexpr const char* kBadOption = "population size";
  static fct::CmaEsOptimizer withBadOption() {
    fct::CmaEsOptions options;
    options.populationSize = 2;
    return fct::CmaEsOptimizer(options);
  }
};

template <typename Optimizer>
class PoseOptimizerContract : public ::testing::Test {
 protected:
  using Traits = OptimizerTraits<Optimizer>;
  const PoseVector scales = t::unitScales();
  const PoseVector target = t::targetPose();
};

using ContractOptimizers = ::testing::Types<fct::NelderMeadOptimizer, fct::BobyqaOptimizer, fct::GeneticSearchOptimizer,
                                           fct::CmaEsOptimizer>;
TYPED_TEST_SUITE(PoseOptimizerContract, ContractOptimizers);

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TYPED_TEST(PoseOptimizerContract, CancelFlagStopsTheRunAndReturnsTheBestSoFar) {
  const auto optimizerValue = TestFixture::Traits::make(1);
  const fct::PoseOptimizer& optimizer = optimizerValue;
  const auto bowl = t::bowl(this->target, this->scales);
  std::atomic<bool> cancel{false};
  int calls = 0;
  const fct::PoseObjective objective = t::cancellingAt(30, bowl, calls, cancel);
  const auto result =
      optimizer.minimize(objective, PoseVector::Zero(), this->scales, fct::ProgressMonitor(nullptr, &cancel));
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().cancelled);
  EXPECT_FALSE(result.value().converged);
  EXPECT_EQ(result.value().evaluations, 30);  // the flag is checked before every evaluation
  EXPECT_EQ(calls, 30);
  EXPECT_TRUE(std::isfinite(result.value().value));
  EXPECT_DOUBLE_EQ(result.value().value, bowl(result.value().params));  // the best pose evaluated, with its value
}

TYPED_TEST(PoseOptimizerContract, CancelledBeforeTheStartEvaluatesNothingAndReturnsTheStart) {
  const auto optimizerValue = TestFixture::Traits::make(1);
  const fct::PoseOptimizer& optimizer = optimizerValue;
  const std::atomic<bool> cancel{true};
  int calls = 0;
  const fct::PoseObjective objective = [&](const PoseVector&) { return static_cast<double>(++calls); };
  PoseVector start;
  start << 1, 2, 3, 4, 5, 6;
  const auto result = optimizer.minimize(objective, start, this->scales, fct::ProgressMonitor(nullptr, &cancel));
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().cancelled);
  EXPECT_EQ(result.value().evaluations, 0);
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(result.value().params, start);
}

TYPED_TEST(PoseOptimizerContract, NanEverywhereFailsWithAMessageNamingTheOptimizer) {
  const auto optimizerValue = TestFixture::Traits::make(1);
  const fct::PoseOptimizer& optimizer = optimizerValue;
  const fct::PoseObjective allNan = [](const PoseVector&) { return kNan; };
  const auto result = optimizer.minimize(allNan, PoseVector::Zero(), this->scales);
  ASSERT_FALSE(result.ok());
  EXPECT_TRUE(contains(result.error(), "NaN")) << result.error();
  EXPECT_TRUE(contains(result.error(), optimizer.name())) << result.error();
}

TYPED_TEST(PoseOptimizerContract, BadInputFailsNamingTheParameterBeforeAnyEvaluation) {
  const auto optimizerValue = TestFixture::Traits::make(1);
  const fct::PoseOptimizer& optimizer = optimizerValue;
  int calls = 0;
  const auto bowl = t::bowl(this->target, this->scales);
  const fct::PoseObjective counted = [&](const PoseVector& p) {
    ++calls;
    return bowl(p);
  };

  const auto noObjective = optimizer.minimize(fct::PoseObjective(), PoseVector::Zero(), this->scales);
  ASSERT_FALSE(noObjective.ok());
  EXPECT_TRUE(contains(noObjective.error(), "objective")) << noObjective.error();

  PoseVector nanStart = PoseVector::Zero();
  nanStart[5] = kNan;
  const auto badStart = optimizer.minimize(counted, nanStart, this->scales);
  ASSERT_FALSE(badStart.ok());
  EXPECT_TRUE(contains(badStart.error(), "start pose parameter tz")) << badStart.error();
  PoseVector infiniteStart = PoseVector::Zero();
  infiniteStart[0] = std::numeric_limits<double>::infinity();
  const auto infinite = optimizer.minimize(counted, infiniteStart, this->scales);
  ASSERT_FALSE(infinite.ok());
  EXPECT_TRUE(contains(infinite.error(), "start pose parameter rx")) << infinite.error();

  const char* names[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  const std::vector<std::pair<int, double>> badScales{{1, 0.0}, {3, -1.0}, {4, kNan}};
  for (const auto& [index, value] : badScales) {
    PoseVector scales = this->scales;
    scales[index] = value;
    const auto result = optimizer.minimize(counted, PoseVector::Zero(), scales);
    ASSERT_FALSE(result.ok()) << "scale " << value;
    EXPECT_TRUE(contains(result.error(), std::string("scale of pose parameter ") + names[index])) << result.error();
  }

  const auto badOptionValue = TestFixture::Traits::withBadOption();
  const fct::PoseOptimizer& badOption = badOptionValue;
  const auto options = badOption.minimize(counted, PoseVector::Zero(), this->scales);
  ASSERT_FALSE(options.ok());
  EXPECT_TRUE(contains(options.error(), TestFixture::Traits::kBadOption)) << options.error();
  EXPECT_FALSE(badOption.validateOptions().ok());
  EXPECT_TRUE(optimizer.validateOptions().ok());

  EXPECT_EQ(calls, 0) << "inputs are checked before the objective is evaluated";
}

TYPED_TEST(PoseOptimizerContract, MinimizesAQuadraticBowlToTolerance) {
  const auto optimizerValue = TestFixture::Traits::make(1);
  const fct::PoseOptimizer& optimizer = optimizerValue;
  const auto result = optimizer.minimize(t::bowl(this->target, this->scales), PoseVector::Zero(), this->scales);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_TRUE(result.value().converged);
  EXPECT_FALSE(result.value().cancelled);
  EXPECT_LT(t::scaledDistance(result.value().params, this->target, this->scales), 0.05);
  EXPECT_LT(result.value().value, 1e-3);
  EXPECT_DOUBLE_EQ(result.value().value, t::bowl(this->target, this->scales)(result.value().params));
}

TYPED_TEST(PoseOptimizerContract, ReportsProgressUnderItsName) {
  const auto optimizerValue = TestFixture::Traits::make(1);
  const fct::PoseOptimizer& optimizer = optimizerValue;
  std::vector<fct::ProgressUpdate> updates;
  const fct::ProgressMonitor monitor([&](const fct::ProgressUpdate& u) { updates.push_back(u); }, nullptr);
  const auto result = optimizer.minimize(t::bowl(this->target, this->scales), PoseVector::Zero(), this->scales, monitor);
  ASSERT_TRUE(result.ok()) << result.error();
  ASSERT_FALSE(updates.empty());
  for (const fct::ProgressUpdate& u : updates) {
    EXPECT_EQ(u.stage, optimizer.name());
    EXPECT_GE(u.fraction, 0.0);
    EXPECT_LE(u.fraction, 1.0);
  }
}

TYPED_TEST(PoseOptimizerContract, IsDeterministicForAFixedSeed) {
  const auto objective = t::bumpyBowl(this->target, this->scales);
  const PoseVector start = t::trappedStart(this->target, this->scales);
  const auto firstValue = TestFixture::Traits::make(7);
  const auto secondValue = TestFixture::Traits::make(7);
  const fct::PoseOptimizer& first = firstValue;
  const fct::PoseOptimizer& second = secondValue;
  const auto a = first.minimize(objective, start, this->scales);
  const auto b = second.minimize(objective, start, this->scales);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.value().params, b.value().params);
  EXPECT_EQ(a.value().value, b.value().value);
  EXPECT_EQ(a.value().evaluations, b.value().evaluations);
  if constexpr (TestFixture::Traits::kSeeded) {
    // The seed is really used: another seed takes another path.
    const auto otherValue = TestFixture::Traits::make(8);
    const fct::PoseOptimizer& other = otherValue;
    const auto c = other.minimize(objective, start, this->scales);
    ASSERT_TRUE(c.ok());
    EXPECT_TRUE(c.value().params != a.value().params || c.value().evaluations != a.value().evaluations);
  } else {
    // No seed: the same inputs give the same run, also from the same object twice.
    const auto again = first.minimize(objective, start, this->scales);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again.value().params, a.value().params);
    EXPECT_EQ(again.value().evaluations, a.value().evaluations);
  }
}
