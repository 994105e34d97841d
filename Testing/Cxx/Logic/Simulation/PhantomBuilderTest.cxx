#include <gtest/gtest.h>

#include <cstddef>
#include <functional>

#include "Simulation/PhantomBuilder.h"

namespace {

/// HU classes of the phantom.
enum class Tissue { Air, Fat, Soft, Cancellous, Cortical, Other };

Tissue classify(float hu) {
  if (hu < -900.0f) return Tissue::Air;
  if (hu > -150.0f && hu < -50.0f) return Tissue::Fat;
  if (hu > -20.0f && hu < 60.0f) return Tissue::Soft;
  if (hu >= 180.0f && hu <= 420.0f) return Tissue::Cancellous;
  if (hu >= 1200.0f && hu <= 1800.0f) return Tissue::Cortical;
  return Tissue::Other;
}

/// Fraction of bone voxels (cortical or cancellous, in either volume) whose class differs under the index map.
double boneMismatch(const fct::Volume& v, const std::function<Eigen::Vector3i(int, int, int)>& map) {
  std::size_t bone = 0, differ = 0;
  const Eigen::Vector3i& d = v.dims();
  for (int k = 0; k < d.z(); ++k)
    for (int j = 0; j < d.y(); ++j)
      for (int i = 0; i < d.x(); ++i) {
        const Tissue a = classify(v.at(i, j, k));
        const Eigen::Vector3i m = map(i, j, k);
        const Tissue b = classify(v.at(m.x(), m.y(), m.z()));
        const bool aBone = a == Tissue::Cortical || a == Tissue::Cancellous;
        const bool bBone = b == Tissue::Cortical || b == Tissue::Cancellous;
        if (aBone || bBone) {
          ++bone;
          if (aBone != bBone) ++differ;
        }
      }
  return bone ? static_cast<double>(differ) / static_cast<double>(bone) : 0.0;
}

}  // namespace

TEST(PhantomBuilder, IsDeterministicForASeedAndCentredAtLpsOrigin) {
  fct::PhantomOptions options;
  options.dims = {64, 64, 48};
  options.spacing_mm = 2.5;
  auto a = fct::PhantomBuilder::build(options);
  auto b = fct::PhantomBuilder::build(options);
  ASSERT_TRUE(a.ok()) << a.error();
  ASSERT_TRUE(b.ok()) << b.error();
  EXPECT_EQ(a.value().voxels(), b.value().voxels());
  EXPECT_NEAR(a.value().centre_lps_mm().norm(), 0.0, 1e-9);
  EXPECT_TRUE(a.value().direction_lps().isIdentity(0.0));
  EXPECT_EQ(a.value().spacing_mm(), Eigen::Vector3d::Constant(2.5));
  options.seed = 8;
  EXPECT_NE(fct::PhantomBuilder::build(options).value().voxels(), a.value().voxels());
}

TEST(PhantomBuilder, HasHuClassesInRealisticFractions) {
  auto result = fct::PhantomBuilder::build();
  ASSERT_TRUE(result.ok()) << result.error();
  const fct::Volume& volume = result.value();
  EXPECT_EQ(volume.dims(), Eigen::Vector3i(160, 160, 120));
  std::size_t counts[6] = {};
  for (const float hu : volume.voxels()) ++counts[static_cast<int>(classify(hu))];
  const auto fraction = [&](Tissue t) { return static_cast<double>(counts[static_cast<int>(t)]) / volume.voxelCount(); };
  // The body ellipse covers about 58 % of each slice; bone about 5 % of the volume.
  EXPECT_GT(fraction(Tissue::Air), 0.35);
  EXPECT_LT(fraction(Tissue::Air), 0.50);
  EXPECT_GT(fraction(Tissue::Fat), 0.06);
  EXPECT_LT(fraction(Tissue::Fat), 0.14);
  EXPECT_GT(fraction(Tissue::Soft), 0.35);
  EXPECT_LT(fraction(Tissue::Soft), 0.50);
  EXPECT_GT(fraction(Tissue::Cortical), 0.01);
  EXPECT_LT(fraction(Tissue::Cortical), 0.04);
  EXPECT_GT(fraction(Tissue::Cancellous), 0.015);
  EXPECT_LT(fraction(Tissue::Cancellous), 0.05);
  EXPECT_LT(fraction(Tissue::Other), 0.02);  // discs and transitions
  const auto [lo, hi] = volume.valueRange();
  EXPECT_EQ(lo, -1000.0f);
  EXPECT_LE(hi, 1800.0f);
  // Air surrounds the body: every corner voxel is air.
  EXPECT_EQ(volume.at(0, 0, 0), -1000.0f);
  EXPECT_EQ(volume.at(159, 159, 119), -1000.0f);
}

TEST(PhantomBuilder, DiffersFromEveryMirrorImageAndHalfTurn) {
  fct::PhantomOptions options;
  options.dims = {80, 80, 60};
  options.spacing_mm = 2.0;
  const fct::Volume v = fct::PhantomBuilder::build(options).value();
  const int X = v.dims().x() - 1, Y = v.dims().y() - 1, Z = v.dims().z() - 1;
  EXPECT_GT(boneMismatch(v, [&](int i, int j, int k) { return Eigen::Vector3i(X - i, j, k); }), 0.2) << "left-right";
  EXPECT_GT(boneMismatch(v, [&](int i, int j, int k) { return Eigen::Vector3i(i, Y - j, k); }), 0.2) << "front-back";
  EXPECT_GT(boneMismatch(v, [&](int i, int j, int k) { return Eigen::Vector3i(i, j, Z - k); }), 0.2) << "up-down";
  EXPECT_GT(boneMismatch(v, [&](int i, int j, int k) { return Eigen::Vector3i(X - i, Y - j, k); }), 0.2) << "about z";
  EXPECT_GT(boneMismatch(v, [&](int i, int j, int k) { return Eigen::Vector3i(X - i, j, Z - k); }), 0.2) << "about y";
  EXPECT_GT(boneMismatch(v, [&](int i, int j, int k) { return Eigen::Vector3i(i, Y - j, Z - k); }), 0.2) << "about x";
  EXPECT_GT(boneMismatch(v, [&](int i, int j, int k) { return Eigen::Vector3i(j, i, k); }), 0.2) << "quarter turn";
  EXPECT_EQ(boneMismatch(v, [](int i, int j, int k) { return Eigen::Vector3i(i, j, k); }), 0.0);
}

TEST(PhantomBuilder, RejectsBadOptions) {
  fct::PhantomOptions options;
  options.dims = {0, 10, 10};
  EXPECT_NE(fct::PhantomBuilder::build(options).error().find("dimensions must be positive"), std::string::npos);
  options.dims = {10, -3, 10};
  EXPECT_FALSE(fct::PhantomBuilder::build(options).ok());
  options.dims = {10, 10, 10};
  options.spacing_mm = 0.0;
  EXPECT_NE(fct::PhantomBuilder::build(options).error().find("spacing"), std::string::npos);
  options.spacing_mm = std::nan("");
  EXPECT_FALSE(fct::PhantomBuilder::build(options).ok());
  options.spacing_mm = 1.0;
  options.dims = {2000, 2000, 2000};
  EXPECT_NE(fct::PhantomBuilder::build(options).error().find("GB"), std::string::npos);
}
