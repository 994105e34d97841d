#include "IO/Dicom/XrayGeometryReader.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcitem.h>
#include <fmt/core.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "IO/Dicom/DicomValues.h"

namespace fct {

namespace {

/// Where one frame's values are looked up, most specific first: its per-frame functional group item, the shared
/// item (both searched into their macro sequences), then the dataset's top level.
class FrameScope {
 public:
  FrameScope(DcmItem& dataset, int frame) : m_dataset(dataset) {
    if (dataset.findAndGetSequenceItem(DCM_PerFrameFunctionalGroupsSequence, m_perFrame, frame).bad()) {
      m_perFrame = nullptr;
    }
    if (dataset.findAndGetSequenceItem(DCM_SharedFunctionalGroupsSequence, m_shared, 0).bad()) m_shared = nullptr;
  }

  /// Value `pos` of a numeric tag; `fromGroups` says whether it came from a functional group.
  std::optional<double> number(const DcmTagKey& tag, unsigned long pos = 0, bool* fromGroups = nullptr) {
    for (DcmItem* group : {m_perFrame, m_shared}) {
      if (!group) continue;
      if (auto value = DicomValues::number(*group, tag, pos, true)) {
        if (fromGroups) *fromGroups = true;
        return value;
      }
    }
    if (fromGroups) *fromGroups = false;
    return DicomValues::number(m_dataset, tag, pos);
  }

  std::optional<Eigen::Vector2d> pair(const DcmTagKey& tag) {
    const auto first = number(tag, 0);
    const auto second = number(tag, 1);
    if (!first || !second) return std::nullopt;
    return Eigen::Vector2d(*first, *second);
  }

  std::string text(const DcmTagKey& tag) {
    for (DcmItem* group : {m_perFrame, m_shared}) {
      if (!group) continue;
      OFString value;
      if (group->findAndGetOFStringArray(tag, value, true).good() && !value.empty()) return value.c_str();
    }
    return DicomValues::text(m_dataset, tag);
  }

 private:
  DcmItem& m_dataset;
  DcmItem* m_perFrame = nullptr;
  DcmItem* m_shared = nullptr;
};

/// The angle of `frame` from a top-level angle and its rotational-run increment tag.
Result<std::optional<double>> withIncrement(DcmItem& dataset, std::optional<double> angle_deg, const DcmTagKey& tag,
                                            const char* name, int frame, int frameCount) {
  const unsigned long values = DicomValues::count(dataset, tag);
  if (values == 0 || !angle_deg) return angle_deg;
  if (values != 1 && values != static_cast<unsigned long>(frameCount)) {
    return fail(fmt::format("{} has {} values but the file has {} frames; it must hold one value (the change per "
                            "frame) or one per frame (each frame's offset from the initial angle)",
                            name, values, frameCount));
  }
  const auto increment = DicomValues::number(dataset, tag, values == 1 ? 0 : static_cast<unsigned long>(frame));
  if (!increment) return fail(fmt::format("{} value {} is not a number", name, values == 1 ? 0 : frame));
  return std::optional<double>(*angle_deg + (values == 1 ? frame * *increment : *increment));
}

/// The LPS direction named by DICOM patient-direction letters ("L", "RA", "HP", ...); zero when any letter is not a
/// biped direction.
Eigen::Vector3d letterDirection(const std::string& letters) {
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  for (const char letter : letters) {
    switch (letter) {
      case 'L': direction.x() += 1; break;
      case 'R': direction.x() -= 1; break;
      case 'P': direction.y() += 1; break;
      case 'A': direction.y() -= 1; break;
      case 'H': direction.z() += 1; break;
      case 'F': direction.z() -= 1; break;
      default: return Eigen::Vector3d::Zero();
    }
  }
  return direction.norm() > 0.0 ? Eigen::Vector3d(direction.normalized()) : direction;
}

/// The camera seen from the other side of the image centre: turned by 180 deg about its principal ray.
Result<Camera> turnedHalfway(const Camera& camera) {
  CameraIntrinsics intrinsics = camera.intrinsics();
  intrinsics.principalPoint_px =
      Eigen::Vector2d(intrinsics.cols - 1.0, intrinsics.rows - 1.0) - intrinsics.principalPoint_px;
  Eigen::Isometry3d T_world_from_camera = camera.T_world_from_camera();
  T_world_from_camera.linear().col(0) *= -1.0;
  T_world_from_camera.linear().col(1) *= -1.0;
  return Camera::create(intrinsics, T_world_from_camera);
}

}  // namespace

Result<XrayGeometryTags> XrayGeometryReader::readTags(DcmItem& dataset, int frame, int frameCount) {
  if (frame < 0 || frame >= frameCount) {
    return fail(fmt::format("frame {} is out of range: the file has {} frame{} (0..{})", frame, frameCount,
                            frameCount == 1 ? "" : "s", frameCount - 1));
  }
  FrameScope scope(dataset, frame);
  XrayGeometryTags g;
  std::vector<std::string> warnings;
  g.sourceToDetector_mm = scope.number(DCM_DistanceSourceToDetector);
  g.sourceToPatient_mm = scope.number(DCM_DistanceSourceToIsocenter);
  if (!g.sourceToPatient_mm) g.sourceToPatient_mm = scope.number(DCM_DistanceSourceToPatient);
  // DICOM spacing order is (row spacing, column spacing) = (dv, du).
  if (const auto imager = scope.pair(DCM_ImagerPixelSpacing)) {
    g.pixelSpacing_mm = Eigen::Vector2d(imager->y(), imager->x());
  } else if (const auto plain = scope.pair(DCM_PixelSpacing)) {
    g.pixelSpacing_mm = Eigen::Vector2d(plain->y(), plain->x());
    warnings.emplace_back("pixel spacing taken from PixelSpacing (0028,0030), which may be calibrated at the patient "
                          "rather than at the detector; check it");
  }
  bool primaryFromGroups = false, secondaryFromGroups = false;
  g.primaryAngle_deg = scope.number(DCM_PositionerPrimaryAngle, 0, &primaryFromGroups);
  g.secondaryAngle_deg = scope.number(DCM_PositionerSecondaryAngle, 0, &secondaryFromGroups);
  if (!primaryFromGroups) {
    auto primary = withIncrement(dataset, g.primaryAngle_deg, DCM_PositionerPrimaryAngleIncrement,
                                 "PositionerPrimaryAngleIncrement (0018,1520)", frame, frameCount);
    if (!primary) return fail(primary.error());
    g.primaryAngle_deg = primary.value();
  }
  if (!secondaryFromGroups) {
    auto secondary = withIncrement(dataset, g.secondaryAngle_deg, DCM_PositionerSecondaryAngleIncrement,
                                   "PositionerSecondaryAngleIncrement (0018,1521)", frame, frameCount);
    if (!secondary) return fail(secondary.error());
    g.secondaryAngle_deg = secondary.value();
  }
  if (const auto origin = scope.pair(DCM_DetectorActiveOrigin)) {
    g.detectorActiveOrigin_mm = Eigen::Vector2d(origin->y(), origin->x());  // DICOM order is (row, column)
  }
  g.patientOrientation = scope.text(DCM_PatientOrientation);
  Result<XrayGeometryTags> result(std::move(g));
  for (auto& w : warnings) result.addWarning(std::move(w));
  return result;
}

Result<Camera> XrayGeometryReader::cameraFromTags(const XrayGeometryTags& tags, int cols, int rows) {
  std::string missing;
  auto need = [&missing](bool present, const char* tag, const char* key) {
    if (present) return;
    missing += fmt::format("{}missing {}", missing.empty() ? "" : "; ", tag);
    missing += fmt::format(" (supply {} in a view file)", key);
  };
  need(tags.sourceToDetector_mm.has_value(), XrayGeometryReader::kSourceToDetectorTag, "source_to_detector_mm");
  need(tags.sourceToPatient_mm.has_value(), XrayGeometryReader::kSourceToPatientTag, "source_to_patient_mm");
  need(tags.pixelSpacing_mm.has_value(), XrayGeometryReader::kPixelSpacingTag, "detector.pixel_spacing_mm");
  if (!missing.empty()) return fail(fmt::format("cannot build the C-arm camera from the DICOM tags: {}", missing));

  const double sid = *tags.sourceToDetector_mm;
  const double sod = *tags.sourceToPatient_mm;
  if (!(sod > 0.0) || !(sid > sod)) {
    return fail(fmt::format("implausible distances: source to isocentre {} mm must be positive and smaller than "
                            "source to detector {} mm",
                            sod, sid));
  }
  if (!((tags.pixelSpacing_mm->array() > 0.0).all())) {
    return fail(fmt::format("implausible detector pixel spacing [{}, {}] mm: it must be positive",
                            tags.pixelSpacing_mm->x(), tags.pixelSpacing_mm->y()));
  }
  CameraIntrinsics intrinsics;
  intrinsics.cols = cols;
  intrinsics.rows = rows;
  intrinsics.pixelSpacing_mm = *tags.pixelSpacing_mm;
  intrinsics.sourceToDetector_mm = sid;
  intrinsics.principalPoint_px = Eigen::Vector2d(0.5 * (cols - 1), 0.5 * (rows - 1));

  std::vector<std::string> warnings;
  if (!tags.primaryAngle_deg) warnings.emplace_back("PositionerPrimaryAngle (0018,1510) absent: assumed 0 deg (no LAO/RAO)");
  if (!tags.secondaryAngle_deg) {
    warnings.emplace_back("PositionerSecondaryAngle (0018,1511) absent: assumed 0 deg (no cranial/caudal tilt)");
  }
  if (tags.detectorActiveOrigin_mm) {
    warnings.push_back(fmt::format("DetectorActiveOrigin (0018,7028) = ({}, {}) mm is recorded but the physical "
                                   "detector size is not; principal point taken at the image centre",
                                   tags.detectorActiveOrigin_mm->x(), tags.detectorActiveOrigin_mm->y()));
  }
  constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
  const double primary_rad = tags.primaryAngle_deg.value_or(0.0) * kDegToRad;
  const double secondary_rad = tags.secondaryAngle_deg.value_or(0.0) * kDegToRad;
  // R0: camera axes at 0/0 in LPS: +x (columns) to the patient's right, +y (rows) to the feet, +z (beam) anterior.
  Eigen::Matrix3d R0;
  R0.col(0) = Eigen::Vector3d(-1, 0, 0);
  R0.col(1) = Eigen::Vector3d(0, 0, -1);
  R0.col(2) = Eigen::Vector3d(0, -1, 0);
  const Eigen::Matrix3d R_world_from_camera = (Eigen::AngleAxisd(primary_rad, Eigen::Vector3d::UnitZ()) *
                                               Eigen::AngleAxisd(-secondary_rad, Eigen::Vector3d::UnitX()))
                                                  .toRotationMatrix() *
                                              R0;
  Eigen::Isometry3d T_world_from_camera = Eigen::Isometry3d::Identity();
  T_world_from_camera.linear() = R_world_from_camera;
  T_world_from_camera.translation() = -sod * R_world_from_camera.col(2);  // isocentre at the world origin
  auto camera = Camera::create(intrinsics, T_world_from_camera);
  for (auto& w : warnings) camera.addWarning(std::move(w));
  return camera;
}

Result<XrayFrameCamera> XrayGeometryReader::frameCamera(XrayGeometryTags tags, int cols, int rows,
                                                        const XrayGeometryOverrides& overrides) {
  std::vector<std::string> warnings;
  auto mm = [](double v) { return fmt::format("{} mm", v); };
  auto applyScalar = [&](std::optional<double>& value, const std::optional<double>& override, const char* what) {
    if (!override) return;
    if (value && std::abs(*value - *override) > 1e-9) {
      warnings.push_back(fmt::format("{}: the file says {}, the given {} is used", what, mm(*value), mm(*override)));
    }
    value = override;
  };
  applyScalar(tags.sourceToDetector_mm, overrides.sourceToDetector_mm, "source to detector");
  applyScalar(tags.sourceToPatient_mm, overrides.sourceToPatient_mm, "source to isocentre");
  if (overrides.pixelSpacing_mm) {
    if (tags.pixelSpacing_mm && (*tags.pixelSpacing_mm - *overrides.pixelSpacing_mm).norm() > 1e-9) {
      warnings.push_back(fmt::format("detector pixel spacing: the file says [{}, {}] mm, the given [{}, {}] mm is used",
                                     tags.pixelSpacing_mm->x(), tags.pixelSpacing_mm->y(),
                                     overrides.pixelSpacing_mm->x(), overrides.pixelSpacing_mm->y()));
    }
    tags.pixelSpacing_mm = overrides.pixelSpacing_mm;
  }

  auto camera = cameraFromTags(tags, cols, rows);
  if (!camera) return fail(camera.error());
  for (const auto& w : camera.warnings()) warnings.push_back(w);
  XrayFrameCamera result{camera.value(), false, false};

  const std::string& orientation = tags.patientOrientation;
  const auto separator = orientation.find('\\');
  const Eigen::Vector3d columnTag_lps =
      separator == std::string::npos ? Eigen::Vector3d::Zero() : letterDirection(orientation.substr(0, separator));
  const Eigen::Vector3d rowTag_lps =
      separator == std::string::npos ? Eigen::Vector3d::Zero() : letterDirection(orientation.substr(separator + 1));
  if (!columnTag_lps.isZero() && !rowTag_lps.isZero()) {
    result.orientationKnown = true;
    const Eigen::Matrix3d R = result.camera.T_world_from_camera().linear();
    const double columnAgreement = columnTag_lps.dot(R.col(0));
    const double rowAgreement = rowTag_lps.dot(R.col(1));
    constexpr double kAmbiguous = 0.3;  // cosine below which a letter does not name the image axis
    if (std::abs(columnAgreement) < kAmbiguous || std::abs(rowAgreement) < kAmbiguous) {
      return fail(fmt::format("PatientOrientation (0020,0020) is {} but the camera from the positioner angles has "
                              "columns along LPS ({:.2f}, {:.2f}, {:.2f}) and rows along ({:.2f}, {:.2f}, {:.2f}); the "
                              "stored image is turned against the C-arm, so give its camera in a view file",
                              orientation, R(0, 0), R(1, 0), R(2, 0), R(0, 1), R(1, 1), R(2, 1)));
    }
    const bool columnsReversed = columnAgreement < 0.0;
    const bool rowsReversed = rowAgreement < 0.0;
    if (rowsReversed) {
      auto turned = turnedHalfway(result.camera);
      if (!turned) return fail(turned.error());
      result.camera = turned.value();
    }
    result.mirrorColumns = columnsReversed != rowsReversed;
  }
  Result<XrayFrameCamera> out(std::move(result));
  for (auto& w : warnings) out.addWarning(std::move(w));
  return out;
}

}  // namespace fct
