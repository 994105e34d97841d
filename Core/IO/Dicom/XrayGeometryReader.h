#pragma once
// XrayGeometryReader: the C-arm geometry of one frame of an X-ray DICOM dataset - classic XA/RF/DX/CR attributes,
// Enhanced XA functional groups, the angle increments of a rotational run, PatientOrientation - and the pinhole
// camera it implies.
//
// C-arm convention (docs/file-formats.md, "C-arm convention"): world = patient LPS in mm, patient supine, isocentre at
// the world origin. At PositionerPrimaryAngle = PositionerSecondaryAngle = 0 the source is posterior at (0, +SOD, 0)
// and the beam travels anterior (-y); increasing column points to the patient's right (-x), increasing row to the
// feet (-z): the image as seen from the source. R_world_from_camera = Rz(primary) * Rx(-secondary) * R0, LAO and
// cranial positive, R0 = [camera x, y, z in LPS] = [(-1,0,0), (0,0,-1), (0,-1,0)]; source = -SOD * R.col(2).

#include <Eigen/Core>

#include <optional>
#include <string>

#include "Base/Result.h"
#include "Geometry/Camera.h"

class DcmItem;

namespace fct {

/// What a DICOM file says about the acquisition geometry of one frame; std::nullopt = tag absent or empty.
struct XrayGeometryTags {
  std::optional<double> sourceToDetector_mm;       ///< DistanceSourceToDetector (0018,1110)
  std::optional<double> sourceToPatient_mm;        ///< DistanceSourceToIsocenter (0018,9402), else DistanceSourceToPatient (0018,1111)
  std::optional<Eigen::Vector2d> pixelSpacing_mm;  ///< (du, dv) from ImagerPixelSpacing (0018,1164), else PixelSpacing (0028,0030)
  std::optional<double> primaryAngle_deg;          ///< PositionerPrimaryAngle (0018,1510) of this frame, LAO positive
  std::optional<double> secondaryAngle_deg;        ///< PositionerSecondaryAngle (0018,1511) of this frame, cranial positive
  std::optional<Eigen::Vector2d> detectorActiveOrigin_mm;  ///< DetectorActiveOrigin (0018,7028) as (along columns, along rows)
  std::string patientOrientation;  ///< PatientOrientation (0020,0020) as stored, e.g. "R\F"; empty when absent
};

/// Values that replace the file's SID, SOD or detector pixel spacing (or supply them when absent).
struct XrayGeometryOverrides {
  std::optional<double> sourceToDetector_mm;
  std::optional<double> sourceToPatient_mm;
  std::optional<Eigen::Vector2d> pixelSpacing_mm;  ///< (du, dv)
};

/// The camera of one frame for its stored pixels, after an optional left-right flip of the image.
struct XrayFrameCamera {
  Camera camera;
  bool mirrorColumns = false;  ///< the stored image must be flipped left-right (column c -> cols-1-c) to fit `camera`
  bool orientationKnown = false;  ///< PatientOrientation was present in L/R/A/P/H/F letters; else assumed from the source
};

/// Reads per-frame C-arm geometry from DICOM datasets and turns it into cameras.
class XrayGeometryReader {
 public:
  /// The tags a camera needs, as messages and XrayDicomHeader::missingGeometry name them.
  static constexpr const char* kSourceToDetectorTag = "DistanceSourceToDetector (0018,1110)";
  static constexpr const char* kSourceToPatientTag =
      "DistanceSourceToPatient (0018,1111) or DistanceSourceToIsocenter (0018,9402)";
  static constexpr const char* kPixelSpacingTag = "ImagerPixelSpacing (0018,1164) or PixelSpacing (0028,0030)";

  /// The geometry of frame `frame` (0-based) of a dataset with `frameCount` frames. Each value is taken from the
  /// frame's item of the Per-Frame Functional Groups Sequence (5200,9230), else the Shared Functional Groups
  /// Sequence (5200,9229) (Enhanced XA: X-Ray Geometry, Positioner Position, Patient Orientation in Frame), else the
  /// top level. Top-level angles of a multi-frame file get the rotational-run increments (0018,1520/1521): one value
  /// is the change per frame (angle + frame * value), one value per frame is that frame's offset from the initial
  /// angle. Fails on a frame out of range or an increment with another number of values. A PixelSpacing fallback is
  /// a warning on the Result.
  static Result<XrayGeometryTags> readTags(DcmItem& dataset, int frame, int frameCount);

  /// The C-arm camera (convention above) from the tags for a detector of cols x rows pixels, principal point at the
  /// image centre. Fails naming every missing value and the view-file key that supplies it, and on non-positive
  /// distances, SOD >= SID or non-positive spacing. Absent angles are taken as 0 with a warning.
  static Result<Camera> cameraFromTags(const XrayGeometryTags& tags, int cols, int rows);

  /// The camera for the stored pixels: `overrides` replace the tags (a warning when they differ from a value in the
  /// file), then PatientOrientation tells how the stored image stands against the view from the source: the same
  /// (camera as is), mirrored left-right (mirrorColumns) or top-bottom (mirrorColumns and the camera turned by 180 deg
  /// about its axis), or turned by 180 deg (camera turned). Absent or non-biped PatientOrientation: taken as seen
  /// from the source (orientationKnown false). Fails as cameraFromTags, or when the orientation fits neither image axis
  /// (an image turned by 90 deg).
  static Result<XrayFrameCamera> frameCamera(XrayGeometryTags tags, int cols, int rows,
                                             const XrayGeometryOverrides& overrides);
};

}  // namespace fct
