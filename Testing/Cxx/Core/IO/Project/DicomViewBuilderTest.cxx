// DicomViewBuilder: views from X-ray DICOM files made with DCMTK (classic, Enhanced XA, rotational run, mirrored)
// checked against known cameras and a DRR, and the real files' missing tags.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Drr/DrrRendererFactory.h"
#include "Drr/DrrVolume.h"
#include "IO/Project/DicomViewBuilder.h"
#include "IO/Project/ViewFile.h"
#include "SyntheticXrayDicom.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using fct::DicomViewBuilder;
using fct::test::SyntheticXray;

constexpr double kDeg = M_PI / 180.0;

/// A classic XA file with complete C-arm tags and the given PatientOrientation (none when empty).
fs::path classicXa(const fs::path& path, int cols, int rows, double primary_deg, double secondary_deg,
                   const char* orientation = "R\\F") {
  SyntheticXray x;
  x.cols = cols;
  x.rows = rows;
  DcmFileFormat file = x.build();
  fct::test::putCarmTags(*file.getDataset(), 1000, 700, 1.0, 1.0, primary_deg, secondary_deg);
  if (*orientation) file.getDataset()->putAndInsertString(DCM_PatientOrientation, orientation);
  return fct::test::save(file, path);
}

/// The pixel where the ray from the source through p_world_mm meets the detector, from the documented C-arm
/// convention only: detector direction d = (sin p cos s, -cos p cos s, sin s), source at -SOD d, detector plane at
/// SID from the source, columns along Rz(p) (-1,0,0), rows along d x columns, principal point at the image centre.
Eigen::Vector2d expectedPixel(const Eigen::Vector3d& p_world_mm, double primary_deg, double secondary_deg, int cols,
                              int rows) {
  const double p = primary_deg * kDeg, s = secondary_deg * kDeg, sid = 1000.0, sod = 700.0;
  const Eigen::Vector3d d(std::sin(p) * std::cos(s), -std::cos(p) * std::cos(s), std::sin(s));
  const Eigen::Vector3d source = -sod * d;
  const Eigen::Vector3d column(-std::cos(p), -std::sin(p), 0.0);
  const Eigen::Vector3d row = d.cross(column);
  const Eigen::Vector3d ray = p_world_mm - source;
  const Eigen::Vector3d onDetector = source + ray * (sid / ray.dot(d));
  const Eigen::Vector3d fromCentre = onDetector - (source + sid * d);
  return {0.5 * (cols - 1) + fromCentre.dot(column), 0.5 * (rows - 1) + fromCentre.dot(row)};  // 1 mm pixels
}

}  // namespace

TEST(DicomViewBuilder, BuildsOneViewPerFileThatRoundTripsThroughTheViewFile) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path ap = classicXa(dir / "ap.dcm", 64, 48, 0, 0);
  const fs::path lao = classicXa(dir / "lao.dcm", 64, 48, 40, -10, "L\\F");  // stored as displayed: mirrored
  auto views = DicomViewBuilder::build({ap, lao, ap});
  ASSERT_TRUE(views) << views.error();
  ASSERT_EQ(views.value().size(), 3u);
  EXPECT_EQ(views.value()[0].name, "ap");
  EXPECT_EQ(views.value()[1].name, "lao");
  EXPECT_EQ(views.value()[2].name, "ap_2");
  EXPECT_FALSE(views.value()[0].mirrorColumns);
  EXPECT_TRUE(views.value()[1].mirrorColumns);
  EXPECT_EQ(views.value()[1].imagePath, lao);
  EXPECT_EQ(views.value()[1].frame, 0);

  ASSERT_TRUE(fct::ViewFile::write(views.value(), dir / "views.json").ok());
  auto read = fct::ViewFile::read(dir / "views.json");
  ASSERT_TRUE(read) << read.error();
  EXPECT_TRUE(read.warnings().empty());
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(read.value()[i].name, views.value()[i].name);
    EXPECT_EQ(read.value()[i].mirrorColumns, views.value()[i].mirrorColumns);
    EXPECT_TRUE(read.value()[i].camera.P_px_from_world().isApprox(views.value()[i].camera.P_px_from_world(), 1e-9));
  }
}

TEST(DicomViewBuilder, DrrOfABallLandsWhereTheConventionPutsIt) {
  const fs::path dir = fct::test::scratchDir();
  const double primary_deg = 30.0, secondary_deg = 15.0;
  auto views = DicomViewBuilder::build({classicXa(dir / "oblique.dcm", 96, 80, primary_deg, secondary_deg)});
  ASSERT_TRUE(views) << views.error();
  // A dense ball of 4 mm radius at LPS (12, -8, 10) mm in air, on a 1 mm grid centred on the isocentre.
  const Eigen::Vector3d ball_mm(12.0, -8.0, 10.0);
  auto ct = fct::Volume::create({64, 64, 64}, {1.0, 1.0, 1.0}, Eigen::Vector3d::Constant(-31.5),
                                Eigen::Matrix3d::Identity(), -1000.0f);
  ASSERT_TRUE(ct) << ct.error();
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        if ((ct.value().lpsFromIjk(Eigen::Vector3d(i, j, k)) - ball_mm).norm() <= 4.0) ct.value().at(i, j, k) = 2000.0f;
      }
  auto drrVolume = fct::DrrVolume::create(ct.value());
  ASSERT_TRUE(drrVolume) << drrVolume.error();
  auto renderer = fct::DrrRendererFactory::create(std::make_shared<const fct::DrrVolume>(std::move(drrVolume).value()));
  ASSERT_TRUE(renderer) << renderer.error();
  auto drr = renderer.value()->render(views.value()[0].camera, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(drr) << drr.error();
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  double total = 0.0;
  for (int v = 0; v < drr.value().rows; ++v)
    for (int u = 0; u < drr.value().cols; ++u) {
      const double value = drr.value().at(u, v);
      weighted += value * Eigen::Vector2d(u, v);
      total += value;
    }
  ASSERT_GT(total, 0.0);
  const Eigen::Vector2d centroid_px = weighted / total;
  const Eigen::Vector2d expected_px = expectedPixel(ball_mm, primary_deg, secondary_deg, 96, 80);
  EXPECT_LT((centroid_px - expected_px).norm(), 0.3) << "DRR ball at " << centroid_px.transpose() << ", expected "
                                                    << expected_px.transpose();
}

TEST(DicomViewBuilder, TakesTheChosenFrameOfARotationalRunAndNamesIt) {
  SyntheticXray x;
  x.cols = 32;
  x.rows = 32;
  x.frames = 5;
  DcmFileFormat file = x.build();
  fct::test::putCarmTags(*file.getDataset(), 1000, 700, 1.0, 1.0, -40, 0);
  file.getDataset()->putAndInsertString(DCM_PositionerPrimaryAngleIncrement, "20");
  file.getDataset()->putAndInsertString(DCM_PatientOrientation, "R\\F");
  const fs::path run = fct::test::save(file, fct::test::scratchDir() / "spin.dcm");
  fct::DicomViewOptions options;
  options.frame = 3;  // -40 + 3 * 20 = LAO 20
  auto views = DicomViewBuilder::build({run}, options);
  ASSERT_TRUE(views) << views.error();
  EXPECT_EQ(views.value()[0].name, "spin_f3");
  EXPECT_EQ(views.value()[0].frame, 3);
  const Eigen::Vector3d p(5, 7, -3);
  EXPECT_TRUE(views.value()[0].camera.project(p).isApprox(expectedPixel(p, 20.0, 0.0, 32, 32), 1e-9));

  options.frame = 5;
  auto beyond = DicomViewBuilder::build({run}, options);
  ASSERT_FALSE(beyond);
  EXPECT_NE(beyond.error().find("frame 5 is out of range"), std::string::npos) << beyond.error();
}

TEST(DicomViewBuilder, RefusesTheRealFilesNamingEachMissingTagAndItsViewFileKey) {
  FCT_REQUIRE_DATA("xray");
  struct Case {
    const char* file;
    std::vector<std::string> named;
  };
  const std::vector<Case> cases{
      {"xray/rf_shoulder_kwire.dcm", {"DistanceSourceToDetector (0018,1110)", "source_to_detector_mm",
                                      "DistanceSourceToPatient (0018,1111)", "source_to_patient_mm",
                                      "ImagerPixelSpacing (0018,1164)", "detector.pixel_spacing_mm"}},
      {"xray/dx_thorax_canine.dcm", {"DistanceSourceToPatient (0018,1111)", "source_to_patient_mm"}},
      {"xray/xa_coronary_multiframe_jpeg.dcm", {"DistanceSourceToDetector (0018,1110)", "source_to_patient_mm"}},
      {"xray/cr_chest_monochrome1_jpeg.dcm", {"DistanceSourceToDetector (0018,1110)", "source_to_patient_mm"}},
  };
  for (const Case& c : cases) {
    auto views = DicomViewBuilder::build({fct::test::dataDir() / c.file});
    ASSERT_FALSE(views) << c.file;
    for (const std::string& name : c.named) EXPECT_NE(views.error().find(name), std::string::npos) << views.error();
  }
  // The canine DX lacks only the source-to-isocentre distance; supplied, it becomes a (mirrored: L\F) view.
  fct::DicomViewOptions options;
  options.overrides.sourceToPatient_mm = 700.0;
  auto dx = DicomViewBuilder::build({fct::test::dataDir() / "xray/dx_thorax_canine.dcm"}, options);
  ASSERT_TRUE(dx) << dx.error();
  EXPECT_TRUE(dx.value()[0].mirrorColumns);
  EXPECT_DOUBLE_EQ(dx.value()[0].camera.intrinsics().sourceToDetector_mm, 1000.0);
}

TEST(DicomViewBuilder, RefusesNoFilesAndFilesThatAreNotXrays) {
  EXPECT_FALSE(DicomViewBuilder::build({}));
  const fs::path dir = fct::test::scratchDir();
  SyntheticXray ct;
  ct.modality = "CT";
  DcmFileFormat file = ct.build();
  auto result = DicomViewBuilder::build({fct::test::save(file, dir / "slice.dcm")});
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().find("modality CT"), std::string::npos) << result.error();
  auto missing = DicomViewBuilder::build({dir / "absent.dcm"});
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find("does not exist"), std::string::npos) << missing.error();
}
