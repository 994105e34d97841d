#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "Drr/DrrVolume.h"

namespace {

fct::Volume fourVoxelCt() {
  fct::Volume ct = fct::Volume::create({4, 1, 1}, {0.5, 0.7, 2.0}, {10, 20, 30}).value();
  ct.voxels() = {-1200.0f, -1000.0f, 0.0f, 1000.0f};
  return ct;
}

}  // namespace

TEST(DrrVolume, ConvertsHuToAttenuationWithAirClampedToZero) {
  const auto volume = fct::DrrVolume::create(fourVoxelCt());
  ASSERT_TRUE(volume.ok()) << volume.error();
  const double mu = fct::DrrValueOptions::kWaterAttenuationAt60keV_per_mm;
  const std::vector<float>& v = volume.value().values().voxels();
  EXPECT_EQ(v[0], 0.0f);
  EXPECT_EQ(v[1], 0.0f);
  EXPECT_NEAR(v[2], mu, 1e-7);
  EXPECT_NEAR(v[3], 2.0 * mu, 1e-7);
  EXPECT_EQ(volume.value().options().kind, fct::DrrValueKind::Attenuation);
}

TEST(DrrVolume, BoneContrastScalesOnlyTheAttenuationAboveWaters) {
  fct::Volume ct = fourVoxelCt();
  ct.voxels() = {-500.0f, 100.0f, 500.0f, 1100.0f};
  fct::DrrValueOptions options;
  options.boneContrast = 1.8;
  const auto volume = fct::DrrVolume::create(ct, options);
  ASSERT_TRUE(volume.ok()) << volume.error();
  const double mu = fct::DrrValueOptions::kWaterAttenuationAt60keV_per_mm;
  const std::vector<float>& v = volume.value().values().voxels();
  EXPECT_NEAR(v[0], 0.5 * mu, 1e-7);  // water-like tissue scales with water, up to 100 HU
  EXPECT_NEAR(v[1], 1.1 * mu, 1e-7);
  EXPECT_NEAR(v[2], (1.1 + 1.8 * 0.4) * mu, 1e-7);  // water-bone mixtures: what they add above 100 HU times 1.8
  EXPECT_NEAR(v[3], (1.1 + 1.8) * mu, 1e-7);
  EXPECT_EQ(volume.value().options().boneContrast, 1.8);
}

TEST(DrrVolume, RawValuesAndGeometryAreThoseOfTheCt) {
  const fct::Volume ct = fourVoxelCt();
  fct::DrrValueOptions options;
  options.kind = fct::DrrValueKind::Raw;
  const auto volume = fct::DrrVolume::create(ct, options);
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_EQ(volume.value().values().voxels(), ct.voxels());
  const Eigen::Vector3d p_ct_mm(11.3, 19.0, 33.0);
  EXPECT_NEAR((volume.value().T_ct_from_ijk() * (volume.value().T_ijk_from_ct() * p_ct_mm) - p_ct_mm).norm(), 0.0, 1e-12);
  EXPECT_NEAR((volume.value().T_ijk_from_ct() * p_ct_mm - ct.ijkFromLps(p_ct_mm)).norm(), 0.0, 1e-12);
  EXPECT_EQ(volume.value().boxMax_ijk(), Eigen::Vector3d(3.5, 0.5, 0.5));
}

TEST(DrrVolume, ContentBoxHoldsExactlyTheNonZeroVoxels) {
  fct::Volume ct = fct::Volume::create({10, 8, 6}, {1.0, 1.0, 1.0}, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                       -1000.0f)
                       .value();
  ct.at(2, 5, 1) = 40.0f;
  ct.at(7, 3, 4) = 200.0f;
  const auto volume = fct::DrrVolume::create(ct);  // attenuation: air -> 0
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_TRUE(volume.value().hasContent());
  EXPECT_EQ(volume.value().contentBoxMin_ijk(), Eigen::Vector3d(1.5, 2.5, 0.5));
  EXPECT_EQ(volume.value().contentBoxMax_ijk(), Eigen::Vector3d(7.5, 5.5, 4.5));

  fct::DrrValueOptions raw;
  raw.kind = fct::DrrValueKind::Raw;  // raw: air is -1000, so everything is content
  const auto rawVolume = fct::DrrVolume::create(ct, raw);
  EXPECT_EQ(rawVolume.value().contentBoxMin_ijk(), rawVolume.value().boxMin_ijk());
  EXPECT_EQ(rawVolume.value().contentBoxMax_ijk(), rawVolume.value().boxMax_ijk());

  ct.voxels().assign(ct.voxelCount(), -1024.0f);
  EXPECT_FALSE(fct::DrrVolume::create(ct).value().hasContent());
}

TEST(DrrVolume, RejectsEmptyCtNonFiniteVoxelsBadWaterAttenuationAndBadBoneContrast) {
  EXPECT_FALSE(fct::DrrVolume::create(fct::Volume()).ok());
  fct::Volume ct = fourVoxelCt();
  ct.voxels()[2] = std::numeric_limits<float>::quiet_NaN();
  const auto nan = fct::DrrVolume::create(ct);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().find("1 voxels that are NaN"), std::string::npos) << nan.error();
  fct::DrrValueOptions options;
  options.waterAttenuation_per_mm = 0.0;
  EXPECT_FALSE(fct::DrrVolume::create(fourVoxelCt(), options).ok());
  for (const double contrast : {0.0, -1.0, 10.5, std::numeric_limits<double>::quiet_NaN()}) {
    fct::DrrValueOptions bad;
    bad.boneContrast = contrast;
    const auto refused = fct::DrrVolume::create(fourVoxelCt(), bad);
    ASSERT_FALSE(refused.ok()) << contrast;
    EXPECT_NE(refused.error().find("bone contrast must be above 0 and at most 10"), std::string::npos) << refused.error();
  }
}

TEST(DrrVolume, CoarsenedAveragesBlocksWithAirBeyondTheEdgeAndKeepsTheFrame) {
  Eigen::Matrix3d direction;
  direction << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // a rotation: i along +P, j along -L
  fct::Volume ct = fct::Volume::create({5, 4, 3}, {0.5, 0.7, 2.0}, {10, 20, 30}, direction).value();
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i) ct.at(i, j, k) = static_cast<float>(i + 10 * j + 100 * k);
  fct::DrrValueOptions raw;
  raw.kind = fct::DrrValueKind::Raw;
  const fct::DrrVolume fine = fct::DrrVolume::create(ct, raw).value();
  const auto coarse = fine.coarsened({2, 2, 1});
  ASSERT_TRUE(coarse.ok()) << coarse.error();
  const fct::Volume& c = coarse.value().values();
  EXPECT_EQ(c.dims(), Eigen::Vector3i(3, 2, 3)) << "5 voxels in blocks of 2 round up to 3";
  EXPECT_EQ(c.spacing_mm(), Eigen::Vector3d(1.0, 1.4, 2.0));
  EXPECT_FLOAT_EQ(c.at(0, 0, 0), (0 + 1 + 10 + 11) / 4.0f);
  EXPECT_FLOAT_EQ(c.at(1, 1, 2), (222 + 223 + 232 + 233) / 4.0f);
  EXPECT_FLOAT_EQ(c.at(2, 0, 1), (104 + 114) / 4.0f) << "the missing column counts as 0";
  // A coarse voxel's centre is the centroid of its block's voxel centres, in the same CT frame.
  EXPECT_NEAR((c.lpsFromIjk({1, 1, 2}) - ct.lpsFromIjk({2.5, 2.5, 2.0})).norm(), 0.0, 1e-12);
  EXPECT_NEAR((coarse.value().T_ct_from_ijk() * Eigen::Vector3d(1, 1, 2) - ct.lpsFromIjk({2.5, 2.5, 2.0})).norm(), 0.0,
              1e-12);
  EXPECT_EQ(coarse.value().options().kind, fct::DrrValueKind::Raw);
  EXPECT_FALSE(fine.coarsened({0, 1, 1}).ok());
  EXPECT_NE(fine.coarsened({1, 1, -2}).error().find("at least 1"), std::string::npos);
}

TEST(DrrVolume, CoarsenedKeepsTheTotalAttenuation) {
  fct::Volume ct = fct::Volume::create({12, 9, 8}, {0.45, 0.45, 1.0}).value();
  for (std::size_t n = 0; n < ct.voxels().size(); ++n) ct.voxels()[n] = static_cast<float>((n * 7919) % 2400) - 1000.0f;
  const fct::DrrVolume fine = fct::DrrVolume::create(ct).value();
  const fct::DrrVolume coarse = fine.coarsened({4, 3, 2}).value();
  double fineSum = 0.0, coarseSum = 0.0;
  for (const float v : fine.values().voxels()) fineSum += v;
  for (const float v : coarse.values().voxels()) coarseSum += v;
  EXPECT_NEAR(coarseSum * 24.0, fineSum, 1e-5 * fineSum) << "attenuation x volume is kept";
}

TEST(DrrVolume, ParsesValueKindNames) {
  for (const auto kind : {fct::DrrValueKind::Attenuation, fct::DrrValueKind::Raw}) {
    const auto parsed = fct::DrrVolume::parseValueKind(fct::DrrVolume::valueKindName(kind));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(parsed.value(), kind);
  }
  EXPECT_FALSE(fct::DrrVolume::parseValueKind("hu").ok());
}

TEST(DrrVolume, JFastestCopyHoldsEveryValueAndIsSharedByCopies) {
  fct::Volume ct = fct::Volume::create({5, 4, 3}, {1, 1, 1}).value();
  for (std::size_t n = 0; n < ct.voxels().size(); ++n) ct.voxels()[n] = static_cast<float>(n);
  fct::DrrValueOptions options;
  options.kind = fct::DrrValueKind::Raw;
  const fct::DrrVolume volume = fct::DrrVolume::create(ct, options).value();
  const fct::DrrVolume copy = volume;
  const float* jFastest = copy.valuesJFastest();
  ASSERT_NE(jFastest, nullptr);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i) EXPECT_EQ(jFastest[static_cast<std::size_t>(j + 4 * (i + 5 * k))], ct.at(i, j, k));
  EXPECT_EQ(volume.valuesJFastest(), jFastest);  // made once, shared
}

TEST(DrrVolume, ConvertingInPlaceGivesTheSameValuesAsACopy) {
  fct::Volume ct = fct::Volume::create({6, 5, 4}, {0.5, 0.7, 2.0}, {10, 20, 30}).value();
  for (std::size_t n = 0; n < ct.voxels().size(); ++n) ct.voxels()[n] = -1100.0f + 37.0f * static_cast<float>(n);
  const fct::DrrVolume copied = fct::DrrVolume::create(ct).value();
  fct::Volume consumed = ct;
  const fct::DrrVolume inPlace = fct::DrrVolume::create(std::move(consumed)).value();
  EXPECT_EQ(inPlace.values().voxels(), copied.values().voxels());
  EXPECT_EQ(inPlace.contentBoxMin_ijk(), copied.contentBoxMin_ijk());
  EXPECT_EQ(inPlace.values().origin_lps_mm(), ct.origin_lps_mm());
  fct::Volume broken = ct;
  broken.voxels()[7] = NAN;
  EXPECT_NE(fct::DrrVolume::create(std::move(broken)).error().find("NaN"), std::string::npos);
}

namespace {

/// The value at continuous slice index z of column (i,j) interpolated linearly between slice centres, the outer
/// slices' values held to the volume's box faces (as TrilinearRayCaster samples along k).
double linearAlongK(const fct::Volume& v, int i, int j, double z) {
  const int nk = v.dims().z();
  const double clamped = std::clamp(z, 0.0, nk - 1.0);
  const int k0 = std::min(static_cast<int>(std::floor(clamped)), nk - 2);
  const double t = clamped - k0;
  return (1.0 - t) * v.at(i, j, k0) + t * v.at(i, j, k0 + 1);
}

fct::Volume randomThickSliceCt() {
  fct::Volume ct = fct::Volume::create({5, 4, 9}, {0.45, 0.45, 2.4}, {3, -2, 100}).value();
  for (std::size_t n = 0; n < ct.voxels().size(); ++n) ct.voxels()[n] = static_cast<float>((n * 7919) % 2400) - 1000.0f;
  return ct;
}

}  // namespace

TEST(DrrVolume, SliceAveragesDeconvolvedHaveTheCtsSliceValuesAsTheAveragesOfTheirInterpolant) {
  const fct::DrrVolume original = fct::DrrVolume::create(randomThickSliceCt()).value();
  const fct::DrrVolume deconvolved = original.sliceAveragesDeconvolved();
  ASSERT_EQ(deconvolved.dims(), original.dims());
  // Averaging the linear interpolant over each slice's box by the midpoint rule, independently of the solver.
  constexpr int kSamples = 4000;
  for (int j = 0; j < original.dims().y(); ++j) {
    for (int i = 0; i < original.dims().x(); ++i) {
      for (int k = 0; k < original.dims().z(); ++k) {
        double sum = 0.0;
        for (int s = 0; s < kSamples; ++s) sum += linearAlongK(deconvolved.values(), i, j, k - 0.5 + (s + 0.5) / kSamples);
        EXPECT_NEAR(sum / kSamples, original.values().at(i, j, k), 2e-6) << i << " " << j << " " << k;
      }
    }
  }
  EXPECT_NE(deconvolved.values().voxels(), original.values().voxels()) << "the slab edges are sharpened";
  EXPECT_NEAR((deconvolved.T_ct_from_ijk().matrix() - original.T_ct_from_ijk().matrix()).norm(), 0.0, 1e-12);
  EXPECT_EQ(deconvolved.values().spacing_mm(), original.values().spacing_mm());
  EXPECT_EQ(deconvolved.options().kind, original.options().kind);
}

TEST(DrrVolume, SliceAveragesDeconvolvedKeepAnAxiallyConstantCtAndAnAllAirColumn) {
  fct::Volume ct = fct::Volume::create({3, 2, 6}, {0.5, 0.5, 3.0}, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(),
                                       -1000.0f)
                       .value();
  for (int k = 0; k < 6; ++k) ct.at(1, 1, k) = 400.0f;  // a column of bone, constant along k
  const fct::DrrVolume original = fct::DrrVolume::create(ct).value();
  const fct::DrrVolume deconvolved = original.sliceAveragesDeconvolved();
  for (std::size_t n = 0; n < ct.voxels().size(); ++n) {
    EXPECT_NEAR(deconvolved.values().voxels()[n], original.values().voxels()[n], 1e-7) << n;
  }
  EXPECT_EQ(deconvolved.contentBoxMin_ijk(), original.contentBoxMin_ijk());
  EXPECT_EQ(deconvolved.contentBoxMax_ijk(), original.contentBoxMax_ijk());
  fct::Volume oneSlice = fct::Volume::create({2, 2, 1}, {1.0, 1.0, 2.0}).value();
  oneSlice.voxels() = {0.0f, 100.0f, -500.0f, 1000.0f};
  const fct::DrrVolume single = fct::DrrVolume::create(oneSlice).value();
  EXPECT_EQ(single.sliceAveragesDeconvolved().values().voxels(), single.values().voxels()) << "one slice is its average";
}

TEST(DrrVolume, SlicesAreThickFromOneAndAHalfTimesTheLargerPixel) {
  const auto withSpacing = [](const Eigen::Vector3d& spacing_mm) {
    return fct::DrrVolume::create(fct::Volume::create({2, 2, 2}, spacing_mm).value()).value().hasThickSlices();
  };
  EXPECT_TRUE(withSpacing({0.45, 0.45, 2.4})) << "the head phantom's 2.4 mm CT";
  EXPECT_TRUE(withSpacing({0.45, 0.45, 1.0})) << "its original 1 mm slices";
  EXPECT_FALSE(withSpacing({3.0, 3.0, 3.0})) << "a resampled cubic grid";
  EXPECT_FALSE(withSpacing({0.8, 0.5, 1.15}));
  EXPECT_TRUE(withSpacing({0.8, 0.5, 1.25}));
}
