#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "Drr/CutFaceRayMask.h"
#include "Simulation/StandardViews.h"

namespace {

/// A 2 mm CT of 40 x 40 x 20 voxels centred on the world origin: air with a tissue cylinder (radius 20 mm, along k)
/// through every slice, or ending two slices before each end face when `airAtTheEnds`.
fct::DrrVolume cylinderCt(bool airAtTheEnds) {
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(40, 40, 20), Eigen::Vector3d(2, 2, 2),
                                       Eigen::Vector3d(-39, -39, -19), Eigen::Matrix3d::Identity(), -1000.0f)
                       .value();
  for (int k = airAtTheEnds ? 2 : 0; k < (airAtTheEnds ? 18 : 20); ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i) {
        const Eigen::Vector3d p = ct.lpsFromIjk(Eigen::Vector3d(i, j, k));
        if (p.head<2>().norm() < 20.0) ct.at(i, j, k) = 0.0f;
      }
  return fct::DrrVolume::create(ct).value();
}

/// A 1 mm CT of 64 x 64 x 10 voxels centred on the world origin: air with a tissue rod one voxel thick along k at
/// voxel column (i, j).
fct::DrrVolume rodCt(int i, int j) {
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(64, 64, 10), Eigen::Vector3d(1, 1, 1),
                                       Eigen::Vector3d(-31.5, -31.5, -4.5), Eigen::Matrix3d::Identity(), -1000.0f)
                       .value();
  for (int k = 0; k < 10; ++k) ct.at(i, j, k) = 0.0f;
  return fct::DrrVolume::create(ct).value();
}

/// The first standard view (AP: rays across the slice axis), 128 x 128 at 1 mm.
fct::Camera apCamera() {
  fct::StandardViewOptions options;
  options.count = 1;
  options.cols = options.rows = 128;
  options.pixelSpacing_mm = 1.0;
  return fct::StandardViews::build(Eigen::Vector3d::Zero(), options).value().front().camera;
}

/// Whether the pixel where `p_world_mm` projects is valid in `mask`.
bool validAt(const fct::ValidMask& mask, const fct::Camera& camera, const Eigen::Vector3d& p_world_mm) {
  const Eigen::Vector2d uv = camera.project(p_world_mm);
  return mask.isValid(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())));
}

}  // namespace

TEST(CutFaceRayMask, LeavesOutRaysOverThePatientBeyondACutFace) {
  const fct::Camera camera = apCamera();
  auto cutFaces = fct::CutFaceRayMask::create(cylinderCt(false), 5.0);
  ASSERT_TRUE(cutFaces.ok()) << cutFaces.error();
  const fct::ValidMask mask = cutFaces.value().compute(camera, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(validAt(mask, camera, Eigen::Vector3d(0, 0, 0)));         // through the middle of the slab
  EXPECT_TRUE(validAt(mask, camera, Eigen::Vector3d(0, 0, 10)));        // 10 mm inside the top face
  EXPECT_FALSE(validAt(mask, camera, Eigen::Vector3d(0, 0, 18)));       // within the margin of it
  EXPECT_FALSE(validAt(mask, camera, Eigen::Vector3d(0, 0, 35)));       // beyond it, over the cylinder
  EXPECT_FALSE(validAt(mask, camera, Eigen::Vector3d(0, 0, -35)));      // beyond the bottom face
  EXPECT_TRUE(validAt(mask, camera, Eigen::Vector3d(40, 0, 35)));       // beside the cylinder's footprint
}

TEST(CutFaceRayMask, FindsAOneVoxelFootprintFromEveryDirectionWhereverItSitsInItsBlock) {
  // Rays reach the rod across empty voxel blocks, which the mask steps over in one jump: it must land on the rod all
  // the same, at a block's first, middle and last voxel, seen along i, along j and obliquely.
  fct::StandardViewOptions options;
  options.count = 3;
  options.cols = options.rows = 128;
  options.pixelSpacing_mm = 1.0;
  const auto views = fct::StandardViews::build(Eigen::Vector3d::Zero(), options).value();
  for (const auto& [i, j] : {std::pair{8, 8}, std::pair{47, 12}, std::pair{20, 55}, std::pair{63, 0}}) {
    const fct::DrrVolume volume = rodCt(i, j);
    auto cutFaces = fct::CutFaceRayMask::create(volume, 0.0);
    ASSERT_TRUE(cutFaces.ok()) << cutFaces.error();
    const Eigen::Vector3d rod_world_mm = volume.values().lpsFromIjk(Eigen::Vector3d(i, j, 0));
    for (const auto& view : views) {
      const fct::ValidMask mask = cutFaces.value().compute(view.camera, Eigen::Isometry3d::Identity());
      const std::string where = fmt::format("rod at ({}, {}), view {}", i, j, view.name);
      EXPECT_FALSE(validAt(mask, view.camera, rod_world_mm + Eigen::Vector3d(0, 0, -20))) << where;  // over it, beyond
      EXPECT_TRUE(validAt(mask, view.camera, rod_world_mm + Eigen::Vector3d(0, 0, 3))) << where;     // inside the slab
      EXPECT_GT(mask.validCount(), static_cast<std::size_t>(0.9 * 128 * 128)) << where;  // a rod hides only a strip
    }
  }
}

TEST(CutFaceRayMask, KeepsEveryRayWhenTheEndSlicesHoldNoPatient) {
  const fct::Camera camera = apCamera();
  const fct::ValidMask mask =
      fct::CutFaceRayMask::create(cylinderCt(true), 5.0).value().compute(camera, Eigen::Isometry3d::Identity());
  EXPECT_EQ(mask.validCount(), static_cast<std::size_t>(128 * 128));
}

TEST(CutFaceRayMask, RejectsABadMargin) {
  const fct::DrrVolume volume = cylinderCt(false);
  for (double margin : {-1.0, 600.0, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_FALSE(fct::CutFaceRayMask::create(volume, margin).ok()) << margin;
  }
}
