#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcrleerg.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "IO/Dicom/DicomSeriesReader.h"
#include "SyntheticCtDicom.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

using fct::test::SyntheticSlice;

void writeSlice(const fs::path& path, const SyntheticSlice& s) {
  DcmFileFormat file = s.build();
  if (s.transferSyntax != EXS_LittleEndianExplicit) {
    DcmRLEEncoderRegistration::registerCodecs();
    ASSERT_TRUE(file.getDataset()->chooseRepresentation(s.transferSyntax, nullptr).good());
  }
  ASSERT_TRUE(file.saveFile(path.c_str(), s.transferSyntax).good()) << path;
}

/// Writes one slice per z position into folder/name<index> (no extension).
void writeSeries(const fs::path& folder, SyntheticSlice slice, const std::vector<double>& zs, const std::string& name) {
  fs::create_directories(folder);
  for (std::size_t m = 0; m < zs.size(); ++m) {
    slice.ipp_lps_mm.z() = zs[m];
    writeSlice(folder / fmt::format("{}{}", name, m), slice);
  }
}

/// Passes when text contains part; the failure message shows both.
::testing::AssertionResult contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

void writeText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

/// The Philips head phantom, read once for all tests that need it.
const fct::Result<fct::Volume>& philipsBonePhantom() {
  static const fct::Result<fct::Volume> volume =
      fct::DicomSeriesReader::read(fct::test::dataDir() / "ct/head_phantom_philips_bone");
  return volume;
}

}  // namespace

// ---- synthetic series: no shared data needed ----

TEST(DicomSeriesReader, ReadsSyntheticSeriesGeometryAndHu) {
  const fs::path dir = fct::test::scratchDir();
  SyntheticSlice slice;
  slice.iop = {0, 1, 0, 0, 0, -1};  // sagittal: i along +P, j toward the feet, normal along −L
  slice.ipp_lps_mm = Vector3d(0, -20, 40);
  slice.slope = 2.0;
  slice.intercept = -1000.0;
  slice.stored = [](int i, int j) { return -3 + i + 7 * j; };  // negative stored values: signed pixels
  // Files named out of order, in a subfolder, beside a non-DICOM file; normal = row × col = (−1, 0, 0).
  const Vector3d normal = Vector3d(0, 1, 0).cross(Vector3d(0, 0, -1));
  fs::create_directories(dir / "sub");
  for (int m : {2, 0, 1}) {
    slice.ipp_lps_mm.x() = normal.x() * 1.25 * m;
    writeSlice(dir / "sub" / fmt::format("IM{}", 7 - m), slice);
  }
  writeText(dir / "notes.txt", "not a DICOM file");

  const auto volume = fct::DicomSeriesReader::read(dir);
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_TRUE(volume.warnings().empty());
  const fct::Volume& v = volume.value();
  EXPECT_EQ(v.dims(), Eigen::Vector3i(5, 4, 3));
  EXPECT_TRUE(v.spacing_mm().isApprox(Vector3d(0.8, 0.5, 1.25), 1e-9)) << v.spacing_mm().transpose();
  EXPECT_TRUE(v.origin_lps_mm().isApprox(Vector3d(0, -20, 40))) << v.origin_lps_mm().transpose();
  Eigen::Matrix3d direction;
  direction << Vector3d(0, 1, 0), Vector3d(0, 0, -1), normal;
  EXPECT_TRUE(v.direction_lps().isApprox(direction)) << v.direction_lps();
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(v.at(0, 0, k), 2.0f * -3 - 1000.0f);
    EXPECT_FLOAT_EQ(v.at(4, 3, k), 2.0f * (-3 + 4 + 21) - 1000.0f);
  }
  EXPECT_TRUE(contains(v.description, slice.seriesUid));
  ASSERT_TRUE(v.dicom.has_value());  // kept for objects that refer back to the series (a DICOM registration)
  EXPECT_EQ(v.dicom->seriesInstanceUid, slice.seriesUid);
  EXPECT_EQ(v.dicom->modality, "CT");
  ASSERT_EQ(v.dicom->instances.size(), 3u);
  EXPECT_EQ(v.dicom->instances[0].sopClassUid, UID_CTImageStorage);
}

TEST(DicomSeriesReader, ReadsUnsignedAndRleCompressedPixels) {
  const fs::path dir = fct::test::scratchDir();
  SyntheticSlice slice;
  slice.pixelRepresentation = 0;
  slice.intercept = -32768.0;
  slice.stored = [](int i, int j) { return 40000 + 100 * i + j; };  // above 32767: must not wrap to negative
  slice.transferSyntax = EXS_RLELossless;
  writeSeries(dir, slice, {0.0, 2.0}, "rle");
  const auto volume = fct::DicomSeriesReader::read(dir);
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_FLOAT_EQ(volume.value().at(0, 0, 1), 40000.0f - 32768.0f);
  EXPECT_FLOAT_EQ(volume.value().at(3, 2, 0), 40302.0f - 32768.0f);
}

TEST(DicomSeriesReader, ResamplesIrregularSyntheticSeriesWithWarning) {
  const fs::path dir = fct::test::scratchDir();
  SyntheticSlice slice;
  // Stored value encodes the slice position: HU = 10 × z + i, linear in z, so interpolation is exact.
  fs::create_directories(dir);
  const std::vector<double> zs = {0.0, 1.0, 3.0, 7.0};
  for (std::size_t m = 0; m < zs.size(); ++m) {
    slice.ipp_lps_mm.z() = zs[m];
    slice.stored = [z = zs[m]](int i, int) { return static_cast<int>(10 * z) + i; };
    writeSlice(dir / fmt::format("s{}.dcm", m), slice);
  }

  const auto volume = fct::DicomSeriesReader::read(dir);
  ASSERT_TRUE(volume.ok()) << volume.error();
  ASSERT_EQ(volume.warnings().size(), 1u);
  EXPECT_TRUE(contains(volume.warnings()[0], "non-uniform slice spacing 1.00–4.00 mm"));
  EXPECT_TRUE(contains(volume.warnings()[0], "1.00 mm slice spacing (automatic"));
  const fct::Volume& v = volume.value();
  ASSERT_EQ(v.dims(), Eigen::Vector3i(5, 4, 8));
  EXPECT_DOUBLE_EQ(v.spacing_mm().z(), 1.0);
  for (int k = 0; k < 8; ++k) {
    EXPECT_NEAR(v.lpsFromIjk(Vector3d(0, 0, k)).z(), k, 1e-9);
    EXPECT_NEAR(v.at(2, 1, k), 10.0f * k + 2.0f, 1e-3) << k;
  }
  EXPECT_TRUE(contains(v.description, "resampled"));

  fct::DicomSeriesReadOptions coarse;
  coarse.resampleSpacing_mm = 3.5;
  const auto coarser = fct::DicomSeriesReader::read(dir, coarse);
  ASSERT_TRUE(coarser.ok()) << coarser.error();
  EXPECT_EQ(coarser.value().dims().z(), 3);
  EXPECT_NEAR(coarser.value().at(0, 0, 1), 35.0f, 1e-3);

  fct::DicomSeriesReadOptions refuse;
  refuse.policy = fct::IrregularSeriesPolicy::Refuse;
  const auto refused = fct::DicomSeriesReader::read(dir, refuse);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(contains(refused.error(), "1.00–4.00 mm"));
  EXPECT_TRUE(contains(refused.error(), "read it with resampling")) << refused.error();
  EXPECT_FALSE(contains(refused.error(), "--")) << "no command-line flag in Core: " << refused.error();
}

TEST(DicomSeriesReader, PicksLargestOfTwoMixedSeriesAndScanListsBoth) {
  const fs::path dir = fct::test::scratchDir();
  SyntheticSlice a, b;
  a.seriesUid = "1.2.3.100";
  b.seriesUid = "1.2.3.200";
  b.cols = 3;
  writeSeries(dir, a, {0, 1, 2}, "a");
  writeSeries(dir, b, {5, 7}, "b");

  const auto series = fct::DicomSeriesReader::scan(dir);
  ASSERT_TRUE(series.ok()) << series.error();
  ASSERT_EQ(series.value().size(), 2u);
  EXPECT_EQ(series.value()[0].seriesInstanceUid, "1.2.3.100");
  EXPECT_EQ(series.value()[0].fileCount, 3);
  EXPECT_EQ(series.value()[1].seriesInstanceUid, "1.2.3.200");
  EXPECT_EQ(series.value()[1].fileCount, 2);
  EXPECT_EQ(series.value()[1].cols, 3);
  EXPECT_EQ(series.value()[1].modality, "CT");

  const auto largest = fct::DicomSeriesReader::read(dir);
  ASSERT_TRUE(largest.ok()) << largest.error();
  EXPECT_EQ(largest.value().dims().z(), 3);
  ASSERT_EQ(largest.warnings().size(), 1u);
  EXPECT_TRUE(contains(largest.warnings()[0], "1.2.3.200"));

  fct::DicomSeriesReadOptions pickB;
  pickB.seriesInstanceUid = "1.2.3.200";
  const auto second = fct::DicomSeriesReader::read(dir, pickB);
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_EQ(second.value().dims(), Eigen::Vector3i(3, 4, 2));
  EXPECT_TRUE(second.warnings().empty());

  pickB.seriesInstanceUid = "9.9.9";
  const auto missing = fct::DicomSeriesReader::read(dir, pickB);
  ASSERT_FALSE(missing.ok());
  EXPECT_TRUE(contains(missing.error(), "9.9.9"));
  EXPECT_TRUE(contains(missing.error(), "1.2.3.100"));
  EXPECT_TRUE(contains(missing.error(), "1.2.3.200"));
}

// ---- bad input ----

TEST(DicomSeriesReader, RejectsEmptyMissingAndNonDicomFolders) {
  const fs::path dir = fct::test::scratchDir();
  const auto empty = fct::DicomSeriesReader::read(dir);
  ASSERT_FALSE(empty.ok());
  EXPECT_TRUE(contains(empty.error(), "no DICOM files found"));
  EXPECT_TRUE(contains(empty.error(), "(0 files looked at)"));

  writeText(dir / "a.txt", "hello");
  writeText(dir / "b", std::string(300, 'x'));
  const auto nonDicom = fct::DicomSeriesReader::scan(dir);
  ASSERT_FALSE(nonDicom.ok());
  EXPECT_TRUE(contains(nonDicom.error(), "(2 files looked at)"));

  const auto missing = fct::DicomSeriesReader::read(dir / "nowhere");
  ASSERT_FALSE(missing.ok());
  EXPECT_TRUE(contains(missing.error(), "nowhere"));

  fct::DicomSeriesReadOptions negative;
  negative.resampleSpacing_mm = -1.0;
  EXPECT_FALSE(fct::DicomSeriesReader::read(dir, negative).ok());
}

TEST(DicomSeriesReader, RejectsTruncatedFileNamingIt) {
  const fs::path dir = fct::test::scratchDir();
  SyntheticSlice slice;
  slice.cols = slice.rows = 64;
  writeSeries(dir, slice, {0, 1, 2}, "t");
  fs::resize_file(dir / "t1", fs::file_size(dir / "t1") - 1000);
  const auto volume = fct::DicomSeriesReader::read(dir);
  ASSERT_FALSE(volume.ok());
  EXPECT_TRUE(contains(volume.error(), "t1"));
  EXPECT_TRUE(contains(volume.error(), "truncated"));
}

TEST(DicomSeriesReader, RejectsNonImageDicomAndSliceWithoutPixelData) {
  const fs::path dir = fct::test::scratchDir();
  // A DICOM object with no image at all (e.g. a report): skipped, and the folder then has no image.
  DcmFileFormat report;
  report.getDataset()->putAndInsertString(DCM_SOPClassUID, UID_BasicTextSRStorage);
  report.getDataset()->putAndInsertString(DCM_Modality, "SR");
  ASSERT_TRUE(report.saveFile((dir / "report").c_str(), EXS_LittleEndianExplicit).good());
  const auto noImage = fct::DicomSeriesReader::read(dir);
  ASSERT_FALSE(noImage.ok());
  EXPECT_TRUE(contains(noImage.error(), "no DICOM images"));

  SyntheticSlice slice;
  writeSeries(dir, slice, {0, 1}, "ok");
  slice.withPixelData = false;
  slice.ipp_lps_mm.z() = 2.0;
  writeSlice(dir / "nopixels", slice);
  const auto volume = fct::DicomSeriesReader::read(dir);
  ASSERT_FALSE(volume.ok());
  EXPECT_TRUE(contains(volume.error(), "nopixels"));
  EXPECT_TRUE(contains(volume.error(), "PixelData (7fe0,0010)"));
}

TEST(DicomSeriesReader, RejectsMissingPixelSpacingNamingFileAndTag) {
  const fs::path dir = fct::test::scratchDir();
  SyntheticSlice slice;
  writeSeries(dir, slice, {0, 1}, "ok");
  slice.withPixelSpacing = false;
  slice.ipp_lps_mm.z() = 2.0;
  writeSlice(dir / "nospacing", slice);
  const auto volume = fct::DicomSeriesReader::read(dir);
  ASSERT_FALSE(volume.ok());
  EXPECT_TRUE(contains(volume.error(), "nospacing"));
  EXPECT_TRUE(contains(volume.error(), "PixelSpacing (0028,0030)"));
}

TEST(DicomSeriesReader, RejectsMixedSizesOrientationsAndDuplicatePositions) {
  const fs::path dir = fct::test::scratchDir();
  SyntheticSlice slice;
  writeSeries(dir / "mixed", slice, {0, 1}, "a");
  slice.rows = 6;
  slice.ipp_lps_mm.z() = 2.0;
  writeSlice(dir / "mixed" / "big", slice);
  const auto mixed = fct::DicomSeriesReader::read(dir / "mixed");
  ASSERT_FALSE(mixed.ok());
  EXPECT_TRUE(contains(mixed.error(), "mixes image sizes"));
  EXPECT_TRUE(contains(mixed.error(), "5x6"));

  SyntheticSlice localizer;
  writeSeries(dir / "oriented", localizer, {0, 1}, "a");
  localizer.iop = {1, 0, 0, 0, 0, -1};
  writeSlice(dir / "oriented" / "localizer", localizer);
  const auto oriented = fct::DicomSeriesReader::read(dir / "oriented");
  ASSERT_FALSE(oriented.ok());
  EXPECT_TRUE(contains(oriented.error(), "mixes slice orientations"));
  EXPECT_TRUE(contains(oriented.error(), "localizer"));

  writeSeries(dir / "duplicate", SyntheticSlice{}, {0, 1, 1}, "d");
  const auto duplicate = fct::DicomSeriesReader::read(dir / "duplicate");
  ASSERT_FALSE(duplicate.ok());
  EXPECT_TRUE(contains(duplicate.error(), "same position"));
}

// ---- real data ----

TEST(DicomSeriesReader, LoadsPhilipsHeadPhantomGeometry) {
  FCT_REQUIRE_DATA("ct/head_phantom_philips_bone");
  const auto& volume = philipsBonePhantom();
  ASSERT_TRUE(volume.ok()) << volume.error();
  EXPECT_TRUE(volume.warnings().empty());
  const fct::Volume& v = volume.value();
  EXPECT_EQ(v.dims(), Eigen::Vector3i(512, 512, 140));
  EXPECT_NEAR(v.spacing_mm().x(), 0.451, 1e-3);
  EXPECT_NEAR(v.spacing_mm().y(), 0.451, 1e-3);
  EXPECT_NEAR(v.spacing_mm().z(), 1.0, 1e-3);
  // First slice (lowest along the normal +z) has IPP −115.5\−1.85\694.21.
  EXPECT_TRUE(v.origin_lps_mm().isApprox(Vector3d(-115.5, -1.85, 694.21), 1e-9)) << v.origin_lps_mm().transpose();
  EXPECT_TRUE(v.direction_lps().isIdentity(1e-9));
  const auto [lo, hi] = v.valueRange();
  EXPECT_LE(lo, -1000.0f);
  EXPECT_GT(hi, 1000.0f);
  EXPECT_NEAR(v.at(5, 5, 70), -1000.0f, 100.0f);  // air in the corner
  ASSERT_TRUE(v.dicom.has_value());
  EXPECT_EQ(v.dicom->instances.size(), 140u);
  EXPECT_FALSE(v.dicom->studyInstanceUid.empty());
  EXPECT_FALSE(v.dicom->frameOfReferenceUid.empty());
}

TEST(DicomSeriesReader, ScanListsPhilipsHeadPhantomSeries) {
  FCT_REQUIRE_DATA("ct/head_phantom_philips_bone");
  const auto series = fct::DicomSeriesReader::scan(fct::test::dataDir() / "ct/head_phantom_philips_bone");
  ASSERT_TRUE(series.ok()) << series.error();
  ASSERT_EQ(series.value().size(), 1u);
  EXPECT_EQ(series.value()[0].fileCount, 140);
  EXPECT_EQ(series.value()[0].modality, "CT");
  EXPECT_EQ(series.value()[0].rows, 512);
}

TEST(DicomSeriesReader, ResamplesTiltedPhantomWithWarningOrRefuses) {
  FCT_REQUIRE_DATA("ct/head_phantom_philips_tilted");
  const fs::path dir = fct::test::dataDir() / "ct/head_phantom_philips_tilted";
  const auto volume = fct::DicomSeriesReader::read(dir);
  ASSERT_TRUE(volume.ok()) << volume.error();
  ASSERT_EQ(volume.warnings().size(), 1u);
  EXPECT_TRUE(contains(volume.warnings()[0], "gantry tilt 16.5°"));
  const fct::Volume& v = volume.value();
  const Eigen::Matrix3d& d = v.direction_lps();
  EXPECT_TRUE((d.transpose() * d).isIdentity(1e-9));
  EXPECT_NEAR(d.determinant(), 1.0, 1e-9);
  // 58 slices 2.5 mm apart in z; along the tilted normal (cos 16.5°) they span 57 × 2.397 mm.
  const double span_mm = (v.dims().z() - 1) * v.spacing_mm().z();
  EXPECT_NEAR(span_mm, 57 * 2.5 * std::cos(16.5 * std::numbers::pi / 180.0), 2.5);
  EXPECT_EQ(v.dims().x(), 512);
  EXPECT_GE(v.dims().y(), 512);
  EXPECT_LE(v.dims().y(), 512 + 110);  // sheared slices widen the grid by about 57 × 0.71 mm / 0.406 mm
  // Interpolation stays within the stored range of this soft-tissue series: −1024 … 804 HU.
  const auto [lo, hi] = v.valueRange();
  EXPECT_GE(lo, -1024.0f);
  EXPECT_LE(hi, 804.0f);
  EXPECT_GT(hi, 700.0f);
  EXPECT_TRUE(contains(v.description, "16.5°"));

  fct::DicomSeriesReadOptions refuse;
  refuse.policy = fct::IrregularSeriesPolicy::Refuse;
  const auto refused = fct::DicomSeriesReader::read(dir, refuse);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(contains(refused.error(), "gantry tilt 16.5°"));
}

TEST(DicomSeriesReader, ResamplesIrregularGeHeadWithWarningOrRefuses) {
  FCT_REQUIRE_DATA("ct/head_ge_irregular");
  const fs::path dir = fct::test::dataDir() / "ct/head_ge_irregular";
  fct::DicomSeriesReadOptions refuse;
  refuse.policy = fct::IrregularSeriesPolicy::Refuse;
  const auto refused = fct::DicomSeriesReader::read(dir, refuse);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(contains(refused.error(), "gantry tilt 18.5°"));
  EXPECT_TRUE(contains(refused.error(), "non-uniform slice spacing 1.08–7.00 mm"));

  fct::DicomSeriesReadOptions resample;
  resample.resampleSpacing_mm = 2.0;
  const auto volume = fct::DicomSeriesReader::read(dir, resample);
  ASSERT_TRUE(volume.ok()) << volume.error();
  ASSERT_EQ(volume.warnings().size(), 1u);
  EXPECT_TRUE(contains(volume.warnings()[0], "1.08–7.00 mm"));
  EXPECT_TRUE(contains(volume.warnings()[0], "2.00 mm slice spacing (as requested)"));
  const fct::Volume& v = volume.value();
  EXPECT_NEAR(v.spacing_mm().z(), 2.0, 1e-12);
  // Positions along the normal span 151.94 mm × cos 18.5° = 144.1 mm.
  EXPECT_NEAR((v.dims().z() - 1) * 2.0, 144.1, 2.0);
  EXPECT_TRUE((v.direction_lps().transpose() * v.direction_lps()).isIdentity(1e-9));
}
