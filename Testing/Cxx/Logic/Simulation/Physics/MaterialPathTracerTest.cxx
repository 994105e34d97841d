#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "Simulation/Physics/MaterialPathTracer.h"

namespace {
constexpr int kSoft = static_cast<int>(fct::Material::SoftTissue);
constexpr int kBone = static_cast<int>(fct::Material::CorticalBone);
constexpr int kAir = static_cast<int>(fct::Material::Air);
}  // namespace

TEST(MaterialPathTracer, TakesExactPathLengthsThroughARotatedAnisotropicGrid) {
  // 0 HU everywhere: the soft-tissue mass path is ρ = 1 g/cm³ times the chord through the grid's box.
  const Eigen::Matrix3d direction = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const fct::Volume ct = fct::Volume::create(Eigen::Vector3i(17, 23, 11), Eigen::Vector3d(1.3, 0.9, 2.5),
                                             Eigen::Vector3d(5, -3, 2), direction, 0.0f)
                             .value();
  auto tracer = fct::MaterialPathTracer::create(ct, {});
  ASSERT_TRUE(tracer.ok()) << tracer.error();
  // A ray through the grid centre along the k axis crosses 11 * 2.5 mm.
  const Eigen::Vector3d centre = ct.lpsFromIjk(Eigen::Vector3d(8, 11, 5));
  const Eigen::Vector3d k = direction.col(2);
  const fct::MassPaths along = tracer.value().trace(centre - 100.0 * k, k);
  EXPECT_NEAR(along[kSoft], 2.75, 1e-9);  // cm · g/cm³
  // An oblique ray: compare with the analytic chord of the box [-0.5, dims - 0.5] in index space.
  const Eigen::Vector3d d = (direction * Eigen::Vector3d(0.3, -0.5, 0.8)).normalized();
  const fct::MassPaths oblique = tracer.value().trace(centre - 200.0 * d, d);
  const Eigen::Vector3d o_ijk = ct.ijkFromLps(centre - 200.0 * d);
  const Eigen::Vector3d d_ijk = ct.T_ijk_from_lps().linear() * d;
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    double s0 = (-0.5 - o_ijk[a]) / d_ijk[a], s1 = (ct.dims()[a] - 0.5 - o_ijk[a]) / d_ijk[a];
    if (s0 > s1) std::swap(s0, s1);
    t0 = std::max(t0, s0);
    t1 = std::min(t1, s1);
  }
  EXPECT_NEAR(oblique[kSoft], (t1 - t0) * 0.1, 1e-9);
  // A ray that misses.
  const fct::MassPaths miss = tracer.value().trace(centre + Eigen::Vector3d(500, 0, 0), k);
  EXPECT_EQ(miss[kSoft], 0.0);
}

TEST(MaterialPathTracer, SplitsHounsfieldValuesIntoMaterials) {
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(3, 1, 1), Eigen::Vector3d::Constant(10.0)).value();
  ct.at(0, 0, 0) = -1000.0f;  // air
  ct.at(1, 0, 0) = 800.0f;    // half cortical bone, half soft tissue
  ct.at(2, 0, 0) = 1500.0f;   // cortical bone
  auto tracer = fct::MaterialPathTracer::create(ct, {});
  ASSERT_TRUE(tracer.ok());
  const fct::MassPaths paths = tracer.value().trace(Eigen::Vector3d(-50, 0, 0), Eigen::Vector3d::UnitX());
  EXPECT_NEAR(paths[kAir], 0.001205, 1e-12);
  EXPECT_NEAR(paths[kSoft], 1.1 * 0.5, 1e-9);
  EXPECT_NEAR(paths[kBone], 1.92 * 0.5 + 1.92, 1e-9);
}

TEST(MaterialPathTracer, RejectsNonFiniteVoxelsAndBadThresholds) {
  fct::Volume ct = fct::Volume::create(Eigen::Vector3i(2, 2, 2), Eigen::Vector3d::Ones()).value();
  fct::HuMaterialModel backwards;
  backwards.boneFrom_hu = 2000.0;
  EXPECT_FALSE(fct::MaterialPathTracer::create(ct, backwards).ok());
  ct.at(1, 1, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(fct::MaterialPathTracer::create(ct, {}).ok());
  EXPECT_FALSE(fct::MaterialPathTracer::create(fct::Volume(), {}).ok());
}
