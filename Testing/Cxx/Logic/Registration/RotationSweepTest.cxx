// RotationSweep: the grid of rotation offsets, a start turned 40 deg about the bone centre brought back within a grid
// step by the sweep (also when it is 40 mm off in translation as well), registered with the default preset (as is a
// start off only in translation, by 95 mm), and a start at the truth left alone.
#include <gtest/gtest.h>

#include <cmath>

#include "Registration/Registration.h"
#include "Registration/RegistrationObjective.h"
#include "Registration/RotationSweep.h"
#include "CoarsePhantomCase.h"

namespace {

using Prepared = fct::test::PreparedCase;

/// The small phantom in the three standard views on a 128x128 detector at 2.4 mm.
Prepared prepare() { return fct::test::prepareCoarsePhantom(3); }

/// The truth turned by `angle_deg` about `axis` through the bone centre.
Eigen::Isometry3d turned(const Prepared& p, double angle_deg, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d centre_world_mm = p.simulated.T_truth * p.registrationCase.rotationCentre_ct_mm();
  return Eigen::Translation3d(centre_world_mm) * Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis.normalized()) *
         Eigen::Translation3d(-centre_world_mm) * p.simulated.T_truth;
}

double angleBetween_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * 180.0 / M_PI;
}

/// The default preset's global stage.
fct::RegistrationStage globalStage() {
  return fct::RegistrationSchedule::builtin(fct::RegistrationSchedule::kDefaultPreset).value().stages.front();
}

/// The stage with the sweep's sparser pixel set, which ranks the grid.
fct::RegistrationStage gridStage(const fct::RegistrationStage& stage) {
  fct::RegistrationStage grid = stage;
  grid.pixels.maxPixels = stage.rotationSweep.maxPixels;
  return grid;
}

}  // namespace

TEST(RotationSweep, GridHoldsEveryMultipleOfTheStepWithinTheRadiusButZero) {
  const auto offsets = fct::RotationSweep::offsets_deg(60.0, 15.0);
  EXPECT_EQ(offsets.size(), 256u) << "integer points of a ball of radius 4, less the centre";
  for (const Eigen::Vector3d& r : offsets) {
    EXPECT_LE(r.norm(), 60.0 + 1e-9);
    EXPECT_GT(r.norm(), 0.0);
    for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(std::remainder(r[a], 15.0), 0.0);
  }
  EXPECT_TRUE(fct::RotationSweep::offsets_deg(10.0, 15.0).empty());
  EXPECT_TRUE(fct::RotationSweep::offsets_deg(60.0, 0.0).empty());
}

TEST(RotationSweep, BringsAStartTurned40DegreesWithinAGridStepAndLeavesTheTruthAlone) {
  Prepared p = prepare();
  const fct::RegistrationStage stage = globalStage();
  ASSERT_GT(stage.rotationSweep.maxRotation_deg, 0.0);
  auto objective = fct::RegistrationObjective::create(p.registrationCase, stage);
  ASSERT_TRUE(objective.ok()) << objective.error();
  auto gridObjective = fct::RegistrationObjective::create(p.registrationCase, gridStage(stage));
  ASSERT_TRUE(gridObjective.ok()) << gridObjective.error();

  const Eigen::Vector3d centre_ct_mm = p.registrationCase.rotationCentre_ct_mm();
  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, -2, 1)}) {
    SCOPED_TRACE(axis.transpose());
    const Eigen::Isometry3d T_start = turned(p, 40.0, axis);
    const auto start = fct::RigidPose::fromTransform(T_start, centre_ct_mm).value().asVector();
    const double startSimilarity = objective.value().similarity(T_start).value();
    auto found = fct::RotationSweep::run(p.registrationCase, gridObjective.value(), objective.value(),
                                         stage.rotationSweep, stage.level, start, startSimilarity);
    ASSERT_TRUE(found.ok()) << found.error();
    ASSERT_FALSE(found.value().empty()) << "a pose nearer the truth beats a start turned 40 deg";
    EXPECT_LE(static_cast<int>(found.value().size()), stage.rotationSweep.seeds);
    const auto& best = found.value().front();
    EXPECT_GT(best.similarity, startSimilarity);
    const Eigen::Isometry3d T_best = p.registrationCase.poseTransform(best.params);
    std::printf("best of %zu: %.1f deg from the truth, similarity %.4f (start %.4f)\n", found.value().size(),
                angleBetween_deg(T_best, p.simulated.T_truth), best.similarity, startSimilarity);
    EXPECT_LT(angleBetween_deg(T_best, p.simulated.T_truth), 15.0);
    for (std::size_t i = 1; i < found.value().size(); ++i) {
      EXPECT_LE(found.value()[i].similarity, found.value()[i - 1].similarity) << "best first";
    }
  }

  const auto truth = fct::RigidPose::fromTransform(p.simulated.T_truth, centre_ct_mm).value().asVector();
  const double truthSimilarity = objective.value().similarity(p.simulated.T_truth).value();
  auto atTruth = fct::RotationSweep::run(p.registrationCase, gridObjective.value(), objective.value(),
                                         stage.rotationSweep, stage.level, truth, truthSimilarity);
  ASSERT_TRUE(atTruth.ok()) << atTruth.error();
  // No turned grid pose beats the truth; the truth itself lined up in 2D may, within the alignment's precision.
  for (const auto& candidate : atTruth.value()) {
    const Eigen::Isometry3d T = p.registrationCase.poseTransform(candidate.params);
    EXPECT_LT(angleBetween_deg(T, p.simulated.T_truth), 1e-6);
    EXPECT_LT((T * centre_ct_mm - p.simulated.T_truth * centre_ct_mm).norm(), 3.0);
  }
}

TEST(RotationSweep, JudgesEachRotationWhereARoughAlignmentPutsItSoAStartAlsoFarOffInTranslationIsFound) {
  Prepared p = prepare();
  const fct::RegistrationStage stage = globalStage();
  auto objective = fct::RegistrationObjective::create(p.registrationCase, stage);
  auto gridObjective = fct::RegistrationObjective::create(p.registrationCase, gridStage(stage));
  ASSERT_TRUE(objective.ok() && gridObjective.ok());
  const Eigen::Vector3d centre_ct_mm = p.registrationCase.rotationCentre_ct_mm();
  const Eigen::Isometry3d T_start =
      Eigen::Translation3d(25.0, -20.0, 25.0) * turned(p, 40.0, Eigen::Vector3d(1, -2, 1));
  const auto start = fct::RigidPose::fromTransform(T_start, centre_ct_mm).value().asVector();
  auto found = fct::RotationSweep::run(p.registrationCase, gridObjective.value(), objective.value(),
                                       stage.rotationSweep, stage.level, start,
                                       objective.value().similarity(T_start).value());
  ASSERT_TRUE(found.ok()) << found.error();
  ASSERT_FALSE(found.value().empty());
  const Eigen::Isometry3d T_best = p.registrationCase.poseTransform(found.value().front().params);
  const double centreOff_mm = (T_best * centre_ct_mm - p.simulated.T_truth * centre_ct_mm).norm();
  std::printf("from 40 deg and %.1f mm: %.1f deg and %.1f mm from the truth\n",
              (T_start * centre_ct_mm - p.simulated.T_truth * centre_ct_mm).norm(),
              angleBetween_deg(T_best, p.simulated.T_truth), centreOff_mm);
  EXPECT_LT(angleBetween_deg(T_best, p.simulated.T_truth), 15.0);
  EXPECT_LT(centreOff_mm, 10.0);
}

TEST(RotationSweep, HalvesTheLevelForItsRoughAlignmentDownToImagesOf32Pixels) {
  Prepared p = prepare();  // 128x128 detector: levels of 128, 64 and 32 pixels
  EXPECT_EQ(fct::RotationSweep::roughAlignmentHalvings(p.registrationCase, 0), 2);
  EXPECT_EQ(fct::RotationSweep::roughAlignmentHalvings(p.registrationCase, 1), 1);
  EXPECT_EQ(fct::RotationSweep::roughAlignmentHalvings(p.registrationCase, 2), 0);
}

namespace {

/// Registers the phantom from `start` with the default preset; expects a sweep seed and an end within 0.5 mm.
void expectTheDefaultPresetRegisters(Prepared& p, const Eigen::Isometry3d& start) {
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin(fct::RegistrationSchedule::kDefaultPreset).value();
  options.seed = 4;
  auto result = fct::Registration::run(p.registrationCase, start, options);
  ASSERT_TRUE(result.ok()) << result.error();
  const double error_mm = p.registrationCase.bone()->meanDistance_mm(result.value().T_world_from_ct, p.simulated.T_truth);
  const fct::StageReport& global = result.value().stages.front();
  std::printf("from %.1f mm: %.3f mm (%s)\n", p.registrationCase.bone()->meanDistance_mm(start, p.simulated.T_truth),
              error_mm, fct::stageStartNote(global).c_str());
  EXPECT_GE(global.rotationSweepSeeds, 1);
  EXPECT_NE(fct::stageStartNote(global).find("rotation sweep"), std::string::npos) << fct::stageStartNote(global);
  EXPECT_LT(error_mm, 0.5);
}

}  // namespace

TEST(RotationSweep, TheDefaultPresetRegistersAStartTurned45Degrees) {
  Prepared p = prepare();
  expectTheDefaultPresetRegisters(p, turned(p, 45.0, Eigen::Vector3d(2, 1, -1)));
}

TEST(RotationSweep, TheDefaultPresetRegistersAStartOffOnlyInPlaceByItsOwnAlignment) {
  Prepared p = prepare();
  ASSERT_FALSE(fct::RegistrationSchedule::builtin(fct::RegistrationSchedule::kDefaultPreset)
                   .value().stages.front().shiftPrealign)
      << "the sweep lines up the start itself";
  expectTheDefaultPresetRegisters(p, Eigen::Translation3d(60.0, -55.0, 50.0) * p.simulated.T_truth);
}
