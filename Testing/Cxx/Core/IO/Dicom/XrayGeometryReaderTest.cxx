// XrayGeometryReader: per-frame C-arm geometry (classic tags, Enhanced XA functional groups, rotational runs),
// PatientOrientation and the camera they give, on DICOM files synthesized with DCMTK.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "IO/Dicom/XrayDicomReader.h"
#include "IO/Dicom/XrayGeometryReader.h"
#include "SyntheticXrayDicom.h"
#include "TestSupport.h"

namespace {

using fct::XrayDicomReader;
using fct::XrayGeometryReader;
using fct::test::SyntheticXray;

constexpr double kDeg = M_PI / 180.0;

/// The unit direction from the isocentre to the detector at C-arm angles (LAO, cranial positive), as
/// docs/file-formats.md states it: (sin p cos s, -cos p cos s, sin s).
Eigen::Vector3d detectorDirection(double primary_deg, double secondary_deg) {
  const double p = primary_deg * kDeg, s = secondary_deg * kDeg;
  return {std::sin(p) * std::cos(s), -std::cos(p) * std::cos(s), std::sin(s)};
}

/// An Enhanced-XA-like multi-frame file: each frame's angles and distances in its Per-Frame Functional Groups item
/// (Positioner Position and X-Ray Geometry macros), the pixel spacing in the Shared Functional Groups.
std::filesystem::path enhancedXa(const std::vector<std::array<double, 4>>& perFrame, const std::string& name) {
  SyntheticXray x;
  x.cols = 40;
  x.rows = 30;
  x.frames = static_cast<int>(perFrame.size());
  DcmFileFormat file = x.build();
  DcmDataset* ds = file.getDataset();
  ds->putAndInsertString(DCM_SOPClassUID, UID_EnhancedXAImageStorage);
  DcmItem* shared = nullptr;
  ds->findOrCreateSequenceItem(DCM_SharedFunctionalGroupsSequence, shared, 0);
  DcmItem* detector = nullptr;
  shared->findOrCreateSequenceItem(DCM_XRayGeometrySequence, detector, 0);  // any macro sequence may hold it
  detector->putAndInsertString(DCM_ImagerPixelSpacing, "0.4\\0.3");        // dv, du
  for (std::size_t f = 0; f < perFrame.size(); ++f) {
    const auto& [primary, secondary, sid, sod] = perFrame[f];
    DcmItem* frame = nullptr;
    ds->findOrCreateSequenceItem(DCM_PerFrameFunctionalGroupsSequence, frame, static_cast<long>(f));
    DcmItem* positioner = nullptr;
    frame->findOrCreateSequenceItem(DCM_PositionerPositionSequence, positioner, 0);
    positioner->putAndInsertString(DCM_PositionerPrimaryAngle, std::to_string(primary).c_str());
    positioner->putAndInsertString(DCM_PositionerSecondaryAngle, std::to_string(secondary).c_str());
    DcmItem* geometry = nullptr;
    frame->findOrCreateSequenceItem(DCM_XRayGeometrySequence, geometry, 0);
    geometry->putAndInsertString(DCM_DistanceSourceToDetector, std::to_string(sid).c_str());
    geometry->putAndInsertString(DCM_DistanceSourceToIsocenter, std::to_string(sod).c_str());
  }
  return fct::test::save(file, fct::test::scratchDir() / name);
}

/// A classic XA rotational run: top-level angles of the first frame plus PositionerPrimary/SecondaryAngleIncrement.
DcmFileFormat rotationalRun(int frames, const std::string& primaryIncrement, const std::string& secondaryIncrement) {
  SyntheticXray x;
  x.cols = 32;
  x.rows = 32;
  x.frames = frames;
  DcmFileFormat file = x.build();
  DcmDataset* ds = file.getDataset();
  fct::test::putCarmTags(*ds, 1200, 800, 0.5, 0.5, -60, 5);
  ds->putAndInsertString(DCM_PositionerPrimaryAngleIncrement, primaryIncrement.c_str());
  ds->putAndInsertString(DCM_PositionerSecondaryAngleIncrement, secondaryIncrement.c_str());
  return file;
}

fct::XrayGeometryTags completeTags() {
  fct::XrayGeometryTags tags;
  tags.sourceToDetector_mm = 1000.0;
  tags.sourceToPatient_mm = 750.0;
  tags.pixelSpacing_mm = Eigen::Vector2d(0.5, 0.5);
  tags.primaryAngle_deg = 0.0;
  tags.secondaryAngle_deg = 0.0;
  return tags;
}

}  // namespace

TEST(XrayGeometryReader, GivesEachEnhancedXaFrameItsOwnAnglesAndDistances) {
  const auto path = enhancedXa({{0, 0, 1000, 700}, {30, -10, 1100, 750}, {-45, 20, 1200, 800}}, "enhanced_xa.dcm");
  const std::array<std::array<double, 4>, 3> expected{{{0, 0, 1000, 700}, {30, -10, 1100, 750}, {-45, 20, 1200, 800}}};
  for (int f = 0; f < 3; ++f) {
    auto header = XrayDicomReader::readHeader(path, f);
    ASSERT_TRUE(header) << header.error();
    const fct::XrayGeometryTags& g = header.value().geometry;
    ASSERT_TRUE(g.primaryAngle_deg && g.secondaryAngle_deg && g.sourceToDetector_mm && g.sourceToPatient_mm);
    EXPECT_DOUBLE_EQ(*g.primaryAngle_deg, expected[f][0]);
    EXPECT_DOUBLE_EQ(*g.secondaryAngle_deg, expected[f][1]);
    EXPECT_DOUBLE_EQ(*g.sourceToDetector_mm, expected[f][2]);
    EXPECT_DOUBLE_EQ(*g.sourceToPatient_mm, expected[f][3]);
    ASSERT_TRUE(g.pixelSpacing_mm);
    EXPECT_TRUE(g.pixelSpacing_mm->isApprox(Eigen::Vector2d(0.3, 0.4)));
    auto camera = XrayGeometryReader::cameraFromTags(g, 40, 30);
    ASSERT_TRUE(camera) << camera.error();
    EXPECT_TRUE(camera.value().sourcePosition_world_mm().isApprox(
        -expected[f][3] * detectorDirection(expected[f][0], expected[f][1]), 1e-9));
  }
  auto beyond = XrayDicomReader::readHeader(path, 3);
  ASSERT_FALSE(beyond);
  EXPECT_NE(beyond.error().find("3 frames"), std::string::npos) << beyond.error();
}

TEST(XrayGeometryReader, AddsRotationalRunIncrementsToTheFirstFramesAngles) {
  const auto dir = fct::test::scratchDir();
  DcmFileFormat perFrameChange = rotationalRun(4, "2.5", "-1");  // one value: the change per frame
  const auto constant = fct::test::save(perFrameChange, dir / "rotational_constant.dcm");
  DcmFileFormat offsets = rotationalRun(4, "0\\10\\25\\45", "0\\0\\1\\3");  // one value per frame: offsets
  const auto vector = fct::test::save(offsets, dir / "rotational_vector.dcm");
  const std::array<double, 4> offsetPrimary{0, 10, 25, 45}, offsetSecondary{0, 0, 1, 3};
  for (int f = 0; f < 4; ++f) {
    auto a = XrayDicomReader::readHeader(constant, f);
    ASSERT_TRUE(a) << a.error();
    EXPECT_NEAR(*a.value().geometry.primaryAngle_deg, -60 + 2.5 * f, 1e-12);
    EXPECT_NEAR(*a.value().geometry.secondaryAngle_deg, 5 - 1.0 * f, 1e-12);
    auto b = XrayDicomReader::readHeader(vector, f);
    ASSERT_TRUE(b) << b.error();
    EXPECT_NEAR(*b.value().geometry.primaryAngle_deg, -60 + offsetPrimary[f], 1e-12);
    EXPECT_NEAR(*b.value().geometry.secondaryAngle_deg, 5 + offsetSecondary[f], 1e-12);
  }
}

TEST(XrayGeometryReader, RefusesAnIncrementWithTheWrongNumberOfValues) {
  DcmFileFormat file = rotationalRun(4, "1\\2\\3", "0");
  const auto path = fct::test::save(file, fct::test::scratchDir() / "rotational_bad.dcm");
  auto header = XrayDicomReader::readHeader(path, 1);
  ASSERT_FALSE(header);
  EXPECT_NE(header.error().find("PositionerPrimaryAngleIncrement (0018,1520) has 3 values"), std::string::npos)
      << header.error();
  EXPECT_NE(header.error().find("4 frames"), std::string::npos) << header.error();
}

TEST(XrayGeometryReader, ProjectsKnownPointsToTheExpectedPixels) {
  // LAO 90: the detector on the patient's left, the source on the right; columns run anterior, rows to the feet.
  fct::XrayGeometryTags tags = completeTags();
  tags.primaryAngle_deg = 90.0;
  auto camera = XrayGeometryReader::cameraFromTags(tags, 101, 81);
  ASSERT_TRUE(camera) << camera.error();
  const double pixelsPerMm = (1000.0 / 750.0) / 0.5;  // magnification at the isocentre over the pixel size
  const Eigen::Vector2d centre_px(50.0, 40.0);
  EXPECT_TRUE(camera.value().project(Eigen::Vector3d::Zero()).isApprox(centre_px, 1e-12));
  EXPECT_TRUE(camera.value().project(Eigen::Vector3d(0, -6, 0)).isApprox(centre_px + Eigen::Vector2d(6 * pixelsPerMm, 0),
                                                                        1e-9));  // anterior: +column
  EXPECT_TRUE(camera.value().project(Eigen::Vector3d(0, 0, -9)).isApprox(centre_px + Eigen::Vector2d(0, 9 * pixelsPerMm),
                                                                        1e-9));  // inferior: +row
  EXPECT_TRUE(camera.value().sourcePosition_world_mm().isApprox(Eigen::Vector3d(-750, 0, 0), 1e-9));
}

TEST(XrayGeometryReader, TellsAStoredMirrorFromTheViewFromTheSource) {
  struct Case {
    const char* orientation;
    bool mirrorColumns;
    bool turned;
  };
  const fct::XrayGeometryOverrides none;
  for (const Case& c : {Case{"R\\F", false, false}, Case{"L\\F", true, false}, Case{"R\\H", true, true},
                        Case{"L\\H", false, true}}) {
    fct::XrayGeometryTags tags = completeTags();
    tags.patientOrientation = c.orientation;
    auto result = XrayGeometryReader::frameCamera(tags, 101, 81, none);
    ASSERT_TRUE(result) << c.orientation << ": " << result.error();
    EXPECT_TRUE(result.value().orientationKnown);
    EXPECT_EQ(result.value().mirrorColumns, c.mirrorColumns) << c.orientation;
    // The stored pixel of a point right of and above the isocentre, after the optional column flip.
    const fct::Camera& camera = result.value().camera;
    Eigen::Vector2d uv_px = camera.project(Eigen::Vector3d(-10, 0, 10));  // patient right, head
    if (c.mirrorColumns) uv_px.x() = 100.0 - uv_px.x();
    const bool rightIsHigherColumn = uv_px.x() > 50.0;
    const bool headIsLowerRow = uv_px.y() < 40.0;
    EXPECT_EQ(rightIsHigherColumn, c.orientation[0] == 'R') << c.orientation;
    EXPECT_EQ(headIsLowerRow, c.orientation[2] == 'F') << c.orientation;
    EXPECT_TRUE(camera.project(Eigen::Vector3d::Zero()).isApprox(Eigen::Vector2d(50, 40), 1e-9)) << c.orientation;
    EXPECT_EQ(camera.T_world_from_camera().linear().col(0).x() > 0.0, c.turned) << c.orientation;
  }
  fct::XrayGeometryTags unknown = completeTags();
  unknown.patientOrientation = "CR\\D";  // quadruped letters: not a biped direction
  auto assumed = XrayGeometryReader::frameCamera(unknown, 101, 81, none);
  ASSERT_TRUE(assumed) << assumed.error();
  EXPECT_FALSE(assumed.value().orientationKnown);
  EXPECT_FALSE(assumed.value().mirrorColumns);
}

TEST(XrayGeometryReader, RefusesAnImageTurnedByNinetyDegrees) {
  fct::XrayGeometryTags tags = completeTags();
  tags.patientOrientation = "F\\R";  // columns toward the feet: the image is turned against the C-arm
  auto result = XrayGeometryReader::frameCamera(tags, 101, 81, {});
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().find("PatientOrientation (0020,0020) is F\\R"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("view file"), std::string::npos) << result.error();
}

TEST(XrayGeometryReader, OverridesSupplyMissingValuesAndReplacePresentOnesWithAWarning) {
  fct::XrayGeometryTags tags;
  tags.sourceToDetector_mm = 1000.0;
  tags.patientOrientation = "R\\F";
  auto missing = XrayGeometryReader::frameCamera(tags, 64, 64, {});
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find("DistanceSourceToPatient (0018,1111)"), std::string::npos) << missing.error();
  EXPECT_NE(missing.error().find("source_to_patient_mm"), std::string::npos) << missing.error();
  EXPECT_NE(missing.error().find("detector.pixel_spacing_mm"), std::string::npos) << missing.error();

  fct::XrayGeometryOverrides overrides;
  overrides.sourceToDetector_mm = 1100.0;
  overrides.sourceToPatient_mm = 800.0;
  overrides.pixelSpacing_mm = Eigen::Vector2d(0.3, 0.3);
  auto supplied = XrayGeometryReader::frameCamera(tags, 64, 64, overrides);
  ASSERT_TRUE(supplied) << supplied.error();
  EXPECT_DOUBLE_EQ(supplied.value().camera.intrinsics().sourceToDetector_mm, 1100.0);
  EXPECT_NEAR(supplied.value().camera.sourcePosition_world_mm().norm(), 800.0, 1e-9);
  const auto& warnings = supplied.warnings();
  EXPECT_TRUE(std::any_of(warnings.begin(), warnings.end(), [](const std::string& w) {
    return w.find("source to detector: the file says 1000 mm, the given 1100 mm is used") != std::string::npos;
  }));
}
