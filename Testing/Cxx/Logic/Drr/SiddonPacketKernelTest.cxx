// The AVX-512 packet traversal of SiddonRayCaster against the scalar traversal (the reference), on every dominant axis.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "Drr/SiddonPacketKernel.h"
#include "Drr/SiddonRayCaster.h"
#include "DrrTestPhantoms.h"
#include "Simulation/PhantomBuilder.h"
#include "Simulation/StandardViews.h"

namespace {

/// A 64^3 phantom with a rotated ellipsoid, a ball of another value and voxel noise, so that every voxel a ray meets
/// differs from its neighbours (errors in which voxel or which path length would show).
fct::Volume texturedCt(const Eigen::Vector3i& dims = Eigen::Vector3i(64, 64, 64)) {
  fct::Volume ct = fct::Volume::create(dims, {1.0, 0.9, 1.1}).value();
  ct = fct::Volume::create(dims, {1.0, 0.9, 1.1}, -ct.centre_lps_mm()).value();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.6, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  fct::test::voxelize(fct::test::ellipsoid(Eigen::Vector3d(-2.0, 1.0, 0.5), Eigen::Vector3d(25.0, 18.0, 12.0), R), 1.0f,
                      ct);
  std::mt19937 random(5);
  std::uniform_real_distribution<float> noise(0.0f, 0.3f);
  for (float& v : ct.voxels()) v += noise(random);
  return ct;
}

/// Largest |a - b| over the image, relative to the largest |b|.
double maxRelativeDifference(const fct::FloatImage& a, const fct::FloatImage& b) {
  double largest = 0.0, difference = 0.0;
  for (std::size_t n = 0; n < b.pixels.size(); ++n) {
    largest = std::max(largest, static_cast<double>(std::abs(b.pixels[n])));
    difference = std::max(difference, static_cast<double>(std::abs(a.pixels[n] - b.pixels[n])));
  }
  return difference / largest;
}

/// Camera orientations whose rays run mainly along each CT axis, and obliques between them.
std::vector<Eigen::Matrix3d> orientations() {
  std::vector<Eigen::Matrix3d> result;
  const Eigen::Matrix3d alongK = Eigen::Matrix3d::Identity();  // camera z = CT k
  result.push_back(alongK);
  result.push_back(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix());  // along j
  result.push_back(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix());  // along i
  result.push_back(fct::test::obliqueRotation());
  result.push_back((Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitY()))
                       .toRotationMatrix());  // rays near the diagonal: packets change dominant axis mid-row
  return result;
}

}  // namespace

TEST(SiddonPacketKernel, MatchesTheScalarTraversalAlongEveryAxisAndObliquely) {
  if (!fct::SiddonPacketKernel::available()) GTEST_SKIP() << "this processor has no AVX-512F; renders use the scalar traversal";
  const auto volume = fct::test::rawDrrVolume(texturedCt());
  const fct::SiddonRayCaster packets(volume, fct::SiddonTraversal::Fastest);
  const fct::SiddonRayCaster scalar(volume, fct::SiddonTraversal::Scalar);
  ASSERT_TRUE(packets.usesPackets());
  ASSERT_FALSE(scalar.usesPackets());
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  T_world_from_ct.translation() = Eigen::Vector3d(2.0, -3.0, 1.5);
  for (const Eigen::Matrix3d& R : orientations()) {
    const fct::Camera camera = fct::test::phantomCamera(R, 120, 100, 1.0);
    const fct::FloatImage fast = packets.render(camera, T_world_from_ct).value();
    const fct::FloatImage reference = scalar.render(camera, T_world_from_ct).value();
    int lit = 0;
    for (const float v : reference.pixels) lit += v > 0.0f ? 1 : 0;
    EXPECT_GT(lit, 2000);
    // Float positions inside a packet: within a few 1e-6 of the largest integral, not bit-exact.
    EXPECT_LT(maxRelativeDifference(fast, reference), 5e-6) << "orientation\n" << R;
  }
}

TEST(SiddonPacketKernel, GivesEachPixelTheSameValueWhateverItsNeighbours) {
  if (!fct::SiddonPacketKernel::available()) GTEST_SKIP() << "this processor has no AVX-512F; renders use the scalar traversal";
  const fct::SiddonRayCaster renderer(fct::test::rawDrrVolume(texturedCt()));
  for (const Eigen::Matrix3d& R : orientations()) {
    const fct::Camera camera = fct::test::phantomCamera(R, 120, 100, 1.0);
    const fct::FloatImage full = renderer.render(camera, Eigen::Isometry3d::Identity()).value();
    // Every third pixel alone, then runs of 5 starting at odd columns: other packets than the full render's.
    fct::PixelIndexList sparse, runs;
    for (std::int32_t p = 0; p < full.cols * full.rows; p += 3) sparse.push_back(p);
    for (int row = 0; row < full.rows; row += 7) {
      for (int col = 1; col + 5 <= full.cols; col += 9) {
        for (int c = col; c < col + 5; ++c) runs.push_back(row * full.cols + c);
      }
    }
    for (const fct::PixelIndexList* list : {&sparse, &runs}) {
      const std::vector<float> values = renderer.renderPixels(camera, Eigen::Isometry3d::Identity(), 0, *list).value();
      for (std::size_t n = 0; n < list->size(); ++n) {
        ASSERT_EQ(values[n], full.pixels[static_cast<std::size_t>((*list)[n])]) << "pixel " << (*list)[n];
      }
    }
  }
}

TEST(SiddonPacketKernel, NarrowVolumesAndMissingRaysUseTheScalarResult) {
  // 31 voxels along i and j: narrower than the kernel's window, so every ray takes the scalar traversal.
  const auto narrow = fct::test::rawDrrVolume(texturedCt(Eigen::Vector3i(31, 31, 40)));
  const fct::SiddonRayCaster fastest(narrow, fct::SiddonTraversal::Fastest);
  const fct::SiddonRayCaster scalar(narrow, fct::SiddonTraversal::Scalar);
  for (const Eigen::Matrix3d& R : orientations()) {
    const fct::Camera camera = fct::test::phantomCamera(R, 64, 48, 1.5);
    EXPECT_EQ(fastest.render(camera, Eigen::Isometry3d::Identity()).value().pixels,
              scalar.render(camera, Eigen::Isometry3d::Identity()).value().pixels);
  }
  // The CT moved far out of every ray: an all-zero image, not garbage from lanes without a ray.
  const fct::SiddonRayCaster renderer(fct::test::rawDrrVolume(texturedCt()));
  Eigen::Isometry3d away = Eigen::Isometry3d::Identity();
  away.translation() = Eigen::Vector3d(0.0, 0.0, 5000.0);
  const fct::FloatImage empty = renderer.render(fct::test::phantomCamera(Eigen::Matrix3d::Identity()), away).value();
  EXPECT_EQ(*std::max_element(empty.pixels.begin(), empty.pixels.end()), 0.0f);
}

TEST(SiddonPacketKernel, MatchesTheScalarTraversalOnThePhantomAndItsCoarseLevels) {
  if (!fct::SiddonPacketKernel::available()) GTEST_SKIP() << "this processor has no AVX-512F; renders use the scalar traversal";
  fct::PhantomOptions phantom;
  phantom.dims = Eigen::Vector3i(80, 80, 60);
  phantom.spacing_mm = 2.0;
  const auto full = std::make_shared<const fct::DrrVolume>(
      fct::DrrVolume::create(fct::PhantomBuilder::build(phantom).value()).value());
  fct::StandardViewOptions viewOptions;
  viewOptions.count = 5;
  viewOptions.cols = 192;
  viewOptions.rows = 160;
  viewOptions.pixelSpacing_mm = 1.6;
  viewOptions.sourceToIsocentre_mm = 700.0;
  viewOptions.sourceToDetector_mm = 1000.0;
  const auto views = fct::StandardViews::build(Eigen::Vector3d::Zero(), viewOptions).value();
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  T_world_from_ct.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, -2, 3).normalized()).toRotationMatrix();
  T_world_from_ct.translation() = -full->values().centre_lps_mm() + Eigen::Vector3d(2.0, -3.0, 1.5);
  for (const int block : {1, 2}) {
    const auto volume = block == 1 ? full : std::make_shared<const fct::DrrVolume>(full->coarsened(Eigen::Vector3i::Constant(block)).value());
    const fct::SiddonRayCaster packets(volume, fct::SiddonTraversal::Fastest);
    const fct::SiddonRayCaster scalar(volume, fct::SiddonTraversal::Scalar);
    for (const fct::ViewSpec& view : views) {
      for (const int level : {0, 1, 2}) {
        const fct::FloatImage fast = packets.render(view.camera, T_world_from_ct, level).value();
        const fct::FloatImage reference = scalar.render(view.camera, T_world_from_ct, level).value();
        EXPECT_LT(maxRelativeDifference(fast, reference), 5e-6) << view.name << " level " << level << " block " << block;
      }
    }
  }
}
