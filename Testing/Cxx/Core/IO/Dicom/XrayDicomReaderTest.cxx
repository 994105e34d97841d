#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>

#include "IO/Dicom/XrayDicomReader.h"
#include "SyntheticXrayDicom.h"
#include "TestSupport.h"

namespace {

using fct::XrayDicomReader;

using fct::test::save;
using fct::test::SyntheticXray;

std::vector<Uint16> ramp(std::size_t n, Uint16 start, Uint16 step) {
  std::vector<Uint16> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<Uint16>(start + i * step);
  return v;
}

/// DCMTK's own decoding of frame 0 of an 8-bit file (whole-dataset decompression, a different path from the reader).
std::vector<Uint8> dcmtkRawFrame0(const std::filesystem::path& path, std::size_t pixelCount) {
  DcmFileFormat file;
  EXPECT_TRUE(file.loadFile(path.c_str()).good());
  EXPECT_TRUE(file.getDataset()->chooseRepresentation(EXS_LittleEndianExplicit, nullptr).good());
  const Uint8* data = nullptr;
  unsigned long count = 0;
  EXPECT_TRUE(file.getDataset()->findAndGetUint8Array(DCM_PixelData, data, &count).good());
  EXPECT_GE(count, pixelCount);
  return data ? std::vector<Uint8>(data, data + pixelCount) : std::vector<Uint8>{};
}

double stddev(const std::vector<float>& v) {
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  double sum = 0.0;
  for (float x : v) sum += (x - mean) * (x - mean);
  return std::sqrt(sum / static_cast<double>(v.size()));
}

const std::string kSid = "DistanceSourceToDetector (0018,1110)";
const std::string kSod = "DistanceSourceToPatient (0018,1111) or DistanceSourceToIsocenter (0018,9402)";
const std::string kSpacing = "ImagerPixelSpacing (0018,1164) or PixelSpacing (0028,0030)";

}  // namespace

// ---------------------------------------------------------------- real files

TEST(XrayDicomReader, ReadsRfShoulderWithoutAnyGeometry) {
  FCT_REQUIRE_DATA("xray/rf_shoulder_kwire.dcm");
  const auto path = fct::test::dataDir() / "xray/rf_shoulder_kwire.dcm";
  auto header = XrayDicomReader::readHeader(path);
  ASSERT_TRUE(header) << header.error();
  const auto& h = header.value();
  EXPECT_EQ(h.modality, "RF");
  EXPECT_EQ(h.photometric, "MONOCHROME2");
  EXPECT_EQ(h.cols, 512);
  EXPECT_EQ(h.rows, 464);
  EXPECT_EQ(h.frames, 1);
  EXPECT_EQ(h.bitsAllocated, 8);
  EXPECT_EQ(h.bitsStored, 8);
  EXPECT_FALSE(h.geometry.sourceToDetector_mm || h.geometry.sourceToPatient_mm || h.geometry.pixelSpacing_mm ||
               h.geometry.primaryAngle_deg || h.geometry.secondaryAngle_deg || h.geometry.detectorActiveOrigin_mm);
  EXPECT_EQ(h.missingGeometry, (std::vector<std::string>{kSid, kSod, kSpacing}));

  auto image = XrayDicomReader::read(path);
  ASSERT_TRUE(image) << image.error();
  EXPECT_FALSE(image.value().camera.has_value());
  EXPECT_TRUE(image.value().fovMask.empty());
  EXPECT_EQ(image.value().pixels.size(), 512u * 464u);
  ASSERT_FALSE(image.warnings().empty());
  EXPECT_NE(image.warnings().back().find("view file"), std::string::npos);
  // MONOCHROME2 with an identity Modality LUT: the pixels are DCMTK's raw values.
  const auto raw = dcmtkRawFrame0(path, 512u * 464u);
  for (std::size_t i = 0; i < raw.size(); i += 997) EXPECT_EQ(image.value().pixels[i], static_cast<float>(raw[i]));
}

TEST(XrayDicomReader, ReadsDxThoraxWithDetectorDistanceButNoPatientDistance) {
  FCT_REQUIRE_DATA("xray/dx_thorax_canine.dcm");
  const auto path = fct::test::dataDir() / "xray/dx_thorax_canine.dcm";
  auto header = XrayDicomReader::readHeader(path);
  ASSERT_TRUE(header) << header.error();
  const auto& h = header.value();
  EXPECT_EQ(h.modality, "DX");
  EXPECT_EQ(h.photometric, "MONOCHROME1");
  EXPECT_EQ(h.cols, 211);
  EXPECT_EQ(h.rows, 169);
  EXPECT_EQ(h.frames, 1);
  EXPECT_EQ(h.bitsStored, 8);
  ASSERT_TRUE(h.geometry.sourceToDetector_mm);
  EXPECT_DOUBLE_EQ(*h.geometry.sourceToDetector_mm, 1000.0);
  ASSERT_TRUE(h.geometry.pixelSpacing_mm);
  EXPECT_NEAR(h.geometry.pixelSpacing_mm->x(), 1.2012, 1e-6);  // du = column spacing = second DICOM value
  EXPECT_NEAR(h.geometry.pixelSpacing_mm->y(), 1.2, 1e-9);
  EXPECT_FALSE(h.geometry.sourceToPatient_mm);
  EXPECT_EQ(h.missingGeometry, (std::vector<std::string>{kSod}));

  auto image = XrayDicomReader::read(path);
  ASSERT_TRUE(image) << image.error();
  EXPECT_FALSE(image.value().camera.has_value());
  const auto raw = dcmtkRawFrame0(path, 211u * 169u);
  for (std::size_t i = 0; i < raw.size(); i += 101) EXPECT_EQ(image.value().pixels[i], 255.0f - raw[i]);
}

TEST(XrayDicomReader, DecodesJpegMultiFrameAngiogramFrameByFrame) {
  FCT_REQUIRE_DATA("xray/xa_coronary_multiframe_jpeg.dcm");
  const auto path = fct::test::dataDir() / "xray/xa_coronary_multiframe_jpeg.dcm";
  auto header = XrayDicomReader::readHeader(path);
  ASSERT_TRUE(header) << header.error();
  const auto& h = header.value();
  EXPECT_EQ(h.modality, "XA");
  EXPECT_EQ(h.photometric, "MONOCHROME2");
  EXPECT_EQ(h.cols, 512);
  EXPECT_EQ(h.rows, 512);
  EXPECT_EQ(h.frames, 96);
  EXPECT_EQ(h.bitsStored, 8);
  EXPECT_NE(h.transferSyntax.find("JPEG"), std::string::npos) << h.transferSyntax;
  ASSERT_TRUE(h.geometry.primaryAngle_deg && h.geometry.secondaryAngle_deg);
  EXPECT_DOUBLE_EQ(*h.geometry.primaryAngle_deg, -32.0);
  EXPECT_DOUBLE_EQ(*h.geometry.secondaryAngle_deg, 2.0);
  EXPECT_EQ(h.missingGeometry, (std::vector<std::string>{kSid, kSod, kSpacing}));

  auto frame0 = XrayDicomReader::read(path, 0);
  auto frame50 = XrayDicomReader::read(path, 50);
  ASSERT_TRUE(frame0) << frame0.error();
  ASSERT_TRUE(frame50) << frame50.error();
  EXPECT_EQ(frame50.value().frameIndex, 50);
  EXPECT_EQ(frame50.value().frameCount, 96);
  EXPECT_GT(stddev(frame0.value().pixels), 10.0);  // a real angiogram, not a constant
  double meanAbsDiff = 0.0;
  for (std::size_t i = 0; i < frame0.value().pixels.size(); ++i) {
    meanAbsDiff += std::abs(frame0.value().pixels[i] - frame50.value().pixels[i]);
  }
  EXPECT_GT(meanAbsDiff / static_cast<double>(frame0.value().pixels.size()), 1.0);

  auto beyond = XrayDicomReader::read(path, 96);
  ASSERT_FALSE(beyond);
  EXPECT_NE(beyond.error().find("96 frames"), std::string::npos) << beyond.error();
}

TEST(XrayDicomReader, InvertsJpegMonochrome1ChestToMonochrome2) {
  FCT_REQUIRE_DATA("xray/cr_chest_monochrome1_jpeg.dcm");
  const auto path = fct::test::dataDir() / "xray/cr_chest_monochrome1_jpeg.dcm";
  auto header = XrayDicomReader::readHeader(path);
  ASSERT_TRUE(header) << header.error();
  const auto& h = header.value();
  EXPECT_EQ(h.modality, "CR");
  EXPECT_EQ(h.photometric, "MONOCHROME1");
  EXPECT_EQ(h.cols, 2010);
  EXPECT_EQ(h.rows, 2446);
  EXPECT_EQ(h.frames, 1);
  EXPECT_EQ(h.bitsStored, 8);
  ASSERT_TRUE(h.geometry.pixelSpacing_mm);
  EXPECT_DOUBLE_EQ(h.geometry.pixelSpacing_mm->x(), 0.175);
  EXPECT_DOUBLE_EQ(h.geometry.pixelSpacing_mm->y(), 0.175);
  EXPECT_FALSE(h.geometry.sourceToPatient_mm);  // present in the file but empty
  EXPECT_EQ(h.missingGeometry, (std::vector<std::string>{kSid, kSod}));

  auto image = XrayDicomReader::read(path);
  ASSERT_TRUE(image) << image.error();
  const auto& pixels = image.value().pixels;
  EXPECT_GT(stddev(pixels), 10.0);
  const auto [lo, hi] = std::minmax_element(pixels.begin(), pixels.end());
  EXPECT_GE(*lo, 0.0f);
  EXPECT_LE(*hi, 255.0f);
  const auto raw = dcmtkRawFrame0(path, pixels.size());
  for (std::size_t i = 0; i < raw.size(); i += 4999) EXPECT_EQ(pixels[i], 255.0f - raw[i]) << "pixel " << i;
}

// ---------------------------------------------------------------- synthetic files

TEST(XrayDicomReader, InvertsTwelveBitMonochrome1WithinStoredBitsThenRescales) {
  SyntheticXray x;
  x.photometric = "MONOCHROME1";
  x.bitsStored = 12;
  x.samples = ramp(20, 0, 215);  // 0 .. 4085
  x.samples[19] = 4095;
  x.samples[3] |= 0xF000;  // garbage above the high bit must be masked off
  DcmFileFormat file = x.build();
  file.getDataset()->putAndInsertString(DCM_RescaleSlope, "2");
  file.getDataset()->putAndInsertString(DCM_RescaleIntercept, "-10");
  const auto path = save(file, fct::test::scratchDir() / "mono1_12bit.dcm");

  auto image = XrayDicomReader::read(path);
  ASSERT_TRUE(image) << image.error();
  EXPECT_EQ(image.value().bitsStored, 12);
  EXPECT_EQ(image.value().photometric, "MONOCHROME1");
  for (std::size_t i = 0; i < 20; ++i) {
    const int stored = x.samples[i] & 0x0FFF;
    EXPECT_FLOAT_EQ(image.value().pixels[i], 2.0f * static_cast<float>(4095 - stored) - 10.0f) << "pixel " << i;
  }
  EXPECT_FLOAT_EQ(image.value().at(0, 0), 2.0f * 4095 - 10);  // darkest MONOCHROME1 value = most signal
}

TEST(XrayDicomReader, AppliesModalityLutClampingOutsideItsRange) {
  SyntheticXray x;
  x.cols = 4;
  x.rows = 1;
  x.bitsAllocated = 8;
  x.bitsStored = 8;
  x.samples = {0, 1, 3, 200};
  DcmFileFormat file = x.build();
  DcmItem* lut = nullptr;
  ASSERT_TRUE(file.getDataset()->findOrCreateSequenceItem(DCM_ModalityLUTSequence, lut, 0).good());
  const Uint16 descriptor[3] = {3, 1, 16};  // 3 entries, first mapped stored value 1
  const Uint16 data[3] = {100, 200, 300};
  lut->putAndInsertUint16Array(DCM_LUTDescriptor, descriptor, 3);
  lut->putAndInsertUint16Array(DCM_LUTData, data, 3);
  const auto path = save(file, fct::test::scratchDir() / "modality_lut.dcm");
  auto image = XrayDicomReader::read(path);
  ASSERT_TRUE(image) << image.error();
  EXPECT_EQ(image.value().pixels, (std::vector<float>{100, 100, 300, 300}));
}

TEST(XrayDicomReader, ReadsRequestedFrameOfSixteenBitMultiFrame) {
  SyntheticXray x;
  x.frames = 3;
  x.samples = ramp(60, 0, 1);
  for (std::size_t i = 0; i < 60; ++i) x.samples[i] = static_cast<Uint16>(20000 * (i / 20) + i % 20);
  DcmFileFormat file = x.build();
  const auto path = save(file, fct::test::scratchDir() / "multiframe16.dcm");

  for (int frame = 0; frame < 3; ++frame) {
    auto image = XrayDicomReader::read(path, frame);
    ASSERT_TRUE(image) << image.error();
    EXPECT_EQ(image.value().frameCount, 3);
    EXPECT_FLOAT_EQ(image.value().at(0, 0), 20000.0f * frame);
    EXPECT_FLOAT_EQ(image.value().at(4, 3), 20000.0f * frame + 19);
  }
  auto beyond = XrayDicomReader::read(path, 3);
  ASSERT_FALSE(beyond);
  EXPECT_NE(beyond.error().find("3 frames"), std::string::npos) << beyond.error();
  EXPECT_FALSE(XrayDicomReader::read(path, -1));
}

TEST(XrayDicomReader, CameraFromCompleteTagsProjectsIsocentreToDetectorCentre) {
  SyntheticXray x;
  x.cols = 64;
  x.rows = 48;
  x.bitsAllocated = 8;
  x.bitsStored = 8;
  x.samples = std::vector<Uint16>(64 * 48, 7);
  DcmFileFormat file = x.build();
  DcmDataset* ds = file.getDataset();
  ds->putAndInsertString(DCM_DistanceSourceToDetector, "1200");
  ds->putAndInsertString(DCM_DistanceSourceToPatient, "800");
  ds->putAndInsertString(DCM_ImagerPixelSpacing, "0.3\\0.2");  // row spacing dv, column spacing du
  ds->putAndInsertString(DCM_PositionerPrimaryAngle, "30");
  ds->putAndInsertString(DCM_PositionerSecondaryAngle, "-15");
  const auto path = save(file, fct::test::scratchDir() / "xa_geometry.dcm");

  auto image = XrayDicomReader::read(path);
  ASSERT_TRUE(image) << image.error();
  ASSERT_TRUE(image.value().camera.has_value());
  const fct::Camera& camera = *image.value().camera;
  EXPECT_DOUBLE_EQ(camera.intrinsics().pixelSpacing_mm.x(), 0.2);
  EXPECT_DOUBLE_EQ(camera.intrinsics().pixelSpacing_mm.y(), 0.3);
  EXPECT_DOUBLE_EQ(camera.intrinsics().sourceToDetector_mm, 1200.0);
  bool inFront = false;
  const Eigen::Vector2d centre_px = camera.project(Eigen::Vector3d::Zero(), &inFront);
  EXPECT_TRUE(inFront);
  EXPECT_NEAR(centre_px.x(), 31.5, 1e-9);
  EXPECT_NEAR(centre_px.y(), 23.5, 1e-9);
  EXPECT_NEAR(camera.sourcePosition_world_mm().norm(), 800.0, 1e-9);
  // LAO 30, caudal 15: the detector sits toward the patient's left (+x), anterior (-y) and feet (-z).
  const double a = 30.0 * M_PI / 180.0, b = -15.0 * M_PI / 180.0;
  const Eigen::Vector3d detectorDirection(std::sin(a) * std::cos(b), -std::cos(a) * std::cos(b), std::sin(b));
  EXPECT_TRUE(camera.sourcePosition_world_mm().isApprox(-800.0 * detectorDirection, 1e-9));
  EXPECT_TRUE(camera.detectorPoint_world_mm(centre_px).isApprox(400.0 * detectorDirection, 1e-9));
}

TEST(XrayDicomReader, CameraAtZeroAnglesLooksAnteriorWithPatientRightAlongColumns) {
  fct::XrayGeometryTags tags;
  tags.sourceToDetector_mm = 1000.0;
  tags.sourceToPatient_mm = 700.0;
  tags.pixelSpacing_mm = Eigen::Vector2d(0.5, 0.5);
  auto camera = fct::XrayGeometryReader::cameraFromTags(tags, 100, 80);
  ASSERT_TRUE(camera) << camera.error();
  EXPECT_TRUE(camera.value().sourcePosition_world_mm().isApprox(Eigen::Vector3d(0, 700, 0), 1e-12));
  const Eigen::Vector2d centre_px = camera.value().project(Eigen::Vector3d::Zero());
  const Eigen::Vector2d right_px = camera.value().project(Eigen::Vector3d(-10, 0, 0));  // LPS: -x = patient right
  const Eigen::Vector2d head_px = camera.value().project(Eigen::Vector3d(0, 0, 10));    // +z = superior
  EXPECT_GT(right_px.x(), centre_px.x());
  EXPECT_NEAR(right_px.y(), centre_px.y(), 1e-9);
  EXPECT_LT(head_px.y(), centre_px.y());
  EXPECT_NEAR((right_px - centre_px).x(), 10.0 * 1000.0 / 700.0 / 0.5, 1e-9);  // magnification SID/SOD
  ASSERT_EQ(camera.warnings().size(), 2u);  // both angles assumed 0
  EXPECT_NE(camera.warnings()[0].find("assumed 0"), std::string::npos);
}

TEST(XrayDicomReader, WarnsWhenPatientOrientationContradictsTheCamera) {
  SyntheticXray x;
  x.samples = ramp(20, 0, 1);
  const auto dir = fct::test::scratchDir();
  auto readWithOrientation = [&](const char* orientation, const char* fileName) {
    DcmFileFormat file = x.build();
    DcmDataset* ds = file.getDataset();
    ds->putAndInsertString(DCM_DistanceSourceToDetector, "1000");
    ds->putAndInsertString(DCM_DistanceSourceToPatient, "750");
    ds->putAndInsertString(DCM_ImagerPixelSpacing, "0.2\\0.2");
    ds->putAndInsertString(DCM_PositionerPrimaryAngle, "0");
    ds->putAndInsertString(DCM_PositionerSecondaryAngle, "0");
    ds->putAndInsertString(DCM_PatientOrientation, orientation);
    return XrayDicomReader::read(save(file, dir / fileName));
  };
  auto hasMirrorWarning = [](const fct::Result<fct::XrayImage>& image) {
    return std::any_of(image.warnings().begin(), image.warnings().end(),
                       [](const std::string& w) { return w.find("mirrored") != std::string::npos; });
  };
  auto seenFromSource = readWithOrientation("R\\F", "from_source.dcm");
  ASSERT_TRUE(seenFromSource) << seenFromSource.error();
  EXPECT_TRUE(seenFromSource.value().camera.has_value());
  EXPECT_FALSE(hasMirrorWarning(seenFromSource));
  EXPECT_TRUE(seenFromSource.warnings().empty());  // complete geometry, explicit angles: nothing to say

  auto asDisplayed = readWithOrientation("L\\F", "as_displayed.dcm");
  ASSERT_TRUE(asDisplayed) << asDisplayed.error();
  EXPECT_FALSE(asDisplayed.value().camera.has_value()) << "a camera for the unmirrored view does not fit the pixels";
  EXPECT_TRUE(hasMirrorWarning(asDisplayed));
}

TEST(XrayDicomReader, CameraErrorNamesEveryMissingValue) {
  fct::XrayGeometryTags tags;
  tags.sourceToDetector_mm = 1000.0;
  tags.pixelSpacing_mm = Eigen::Vector2d(1.2, 1.2);
  auto camera = fct::XrayGeometryReader::cameraFromTags(tags, 211, 169);
  ASSERT_FALSE(camera);
  EXPECT_NE(camera.error().find("missing DistanceSourceToPatient (0018,1111)"), std::string::npos) << camera.error();
  EXPECT_NE(camera.error().find("source_to_patient_mm"), std::string::npos);
  EXPECT_EQ(camera.error().find("DistanceSourceToDetector"), std::string::npos);

  tags.sourceToPatient_mm = 1500.0;  // beyond the detector
  auto inverted = fct::XrayGeometryReader::cameraFromTags(tags, 211, 169);
  ASSERT_FALSE(inverted);
  EXPECT_NE(inverted.error().find("smaller than"), std::string::npos) << inverted.error();
}

// ---------------------------------------------------------------- bad inputs

TEST(XrayDicomReader, RejectsTruncatedFile) {
  SyntheticXray x;
  x.cols = 64;
  x.rows = 64;
  x.samples = ramp(64 * 64, 0, 3);
  DcmFileFormat file = x.build();
  const auto dir = fct::test::scratchDir();
  const auto full = save(file, dir / "full.dcm");
  const auto truncated = dir / "truncated.dcm";
  std::filesystem::copy_file(full, truncated);
  std::filesystem::resize_file(truncated, std::filesystem::file_size(full) / 2);
  auto image = XrayDicomReader::read(truncated);
  ASSERT_FALSE(image);
  EXPECT_NE(image.error().find("truncated"), std::string::npos) << image.error();
}

TEST(XrayDicomReader, RejectsFileWithoutPixelData) {
  SyntheticXray x;
  x.samples = ramp(20, 0, 1);
  DcmFileFormat file = x.build();
  delete file.getDataset()->remove(DCM_PixelData);
  const auto path = save(file, fct::test::scratchDir() / "nopixels.dcm");
  EXPECT_TRUE(XrayDicomReader::readHeader(path));  // the header alone is fine
  auto image = XrayDicomReader::read(path);
  ASSERT_FALSE(image);
  EXPECT_NE(image.error().find("no pixel data"), std::string::npos) << image.error();
}

TEST(XrayDicomReader, RejectsCtSliceNamingItsModality) {
  SyntheticXray x;
  x.modality = "CT";
  x.samples = ramp(20, 0, 1);
  DcmFileFormat file = x.build();
  const auto path = save(file, fct::test::scratchDir() / "ct.dcm");
  auto image = XrayDicomReader::read(path);
  ASSERT_FALSE(image);
  EXPECT_NE(image.error().find("modality CT"), std::string::npos) << image.error();
}

TEST(XrayDicomReader, RejectsZeroRows) {
  SyntheticXray x;
  x.rows = 0;
  x.samples = {0, 0};
  DcmFileFormat file = x.build();
  const auto path = save(file, fct::test::scratchDir() / "zerorows.dcm");
  auto header = XrayDicomReader::readHeader(path);
  ASSERT_FALSE(header);
  EXPECT_NE(header.error().find("5 x 0"), std::string::npos) << header.error();
}

TEST(XrayDicomReader, RejectsColourAndUnsupportedBitDepth) {
  SyntheticXray colour;
  colour.photometric = "RGB";
  colour.samples = ramp(20, 0, 1);
  DcmFileFormat file = colour.build();
  const auto dir = fct::test::scratchDir();
  auto rgb = XrayDicomReader::readHeader(save(file, dir / "rgb.dcm"));
  ASSERT_FALSE(rgb);
  EXPECT_NE(rgb.error().find("grey-scale"), std::string::npos) << rgb.error();

  SyntheticXray wide;
  wide.samples = ramp(20, 0, 1);
  DcmFileFormat wideFile = wide.build();
  wideFile.getDataset()->putAndInsertUint16(DCM_BitsAllocated, 32);
  auto bits = XrayDicomReader::readHeader(save(wideFile, dir / "bits32.dcm"));
  ASSERT_FALSE(bits);
  EXPECT_NE(bits.error().find("32 bits allocated"), std::string::npos) << bits.error();
}

TEST(XrayDicomReader, RejectsNonDicomAndMissingFiles) {
  const auto dir = fct::test::scratchDir();
  const auto text = dir / "notes.dcm";
  std::ofstream(text) << "this is not a DICOM file, just some text that happens to end in .dcm\n";
  auto notDicom = XrayDicomReader::read(text);
  ASSERT_FALSE(notDicom);
  EXPECT_NE(notDicom.error().find("notes.dcm"), std::string::npos) << notDicom.error();

  auto missing = XrayDicomReader::read(dir / "absent.dcm");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find("does not exist"), std::string::npos) << missing.error();
}
