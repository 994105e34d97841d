// Our exact DRR against the real peer, `plastimatch drr -i exact`, on real CTs with the same geometry.
// Both integrate the same voxel values: plastimatch gets a MetaImage of max(HU + 1000, 0) with an identity direction
// (it ignores direction cosines) and `-P none` (no HU conversion of its own); our attenuation DRR integrates
// µ_water · max(1 + HU/1000, 0), which is proportional. NCC is insensitive to that scale.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "Drr/DrrRendererFactory.h"
#include "IO/Dicom/DicomSeriesReader.h"
#include "IO/Volume/VolumeFileIO.h"
#include "TestSupport.h"

namespace {

const char* const kPlastimatch = "/usr/bin/plastimatch";

/// The geometry of one `plastimatch drr` call. Note: plastimatch 1.9.4 takes `-r` and `-z` as "columns rows" and
/// "width height" (the first number is along the detector's columns, i.e. the image width), although its help text
/// says "row col"; verified with a one-voxel bead. Its PFM output stores the top detector row (toward --vup) first.
struct PlastimatchView {
  Eigen::Vector3d isocenter_mm, nrm, vup;
  double sad_mm = 1000.0, sid_mm = 1500.0;
  int cols = 200, rows = 150;
  double width_mm = 400.0, height_mm = 300.0;

  /// The same view as our Camera: source at isocenter + sad · nrm, looking along -nrm; columns run along vup × nrm,
  /// rows away from vup; principal point at the detector centre ((n-1)/2, plastimatch's default -c).
  fct::Camera camera() const {
    const Eigen::Vector3d n = nrm.normalized();
    Eigen::Matrix3d R;
    R.col(2) = -n;
    R.col(0) = vup.cross(n).normalized();
    R.col(1) = R.col(2).cross(R.col(0));
    fct::CameraIntrinsics in;
    in.cols = cols;
    in.rows = rows;
    in.pixelSpacing_mm = {width_mm / cols, height_mm / rows};
    in.sourceToDetector_mm = sid_mm;
    in.principalPoint_px = {0.5 * (cols - 1), 0.5 * (rows - 1)};
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R;
    T.translation() = isocenter_mm + sad_mm * n;
    return fct::Camera::create(in, T).value();
  }

  std::string arguments() const {
    return fmt::format("-i exact -P none -t pfm -r \"{} {}\" -z \"{} {}\" --sad {} --sid {} --nrm \"{} {} {}\" "
                       "--vup \"{} {} {}\" -o \"{} {} {}\"",
                       cols, rows, width_mm, height_mm, sad_mm, sid_mm, nrm.x(), nrm.y(), nrm.z(), vup.x(), vup.y(),
                       vup.z(), isocenter_mm.x(), isocenter_mm.y(), isocenter_mm.z());
  }
};

/// A copy of `ct` whose direction is the identity (axes re-ordered and flipped), for volumes whose direction is a
/// signed permutation; fails otherwise.
fct::Result<fct::Volume> withIdentityDirection(const fct::Volume& ct) {
  const Eigen::Matrix3d& D = ct.direction_lps();
  int oldAxis[3];
  bool flipped[3];
  for (int a = 0; a < 3; ++a) {
    Eigen::Index b = 0;
    D.row(a).cwiseAbs().maxCoeff(&b);
    if (std::abs(std::abs(D(a, b)) - 1.0) > 1e-6) return fct::fail("direction is not a signed permutation");
    oldAxis[a] = static_cast<int>(b);
    flipped[a] = D(a, b) < 0.0;
  }
  Eigen::Vector3i dims;
  Eigen::Vector3d spacing;
  for (int a = 0; a < 3; ++a) {
    dims[a] = ct.dims()[oldAxis[a]];
    spacing[a] = ct.spacing_mm()[oldAxis[a]];
  }
  auto oldIndex = [&](const Eigen::Vector3i& p) {
    Eigen::Vector3i q;
    for (int a = 0; a < 3; ++a) q[oldAxis[a]] = flipped[a] ? dims[a] - 1 - p[a] : p[a];
    return q;
  };
  auto result = fct::Volume::create(dims, spacing, ct.lpsFromIjk(oldIndex(Eigen::Vector3i::Zero()).cast<double>()));
  if (!result.ok()) return result;
  fct::Volume& out = result.value();
  for (int k = 0; k < dims.z(); ++k)
    for (int j = 0; j < dims.y(); ++j)
      for (int i = 0; i < dims.x(); ++i) {
        const Eigen::Vector3i q = oldIndex({i, j, k});
        out.at(i, j, k) = ct.at(q.x(), q.y(), q.z());
      }
  return result;
}

/// Writes max(HU + 1000, 0) as a MetaImage of 16-bit integers (identity direction required).
void writeShiftedHuMha(const fct::Volume& ct, const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary);
  const auto& o = ct.origin_lps_mm();
  const auto& s = ct.spacing_mm();
  out << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\n"
      << "TransformMatrix = 1 0 0 0 1 0 0 0 1\n"
      << fmt::format("Offset = {} {} {}\nElementSpacing = {} {} {}\nDimSize = {} {} {}\n", o.x(), o.y(), o.z(), s.x(),
                     s.y(), s.z(), ct.dims().x(), ct.dims().y(), ct.dims().z())
      << "ElementType = MET_SHORT\nElementDataFile = LOCAL\n";
  std::vector<std::int16_t> values(ct.voxelCount());
  for (std::size_t n = 0; n < values.size(); ++n) {
    values[n] = static_cast<std::int16_t>(std::clamp(std::lround(ct.voxels()[n] + 1000.0f), 0L, 32767L));
  }
  out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * 2));
}

/// Reads plastimatch's PFM output (little-endian floats, first stored line = top detector row).
fct::Result<fct::FloatImage> readPlastimatchPfm(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int cols = 0, rows = 0;
  double scale = 0.0;
  if (!(in >> magic >> cols >> rows >> scale) || magic != "Pf" || scale >= 0.0) {
    return fct::fail("not a little-endian grey PFM: " + path.string());
  }
  in.get();
  fct::FloatImage image = fct::FloatImage::filled(cols, rows);
  in.read(reinterpret_cast<char*>(image.pixels.data()), static_cast<std::streamsize>(image.pixels.size() * 4));
  if (!in) return fct::fail("truncated PFM: " + path.string());
  return image;
}

double ncc(const fct::FloatImage& a, const fct::FloatImage& b) {
  const Eigen::Map<const Eigen::ArrayXf> x(a.pixels.data(), static_cast<Eigen::Index>(a.pixels.size()));
  const Eigen::Map<const Eigen::ArrayXf> y(b.pixels.data(), static_cast<Eigen::Index>(b.pixels.size()));
  const Eigen::ArrayXd dx = x.cast<double>() - x.cast<double>().mean();
  const Eigen::ArrayXd dy = y.cast<double>() - y.cast<double>().mean();
  return (dx * dy).sum() / std::sqrt((dx * dx).sum() * (dy * dy).sum());
}

/// Renders `ct` with our exact caster and with plastimatch for three views about the volume centre (AP, left
/// lateral, oblique) and checks NCC >= 0.99 and equal image totals (after the unit scale) for each.
void expectMatchesPlastimatch(const fct::Volume& ctAnyDirection) {
  const auto ct = withIdentityDirection(ctAnyDirection);
  ASSERT_TRUE(ct.ok()) << ct.error();
  const auto dir = fct::test::scratchDir();
  const auto mha = dir / "ct.mha";
  writeShiftedHuMha(ct.value(), mha);

  const auto volume = std::make_shared<const fct::DrrVolume>(fct::DrrVolume::create(ct.value()).value());
  const auto siddon = fct::DrrRendererFactory::create(volume).value();
  const Eigen::Vector3d centre = ct.value().centre_lps_mm();
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> views = {
      {Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, 1)},
      {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1)},
      {Eigen::Vector3d(0.6, -0.7, 0.3), Eigen::Vector3d(0.1, 0.2, 1)}};
  int index = 0;
  for (const auto& [nrm, vup] : views) {
    PlastimatchView view{centre, nrm, vup};
    const std::string prefix = (dir / fmt::format("view{}_", index++)).string();
    const std::string command = fmt::format("{} drr {} -O '{}' '{}' > '{}log.txt' 2>&1", kPlastimatch, view.arguments(),
                                            prefix, mha.string(), prefix);
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
    const auto theirs = readPlastimatchPfm(prefix + "0000.pfm");
    ASSERT_TRUE(theirs.ok()) << theirs.error();
    const auto ours = siddon->render(view.camera(), Eigen::Isometry3d::Identity());
    ASSERT_TRUE(ours.ok()) << ours.error();
    ASSERT_EQ(theirs.value().cols, ours.value().cols);
    ASSERT_EQ(theirs.value().rows, ours.value().rows);
    const double score = ncc(ours.value(), theirs.value());
    EXPECT_GE(score, 0.99) << "view nrm " << nrm.transpose() << "; plastimatch: " << command;
    double sumOurs = 0.0, sumTheirs = 0.0;
    for (std::size_t n = 0; n < ours.value().pixels.size(); ++n) {
      sumOurs += ours.value().pixels[n];
      sumTheirs += theirs.value().pixels[n];
    }
    // plastimatch integrates value · cm; ours is µ_water/1000 · value · mm, so the totals differ by µ_water / 100.
    const double expectedScale = fct::DrrValueOptions::kWaterAttenuationAt60keV_per_mm / 100.0;
    EXPECT_NEAR(sumOurs / sumTheirs, expectedScale, 0.01 * expectedScale) << "image totals disagree beyond 1 %";
    ::testing::Test::RecordProperty(fmt::format("ncc_view{}", index - 1), fmt::format("{:.5f}", score));
    std::cout << fmt::format("NCC with plastimatch drr -i exact, view nrm ({:.1f} {:.1f} {:.1f}): {:.5f}\n", nrm.x(),
                             nrm.y(), nrm.z(), score);
  }
}

}  // namespace

TEST(DrrPlastimatchComparison, HeadPhantomMatchesPlastimatchExact) {
  if (!std::filesystem::exists(kPlastimatch)) GTEST_SKIP() << "plastimatch not installed at " << kPlastimatch;
  FCT_REQUIRE_DATA("ct/head_phantom_philips_bone");
  const auto ct = fct::DicomSeriesReader::read(fct::test::dataDir() / "ct/head_phantom_philips_bone");
  ASSERT_TRUE(ct.ok()) << ct.error();
  expectMatchesPlastimatch(ct.value());
}

TEST(DrrPlastimatchComparison, PelvisMatchesPlastimatchExact) {
  if (!std::filesystem::exists(kPlastimatch)) GTEST_SKIP() << "plastimatch not installed at " << kPlastimatch;
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  // NIfTI (RAS on disk) comes back in LPS with a flipped direction; expectMatchesPlastimatch re-orders it to identity.
  const auto ct = fct::VolumeFileIO::read(fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz");
  ASSERT_TRUE(ct.ok()) << ct.error();
  expectMatchesPlastimatch(ct.value());
}
