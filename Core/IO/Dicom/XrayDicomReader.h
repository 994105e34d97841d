#pragma once
// XrayDicomReader: X-ray projection images (XA, RF, DX, CR) from DICOM files, one frame at a time, as float pixels in
// the MONOCHROME2 sense, with the C-arm camera when the file's geometry tags are complete.
//
// Camera convention for cameraFromTags (see README "X-ray import"): isocentre at the world origin, patient supine,
// world LPS. At PositionerPrimaryAngle = PositionerSecondaryAngle = 0 the source is posterior at (0, +SOD, 0) and the
// beam travels anterior (-y) to the detector; increasing row points to the patient's feet (-z) and increasing column
// to the patient's right (-x), i.e. the stored image is seen from the source. The primary angle rotates the C-arm
// about the head-foot axis (+z), LAO positive (detector toward the patient's left); the secondary angle tilts it about
// the left-right axis, cranial positive (detector toward the head): R_world_from_camera = Rz(primary) Rx(-secondary) R0.

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Image/XrayImage.h"

namespace fct {

/// What a DICOM file says about the acquisition geometry; std::nullopt = tag absent or empty.
struct XrayGeometryTags {
  std::optional<double> sourceToDetector_mm;       ///< DistanceSourceToDetector (0018,1110)
  std::optional<double> sourceToPatient_mm;        ///< DistanceSourceToPatient (0018,1111), source to isocentre
  std::optional<Eigen::Vector2d> pixelSpacing_mm;  ///< (du, dv) from ImagerPixelSpacing (0018,1164), else PixelSpacing (0028,0030)
  std::optional<double> primaryAngle_deg;          ///< PositionerPrimaryAngle (0018,1510), LAO positive
  std::optional<double> secondaryAngle_deg;        ///< PositionerSecondaryAngle (0018,1511), cranial positive
  std::optional<Eigen::Vector2d> detectorActiveOrigin_mm;  ///< DetectorActiveOrigin (0018,7028) as (along columns, along rows)
};

/// The header facts of an X-ray DICOM file needed to interpret its pixels and geometry.
struct XrayDicomHeader {
  std::string modality;        ///< XA, RF, DX or CR
  std::string photometric;     ///< MONOCHROME1 or MONOCHROME2
  std::string sopClassUid;
  int cols = 0;
  int rows = 0;
  int frames = 1;
  int bitsAllocated = 0;
  int bitsStored = 0;
  std::string transferSyntax;  ///< DCMTK's name of the transfer syntax, e.g. "JPEG Baseline"
  XrayGeometryTags geometry;
  std::vector<std::string> missingGeometry;  ///< absent tags a camera needs, e.g. "DistanceSourceToPatient (0018,1111)"
};

/// Reads X-ray projection images from DICOM files (uncompressed, JPEG, JPEG-LS, RLE).
class XrayDicomReader {
 public:
  /// Reads and validates the header (modality XA/RF/DX/CR, grey scale, size, bit depth) without decoding pixels.
  /// Fails on a missing, non-DICOM or truncated file, another modality, colour data or an unsupported bit depth.
  static Result<XrayDicomHeader> readHeader(const std::filesystem::path& path);

  /// Reads frame `frameIndex` (0-based) as an XrayImage in the MONOCHROME2 sense (MONOCHROME1 is inverted within the
  /// stored bit range, then Rescale Slope/Intercept or a Modality LUT is applied), with a camera when the tags
  /// suffice (warnings say why not). fovMask is left empty. Fails on a bad header, a frame out of range, no pixel
  /// data, or pixel data that cannot be decoded.
  static Result<XrayImage> read(const std::filesystem::path& path, int frameIndex = 0);

  /// The C-arm camera from the tags for a detector of cols x rows pixels (convention in the header comment), or an
  /// error naming every missing value and the view-file key that supplies it. Absent positioner angles are taken as 0
  /// with a warning. Fails also on non-positive distances, SOD >= SID or non-positive spacing.
  static Result<Camera> cameraFromTags(const XrayGeometryTags& tags, int cols, int rows);
};

}  // namespace fct
