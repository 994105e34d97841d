#pragma once
// XrayDicomReader: X-ray projection images (XA, RF, DX, CR) from DICOM files, one frame at a time, as float pixels in
// the MONOCHROME2 sense, with the C-arm camera when the file's geometry tags are complete.
//
// The C-arm geometry of a frame comes from XrayGeometryReader (convention in its header and docs/file-formats.md).

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Image/DicomIdentity.h"
#include "Image/XrayImage.h"
#include "IO/Dicom/XrayGeometryReader.h"

namespace fct {

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
  XrayGeometryTags geometry;  ///< of the frame asked for (readHeader's `frame`)
  DicomIdentity identity;     ///< patient, study, series, frame of reference and this instance
  std::vector<std::string> missingGeometry;  ///< absent tags a camera needs, e.g. "DistanceSourceToPatient (0018,1111)"
};

/// Reads X-ray projection images from DICOM files (uncompressed, JPEG, JPEG-LS, RLE).
class XrayDicomReader {
 public:
  /// Reads and validates the header (modality XA/RF/DX/CR, grey scale, size, bit depth) without decoding pixels, with
  /// the geometry of frame `frame` (0-based). Fails on a missing, non-DICOM or truncated file, another modality,
  /// colour data, an unsupported bit depth, a frame out of range or malformed angle increments.
  static Result<XrayDicomHeader> readHeader(const std::filesystem::path& path, int frame = 0);

  /// Reads frame `frameIndex` (0-based) as an XrayImage in the MONOCHROME2 sense (MONOCHROME1 is inverted within the
  /// stored bit range, then Rescale Slope/Intercept or a Modality LUT is applied), with a camera when the tags
  /// suffice and the image is stored as seen from the source or turned by 180 deg (warnings say why not). fovMask
  /// is left empty. Fails on a bad header, a frame out of range, no pixel data, or undecodable pixel data.
  static Result<XrayImage> read(const std::filesystem::path& path, int frameIndex = 0);
};

}  // namespace fct
