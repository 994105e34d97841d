// BoneMotion: bounds, smoothness, the jerk, determinism by seed, poses about the bone centre, and bad settings.
#include <gtest/gtest.h>

#include <cmath>

#include "Simulation/BoneMotion.h"

namespace {

fct::BoneMotionOptions withJerk(int jerkFrame, int jerkFrames = 1) {
  fct::BoneMotionOptions o;
  o.frames = 60;
  o.jerkFrame = jerkFrame;
  o.jerkFrames = jerkFrames;
  o.jerkTranslation_mm = 4.0;
  o.jerkRotation_deg = 3.0;
  return o;
}

}  // namespace

TEST(BoneMotion, EveryParameterStaysWithinItsBoundOverManySeeds) {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    fct::BoneMotionOptions o = withJerk(25);
    o.frames = 200;
    o.seed = seed;
    const fct::BoneMotion motion = fct::BoneMotion::create(o).value();
    double largestTranslation_mm = 0.0;
    for (int k = 0; k < motion.frameCount(); ++k) {
      const fct::PoseParameters p = motion.parameters(k);
      EXPECT_LE(p.rotation_deg.cwiseAbs().maxCoeff(), o.maxRotation_deg + 1e-9) << "seed " << seed << " frame " << k;
      EXPECT_LE(p.translation_mm.cwiseAbs().maxCoeff(), o.maxTranslation_mm + 1e-9) << "seed " << seed << " frame " << k;
      largestTranslation_mm = std::max(largestTranslation_mm, p.translation_mm.cwiseAbs().maxCoeff());
    }
    EXPECT_GT(largestTranslation_mm, 3.0) << "the motion is not trivially small, seed " << seed;
  }
}

TEST(BoneMotion, SmoothPartMovesLittleBetweenFramesAndTheJerkIsAStepAtItsFrame) {
  const fct::BoneMotionOptions o = withJerk(30);
  const fct::BoneMotion motion = fct::BoneMotion::create(o).value();
  // Smooth part: the fastest sinusoid (period >= 40 frames) moves at most bound * 2 pi / 40 per frame.
  const double maxStep_mm = o.maxTranslation_mm * 2.0 * M_PI / o.minPeriod_frames;
  const double maxStep_deg = o.maxRotation_deg * 2.0 * M_PI / o.minPeriod_frames;
  for (int k = 1; k < motion.frameCount(); ++k) {
    const fct::PoseVector step = motion.parameters(k).asVector() - motion.parameters(k - 1).asVector();
    const fct::PoseVector jerkStep = motion.jerkParameters(k).asVector() - motion.jerkParameters(k - 1).asVector();
    const fct::PoseVector smoothStep = step - jerkStep;
    EXPECT_LE(smoothStep.head<3>().cwiseAbs().maxCoeff(), maxStep_deg + 1e-9) << "frame " << k;
    EXPECT_LE(smoothStep.tail<3>().cwiseAbs().maxCoeff(), maxStep_mm + 1e-9) << "frame " << k;
    if (k == o.jerkFrame) {
      EXPECT_NEAR(jerkStep.tail<3>().norm(), o.jerkTranslation_mm, 1e-9);
      EXPECT_NEAR(jerkStep.head<3>().norm(), o.jerkRotation_deg, 1e-9);
    } else {
      EXPECT_EQ(jerkStep.norm(), 0.0) << "frame " << k;
    }
  }
  EXPECT_EQ(motion.jerkParameters(o.jerkFrame - 1).asVector().norm(), 0.0);
}

TEST(BoneMotion, TwoFrameJerkRampsInHalfPerFrame) {
  const fct::BoneMotion motion = fct::BoneMotion::create(withJerk(10, 2)).value();
  EXPECT_NEAR(motion.jerkParameters(10).translation_mm.norm(), 2.0, 1e-9);
  EXPECT_NEAR(motion.jerkParameters(11).translation_mm.norm(), 4.0, 1e-9);
  EXPECT_NEAR(motion.jerkParameters(40).translation_mm.norm(), 4.0, 1e-9);
}

TEST(BoneMotion, SameSeedGivesTheSameMotionAndAnotherSeedAnother) {
  fct::BoneMotionOptions o = withJerk(20);
  const fct::BoneMotion a = fct::BoneMotion::create(o).value();
  const fct::BoneMotion b = fct::BoneMotion::create(o).value();
  o.seed = 2;
  const fct::BoneMotion c = fct::BoneMotion::create(o).value();
  double difference = 0.0;
  for (int k = 0; k < a.frameCount(); ++k) {
    EXPECT_EQ(a.parameters(k).asVector(), b.parameters(k).asVector());
    difference += (a.parameters(k).asVector() - c.parameters(k).asVector()).norm();
  }
  EXPECT_GT(difference, 1.0);
}

TEST(BoneMotion, PoseMovesTheBoneCentreByTheTranslationAndTurnsAboutIt) {
  const fct::BoneMotion motion = fct::BoneMotion::create(withJerk(-1)).value();
  fct::PoseParameters baseParameters;
  baseParameters.rotation_deg = Eigen::Vector3d(5.0, -3.0, 20.0);
  baseParameters.translation_mm = Eigen::Vector3d(10.0, -4.0, 7.0);
  const Eigen::Vector3d centre_ct_mm(30.0, -12.0, 80.0);
  const Eigen::Isometry3d T_base = fct::RigidPose::toTransform(baseParameters, Eigen::Vector3d(1.0, 2.0, 3.0));
  for (int k : {0, 17, 59}) {
    const Eigen::Isometry3d T_k = motion.pose(k, T_base, centre_ct_mm);
    const fct::PoseParameters p = motion.parameters(k);
    EXPECT_LT((T_k * centre_ct_mm - (T_base * centre_ct_mm + p.translation_mm)).norm(), 1e-9) << "frame " << k;
    const Eigen::Matrix3d R_motion = T_k.linear() * T_base.linear().transpose();
    const Eigen::Matrix3d R_expected = fct::RigidPose::toTransform(p, Eigen::Vector3d::Zero()).linear();
    EXPECT_LT((R_motion - R_expected).norm(), 1e-9) << "frame " << k;
  }
  EXPECT_EQ(motion.poses(T_base, centre_ct_mm).size(), 60u);
}

TEST(BoneMotion, BadSettingsAreRefusedNamingThem) {
  const auto refused = [](fct::BoneMotionOptions o, const char* word) {
    auto motion = fct::BoneMotion::create(o);
    ASSERT_FALSE(motion.ok());
    EXPECT_NE(motion.error().find(word), std::string::npos) << motion.error();
  };
  fct::BoneMotionOptions o;
  o.frames = 0;
  refused(o, "frame");
  o = {};
  o.maxTranslation_mm = std::nan("");
  refused(o, "translation bound");
  o = {};
  o.maxRotation_deg = 60.0;
  refused(o, "rotation bound");
  o = {};
  o.sinusoids = 0;
  refused(o, "sinusoids");
  o = {};
  o.minPeriod_frames = 50.0;
  o.maxPeriod_frames = 20.0;
  refused(o, "periods");
  o = withJerk(5, 3);
  refused(o, "jerk ramps");
  o = withJerk(5);
  o.jerkTranslation_mm = 20.0;
  refused(o, "jerk translation");
  o = withJerk(5);
  o.jerkRotation_deg = 11.0;
  refused(o, "jerk rotation");
}
