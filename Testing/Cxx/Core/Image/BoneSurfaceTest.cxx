#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "Image/BoneSurface.h"
#include "IO/Volume/VolumeFileIO.h"
#include "Simulation/PhantomBuilder.h"
#include "TestSupport.h"

namespace {

/// A CT of air with a ball of 1000 HU, radius radius_mm, centred at c_lps_mm; anisotropic voxels and an origin
/// away from zero so that index <-> mm mistakes show.
fct::Volume ballVolume(const Eigen::Vector3d& c_lps_mm, double radius_mm) {
  const Eigen::Vector3d spacing_mm(1.0, 1.0, 1.5);
  auto created = fct::Volume::create(Eigen::Vector3i(48, 44, 36), spacing_mm, Eigen::Vector3d(-20.0, -15.0, 10.0),
                                     Eigen::Matrix3d::Identity(), -1000.0f);
  fct::Volume volume = std::move(created).value();
  const Eigen::Vector3i& d = volume.dims();
  for (int k = 0; k < d.z(); ++k)
    for (int j = 0; j < d.y(); ++j)
      for (int i = 0; i < d.x(); ++i)
        if ((volume.lpsFromIjk(Eigen::Vector3d(i, j, k)) - c_lps_mm).norm() <= radius_mm) volume.at(i, j, k) = 1000.0f;
  return volume;
}

const Eigen::Vector3d kBallCentre_lps_mm(3.0, 6.0, 35.0);
constexpr double kBallRadius_mm = 12.0;

}  // namespace

TEST(BoneSurface, BallPointsLieOnItsRadiusWithinOneVoxel) {
  const auto surface = fct::BoneSurface::extract(ballVolume(kBallCentre_lps_mm, kBallRadius_mm));
  ASSERT_TRUE(surface.ok()) << surface.error();
  const auto& points = surface.value().points_ct_mm();
  ASSERT_GT(points.size(), 500u);
  EXPECT_EQ(points.size(), surface.value().boundaryVoxelCount());
  for (const auto& p : points) {
    const double r = (p - kBallCentre_lps_mm).norm();
    ASSERT_LE(r, kBallRadius_mm + 1e-9);
    ASSERT_GT(r, kBallRadius_mm - 1.5);  // the largest voxel spacing
  }
  EXPECT_LT((surface.value().centroid_ct_mm() - kBallCentre_lps_mm).norm(), 0.3);
  EXPECT_NEAR(surface.value().radius_mm(), kBallRadius_mm - 0.5, 0.6);
}

TEST(BoneSurface, IdenticalPosesGiveZeroDistance) {
  const auto surface = fct::BoneSurface::extract(ballVolume(kBallCentre_lps_mm, kBallRadius_mm));
  ASSERT_TRUE(surface.ok()) << surface.error();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  T.pretranslate(Eigen::Vector3d(100.0, -40.0, 7.0));
  EXPECT_EQ(surface.value().meanDistance_mm(T, T), 0.0);
  EXPECT_EQ(surface.value().maxDistance_mm(T, T), 0.0);
}

TEST(BoneSurface, TranslationMovesEveryPointByItsLength) {
  const auto surface = fct::BoneSurface::extract(ballVolume(kBallCentre_lps_mm, kBallRadius_mm));
  ASSERT_TRUE(surface.ok()) << surface.error();
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  a.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  const Eigen::Isometry3d b = Eigen::Translation3d(Eigen::Vector3d(3.0, -4.0, 12.0)) * a;  // 13 mm
  EXPECT_NEAR(surface.value().meanDistance_mm(a, b), 13.0, 1e-9);
  EXPECT_NEAR(surface.value().maxDistance_mm(a, b), 13.0, 1e-9);
}

TEST(BoneSurface, RotationAboutCentroidMovesPointsByChord) {
  const auto surface = fct::BoneSurface::extract(ballVolume(kBallCentre_lps_mm, kBallRadius_mm));
  ASSERT_TRUE(surface.ok()) << surface.error();
  const Eigen::Vector3d c = surface.value().centroid_ct_mm();
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -1.0, 0.4).normalized();
  const double theta = 10.0 * std::numbers::pi / 180.0;
  const Eigen::Isometry3d rotated =
      Eigen::Translation3d(c) * Eigen::AngleAxisd(theta, axis) * Eigen::Translation3d(-c);
  double sumPerpendicular = 0.0, maxPerpendicular = 0.0;
  for (const auto& p : surface.value().points_ct_mm()) {
    const Eigen::Vector3d q = p - c;
    const double perpendicular = (q - q.dot(axis) * axis).norm();
    sumPerpendicular += perpendicular;
    maxPerpendicular = std::max(maxPerpendicular, perpendicular);
  }
  const double chord = 2.0 * std::sin(theta / 2.0);
  const double meanPerpendicular = sumPerpendicular / static_cast<double>(surface.value().points_ct_mm().size());
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  EXPECT_NEAR(surface.value().meanDistance_mm(identity, rotated), meanPerpendicular * chord, 1e-9);
  EXPECT_NEAR(surface.value().maxDistance_mm(identity, rotated), maxPerpendicular * chord, 1e-9);
  // On a ball the mean distance from the axis is π/4 of the radius.
  EXPECT_NEAR(surface.value().meanDistance_mm(identity, rotated), std::numbers::pi / 4.0 * kBallRadius_mm * chord, 0.15);
}

TEST(BoneSurface, SubsamplesDeterministicallyAndEvenly) {
  const fct::Volume ball = ballVolume(kBallCentre_lps_mm, kBallRadius_mm);
  const auto first = fct::BoneSurface::extract(ball, 250.0, 300);
  const auto second = fct::BoneSurface::extract(ball, 250.0, 300);
  ASSERT_TRUE(first.ok()) << first.error();
  ASSERT_TRUE(second.ok()) << second.error();
  ASSERT_EQ(first.value().points_ct_mm().size(), 300u);
  EXPECT_GT(first.value().boundaryVoxelCount(), 300u);
  EXPECT_EQ(first.value().points_ct_mm(), second.value().points_ct_mm());
  // Evenly spread: the centroid of the subsample stays near the ball's centre (every octant is represented).
  EXPECT_LT((first.value().centroid_ct_mm() - kBallCentre_lps_mm).norm(), 1.0);
}

TEST(BoneSurface, FindsThePhantomsBone) {
  fct::PhantomOptions options;
  options.dims = Eigen::Vector3i(64, 64, 48);
  options.spacing_mm = 2.5;
  auto phantom = fct::PhantomBuilder::build(options);
  ASSERT_TRUE(phantom.ok()) << phantom.error();
  const auto surface = fct::BoneSurface::extract(phantom.value());
  ASSERT_TRUE(surface.ok()) << surface.error();
  EXPECT_GT(surface.value().points_ct_mm().size(), 1000u);
  for (const auto& p : surface.value().points_ct_mm()) {
    const Eigen::Vector3d ijk = phantom.value().ijkFromLps(p).array().round();
    ASSERT_GE(phantom.value().at(static_cast<int>(ijk.x()), static_cast<int>(ijk.y()), static_cast<int>(ijk.z())), 250.0f);
  }
  EXPECT_GT(surface.value().radius_mm(), 20.0);
  EXPECT_LT(surface.value().radius_mm(), 120.0);
}

TEST(BoneSurface, ThresholdAboveTheMaximumIsAClearError) {
  const auto surface = fct::BoneSurface::extract(ballVolume(kBallCentre_lps_mm, kBallRadius_mm), 5000.0);
  ASSERT_FALSE(surface.ok());
  EXPECT_NE(surface.error().find("5000"), std::string::npos) << surface.error();
  EXPECT_NE(surface.error().find("-1000..1000"), std::string::npos) << surface.error();
}

TEST(BoneSurface, RejectsEmptyVolumeAndBadArguments) {
  EXPECT_FALSE(fct::BoneSurface::extract(fct::Volume()).ok());
  const fct::Volume ball = ballVolume(kBallCentre_lps_mm, kBallRadius_mm);
  EXPECT_FALSE(fct::BoneSurface::extract(ball, std::nan(""), 100).ok());
  EXPECT_FALSE(fct::BoneSurface::extract(ball, 250.0, 0).ok());
}

TEST(BoneSurface, FindsThePelvisCtsBone) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  auto ct = fct::VolumeFileIO::read(fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz");
  ASSERT_TRUE(ct.ok()) << ct.error();
  const auto surface = fct::BoneSurface::extract(ct.value());
  ASSERT_TRUE(surface.ok()) << surface.error();
  // At 3 mm voxels the bone has fewer boundary voxels than the default cap, so all are kept.
  EXPECT_GT(surface.value().boundaryVoxelCount(), 5000u);
  EXPECT_EQ(surface.value().points_ct_mm().size(),
            std::min(surface.value().boundaryVoxelCount(), fct::BoneSurface::kDefaultMaxPoints));
  // Pelvis, spine and hips span a few hundred mm; the centroid lies inside the CT's field of view.
  EXPECT_GT(surface.value().radius_mm(), 50.0);
  EXPECT_LT(surface.value().radius_mm(), 250.0);
  const Eigen::Vector3d ijk = ct.value().ijkFromLps(surface.value().centroid_ct_mm());
  EXPECT_TRUE((ijk.array() >= 0.0).all() && (ijk.array() < ct.value().dims().cast<double>().array()).all()) << ijk;
}
