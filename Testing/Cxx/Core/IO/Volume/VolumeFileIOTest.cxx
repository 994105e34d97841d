#include <gtest/gtest.h>
#include <zlib.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

#include "IO/Volume/VolumeFileIO.h"
#include "TestSupport.h"

namespace {

std::string gunzipFile(const std::filesystem::path& path) {
  std::string out;
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) return out;
  char buffer[65536];
  int got = 0;
  while ((got = gzread(file, buffer, sizeof(buffer))) > 0) out.append(buffer, static_cast<std::size_t>(got));
  gzclose(file);
  return out;
}

std::string gzipBytes(const std::string& data) {
  z_stream stream{};
  deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);  // +16: gzip wrapper
  std::string out(deflateBound(&stream, data.size()) + 32, '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  stream.avail_in = static_cast<uInt>(data.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  deflate(&stream, Z_FINISH);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return out;
}

void writeFile(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

template <typename T>
T field(const std::string& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

template <typename T>
void put(std::string& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

/// A little NIfTI-1 file with int16 voxels v = i + 10 j + 100 k and the given qform (qform_code 1, no sform).
std::string tinyNifti(const Eigen::Vector3i& dims, const Eigen::Vector3f& pixdim, float qfac, const Eigen::Vector3f& bcd,
                      const Eigen::Vector3f& qoffset, std::size_t dropBytes = 0) {
  std::string bytes(352, '\0');
  put<std::int32_t>(bytes, 0, 348);
  put<std::int16_t>(bytes, 40, 3);
  for (int a = 0; a < 3; ++a) put<std::int16_t>(bytes, 42 + 2 * a, static_cast<std::int16_t>(dims[a]));
  put<std::int16_t>(bytes, 70, 4);   // int16
  put<std::int16_t>(bytes, 72, 16);  // bitpix
  put<float>(bytes, 76, qfac);
  for (int a = 0; a < 3; ++a) put<float>(bytes, 80 + 4 * a, pixdim[a]);
  put<float>(bytes, 108, 352.0f);
  put<std::int16_t>(bytes, 252, 1);
  for (int a = 0; a < 3; ++a) put<float>(bytes, 256 + 4 * a, bcd[a]);
  for (int a = 0; a < 3; ++a) put<float>(bytes, 268 + 4 * a, qoffset[a]);
  std::memcpy(bytes.data() + 344, "n+1", 4);
  for (int k = 0; k < dims.z(); ++k)
    for (int j = 0; j < dims.y(); ++j)
      for (int i = 0; i < dims.x(); ++i) {
        const auto v = static_cast<std::int16_t>(i + 10 * j + 100 * k);
        bytes.append(reinterpret_cast<const char*>(&v), 2);
      }
  bytes.resize(bytes.size() - dropBytes);
  return bytes;
}

fct::Volume obliqueVolume() {
  Eigen::Matrix3d direction = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  direction.col(2) *= -1.0;  // a left-handed grid (det -1), as flipped scanner axes give
  auto volume = fct::Volume::create({7, 5, 4}, {0.7, 1.3, 2.5}, {-120.25, 33.5, 17.125}, direction).value();
  for (std::size_t n = 0; n < volume.voxelCount(); ++n) volume.voxels()[n] = -1000.0f + 3.37f * static_cast<float>(n);
  return volume;
}

void expectSameVolume(const fct::Volume& a, const fct::Volume& b) {
  EXPECT_EQ(a.dims(), b.dims());
  EXPECT_NEAR((a.spacing_mm() - b.spacing_mm()).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  EXPECT_NEAR((a.origin_lps_mm() - b.origin_lps_mm()).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  EXPECT_NEAR((a.direction_lps() - b.direction_lps()).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  EXPECT_EQ(a.voxels(), b.voxels());
}

}  // namespace

TEST(VolumeFileIO, ReadsPelvisNiftiIntoLpsAtSformPositions) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  const auto path = fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz";
  auto result = fct::VolumeFileIO::read(path);
  ASSERT_TRUE(result.ok()) << result.error();
  const fct::Volume& volume = result.value();
  EXPECT_EQ(volume.dims(), Eigen::Vector3i(122, 101, 112));
  EXPECT_NEAR((volume.spacing_mm() - Eigen::Vector3d::Constant(3.0)).norm(), 0.0, 1e-6);
  const auto [lo, hi] = volume.valueRange();
  EXPECT_EQ(lo, -1207.0f);
  EXPECT_EQ(hi, 3382.0f);

  // Independent check against the raw header: sform (RAS) rows, then RAS -> LPS by negating x and y.
  const std::string raw = gunzipFile(path);
  ASSERT_GE(raw.size(), 352u);
  ASSERT_GT(field<std::int16_t>(raw, 254), 0) << "the test expects a file with an sform";
  Eigen::Matrix<double, 3, 4> sform;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) sform(r, c) = field<float>(raw, 280 + 16 * r + 4 * c);
  for (const Eigen::Vector3d& ijk : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(121, 0, 0), Eigen::Vector3d(0, 100, 0),
                                    Eigen::Vector3d(17, 63, 111), Eigen::Vector3d(121, 100, 111)}) {
    Eigen::Vector3d p_lps_mm = sform * ijk.homogeneous();
    p_lps_mm.x() = -p_lps_mm.x();
    p_lps_mm.y() = -p_lps_mm.y();
    EXPECT_NEAR((volume.lpsFromIjk(ijk) - p_lps_mm).norm(), 0.0, 1e-3) << "at ijk " << ijk.transpose();
  }
  // A voxel's value is the raw int32 stored at its offset after vox_offset.
  const auto voxOffset = static_cast<std::size_t>(field<float>(raw, 108));
  for (const Eigen::Vector3i& ijk : {Eigen::Vector3i(61, 50, 56), Eigen::Vector3i(5, 90, 100)}) {
    const std::size_t n = volume.offset(ijk.x(), ijk.y(), ijk.z());
    EXPECT_EQ(volume.at(ijk.x(), ijk.y(), ijk.z()), static_cast<float>(field<std::int32_t>(raw, voxOffset + 4 * n)));
  }
}

TEST(VolumeFileIO, ReadsNiftiQformWithNegativeQfac) {
  const auto dir = fct::test::scratchDir();
  const Eigen::Vector3f bcd(0.1f, -0.3f, 0.2f);
  writeFile(dir / "q.nii", tinyNifti({4, 3, 2}, {2.0f, 3.0f, 4.0f}, -1.0f, bcd, {10.0f, -20.0f, 30.0f}));
  auto result = fct::VolumeFileIO::read(dir / "q.nii");
  ASSERT_TRUE(result.ok()) << result.error();
  // The NIfTI-1 standard's formula, written out: R from (a,b,c,d), columns scaled by pixdim, k flipped by qfac.
  const double b = bcd.x(), c = bcd.y(), d = bcd.z(), a = std::sqrt(1.0 - b * b - c * c - d * d);
  Eigen::Matrix3d R;
  R << a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c),
       2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b),
       2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b;
  for (const Eigen::Vector3d& ijk : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, 2, 1), Eigen::Vector3d(1, 0, 1)}) {
    Eigen::Vector3d p_ras = R * Eigen::Vector3d(2.0 * ijk.x(), 3.0 * ijk.y(), -4.0 * ijk.z()) +
                            Eigen::Vector3d(10.0, -20.0, 30.0);
    const Eigen::Vector3d p_lps(-p_ras.x(), -p_ras.y(), p_ras.z());
    EXPECT_NEAR((result.value().lpsFromIjk(ijk) - p_lps).norm(), 0.0, 1e-4) << "at ijk " << ijk.transpose();
  }
  EXPECT_NEAR(result.value().direction_lps().determinant(), -1.0, 1e-6);  // RAS->LPS (det +1) times the qfac flip
  EXPECT_EQ(result.value().at(3, 2, 1), 123.0f);
}

TEST(VolumeFileIO, RoundTripsObliqueNrrdMhaAndMhd) {
  const auto dir = fct::test::scratchDir();
  const fct::Volume original = obliqueVolume();
  for (const char* name : {"v.nrrd", "v.mha", "v.mhd"}) {
    SCOPED_TRACE(name);
    const fct::Status written = fct::VolumeFileIO::write(original, dir / name);
    ASSERT_TRUE(written.ok()) << written.error();
    auto back = fct::VolumeFileIO::read(dir / name);
    ASSERT_TRUE(back.ok()) << back.error();
    expectSameVolume(original, back.value());
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "v.raw"));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 4) << "temporary files were left behind";
}

TEST(VolumeFileIO, ConvertsRasNrrdToLps) {
  const auto dir = fct::test::scratchDir();
  std::string voxels;
  for (std::int16_t v = 0; v < 2 * 3 * 4; ++v) voxels.append(reinterpret_cast<const char*>(&v), 2);
  const std::string header =
      "NRRD0004\n# hand-written\ntype: short\ndimension: 3\nspace: right-anterior-superior\nsizes: 2 3 4\n"
      "space directions: (0,2,0) (-1.5,0,0) (0,0,3)\nkinds: domain domain domain\nendian: little\n";
  writeFile(dir / "ras.nrrd", header + "encoding: raw\nspace origin: (10,20,-5)\n\n" + voxels);
  writeFile(dir / "ras_gz.nrrd", header + "encoding: gzip\nspace origin: (10,20,-5)\n\n" + gzipBytes(voxels));
  writeFile(dir / "ras.nhdr", header + "encoding: gzip\nspace origin: (10,20,-5)\ndata file: ras.raw.gz\n");
  writeFile(dir / "ras.raw.gz", gzipBytes(voxels));
  for (const char* name : {"ras.nrrd", "ras_gz.nrrd", "ras.nhdr"}) {
    SCOPED_TRACE(name);
    auto result = fct::VolumeFileIO::read(dir / name);
    ASSERT_TRUE(result.ok()) << result.error();
    const fct::Volume& volume = result.value();
    EXPECT_NEAR((volume.origin_lps_mm() - Eigen::Vector3d(-10, -20, -5)).norm(), 0.0, 1e-12);
    EXPECT_NEAR((volume.spacing_mm() - Eigen::Vector3d(2, 1.5, 3)).norm(), 0.0, 1e-12);
    // RAS (10,20,-5) + 1*(0,2,0) + 2*(-1.5,0,0) + 3*(0,0,3) = (7,22,4), which is LPS (-7,-22,4).
    EXPECT_NEAR((volume.lpsFromIjk({1, 2, 3}) - Eigen::Vector3d(-7, -22, 4)).norm(), 0.0, 1e-12);
    EXPECT_EQ(volume.at(1, 2, 3), static_cast<float>(1 + 2 * 2 + 6 * 3));
  }
}

TEST(VolumeFileIO, ReadsBigEndianMetaImageWithAnatomicalOrientationOnly) {
  const auto dir = fct::test::scratchDir();
  std::string voxels;
  for (int n = 0; n < 8; ++n) {
    const auto v = static_cast<std::uint16_t>(-500 + 100 * n);
    voxels += static_cast<char>(v >> 8);
    voxels += static_cast<char>(v & 0xff);
  }
  writeFile(dir / "lps.mha",
            "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = True\n"
            "Offset = 1 2 3\nAnatomicalOrientation = LPS\nElementSpacing = 0.5 0.5 2\nDimSize = 2 2 2\n"
            "ElementType = MET_SHORT\nElementDataFile = LOCAL\n" + voxels);
  auto result = fct::VolumeFileIO::read(dir / "lps.mha");
  ASSERT_TRUE(result.ok()) << result.error();
  // "LPS" names where each axis comes from: i runs L->R (-x), j P->A (-y), k S->I (-z).
  EXPECT_NEAR((result.value().direction_lps() - Eigen::Matrix3d(Eigen::Vector3d(-1, -1, -1).asDiagonal())).norm(), 0.0,
              1e-12);
  EXPECT_EQ(result.value().at(1, 1, 1), 200.0f);
  EXPECT_EQ(result.value().at(0, 0, 0), -500.0f);
}

TEST(VolumeFileIO, RejectsMissingUnknownTruncatedAndMalformedFiles) {
  const auto dir = fct::test::scratchDir();
  EXPECT_NE(fct::VolumeFileIO::read(dir / "absent.nrrd").error().find("does not exist"), std::string::npos);
  writeFile(dir / "volume.vtk", "# vtk DataFile\n");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "volume.vtk").error().find("unknown volume extension"), std::string::npos);

  writeFile(dir / "short.nii", tinyNifti({4, 3, 2}, {1, 1, 1}, 1.0f, {0, 0, 0}, {0, 0, 0}, 10));
  EXPECT_NE(fct::VolumeFileIO::read(dir / "short.nii").error().find("truncated"), std::string::npos);
  writeFile(dir / "header_only.nii", tinyNifti({4, 3, 2}, {1, 1, 1}, 1.0f, {0, 0, 0}, {0, 0, 0}).substr(0, 200));
  EXPECT_NE(fct::VolumeFileIO::read(dir / "header_only.nii").error().find("truncated"), std::string::npos);
  std::string farOffset = tinyNifti({4, 3, 2}, {1, 1, 1}, 1.0f, {0, 0, 0}, {0, 0, 0});
  put<float>(farOffset, 108, 6.7e31f);  // vox_offset far past the end (found by fuzzing: an out-of-range cast)
  writeFile(dir / "far_offset.nii", farOffset);
  EXPECT_NE(fct::VolumeFileIO::read(dir / "far_offset.nii").error().find("beyond the file's"), std::string::npos);
  const std::string gz = gzipBytes(tinyNifti({40, 30, 20}, {1, 1, 1}, 1.0f, {0, 0, 0}, {0, 0, 0}));
  writeFile(dir / "cut.nii.gz", gz.substr(0, gz.size() / 2));
  EXPECT_FALSE(fct::VolumeFileIO::read(dir / "cut.nii.gz").ok());

  ASSERT_TRUE(fct::VolumeFileIO::write(obliqueVolume(), dir / "whole.nrrd").ok());
  std::filesystem::resize_file(dir / "whole.nrrd", std::filesystem::file_size(dir / "whole.nrrd") - 7);
  EXPECT_NE(fct::VolumeFileIO::read(dir / "whole.nrrd").error().find("truncated"), std::string::npos);

  writeFile(dir / "zero.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 0 5 5\nencoding: raw\n\n");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "zero.nrrd").error().find("must be positive"), std::string::npos);
  writeFile(dir / "huge.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 7.7e29 5 5\nencoding: raw\n\n");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "huge.nrrd").error().find("whole number of voxels"), std::string::npos);
  writeFile(dir / "fraction.mha", "ObjectType = Image\nNDims = 3\nElementSpacing = 1 1 1\nDimSize = 1.5 1 1\n"
                                  "ElementType = MET_FLOAT\nElementDataFile = LOCAL\nabcd");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "fraction.mha").error().find("DimSize"), std::string::npos);
  writeFile(dir / "nan.mha", "ObjectType = Image\nNDims = 3\nElementSpacing = nan 1 1\nDimSize = 1 1 1\n"
                             "ElementType = MET_FLOAT\nElementDataFile = LOCAL\nabcd");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "nan.mha").error().find("ElementSpacing"), std::string::npos);
  writeFile(dir / "zero_spacing.mha", "ObjectType = Image\nNDims = 3\nElementSpacing = 0 1 1\nDimSize = 1 1 1\n"
                                      "ElementType = MET_FLOAT\nElementDataFile = LOCAL\nabcd");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "zero_spacing.mha").error().find("spacing"), std::string::npos);
  writeFile(dir / "sheared.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nspace: LPS\nsizes: 1 1 1\n"
                                  "space directions: (1,0,0) (0.5,1,0) (0,0,1)\nencoding: raw\n\nx");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "sheared.nrrd").error().find("not perpendicular"), std::string::npos);
  writeFile(dir / "scanner.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nspace: scanner-xyz\nsizes: 1 1 1\n"
                                  "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\n\nx");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "scanner.nrrd").error().find("scanner-xyz"), std::string::npos);
  writeFile(dir / "unnamed_space.nrrd", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\n"
                                        "space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\n\nx");
  EXPECT_NE(fct::VolumeFileIO::read(dir / "unnamed_space.nrrd").error().find("no 'space'"), std::string::npos);
  writeFile(dir / "garbage.nii", std::string(400, 'x'));
  EXPECT_NE(fct::VolumeFileIO::read(dir / "garbage.nii").error().find("not a NIfTI-1"), std::string::npos);
}

TEST(VolumeFileIO, WriteFailureLeavesNothingBehind) {
  const auto dir = fct::test::scratchDir();
  const fct::Volume volume = obliqueVolume();
  const fct::Status missingFolder = fct::VolumeFileIO::write(volume, dir / "no_such_folder" / "v.nrrd");
  ASSERT_FALSE(missingFolder.ok());
  EXPECT_NE(missingFolder.error().find("does not exist"), std::string::npos) << missingFolder.error();
  EXPECT_NE(fct::VolumeFileIO::write(volume, dir / "v.nii").error().find("unknown extension"), std::string::npos);
  // A folder standing where the file should go: the rename fails and the temporary file is removed.
  std::filesystem::create_directory(dir / "taken.mha");
  std::filesystem::create_directory(dir / "taken.mha" / "child");
  EXPECT_FALSE(fct::VolumeFileIO::write(volume, dir / "taken.mha").ok());
  EXPECT_FALSE(fct::VolumeFileIO::write(fct::Volume(), dir / "empty.nrrd").ok());
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1) << "a partial or temporary file was left";
}
