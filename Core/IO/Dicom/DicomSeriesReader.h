#pragma once
// DicomSeriesReader: finds the image series in a folder of DICOM files and reads one as a CT Volume in HU (LPS, mm),
// resampling gantry-tilted or irregularly spaced series onto a regular grid (or refusing them, by policy).

#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// One image series found in a folder.
struct DicomSeriesSummary {
  std::string seriesInstanceUid, seriesDescription, modality;
  int fileCount = 0;     ///< image files of the series
  int rows = 0, cols = 0;  ///< image size of the series' first file
};

/// What to do with a series whose slices are not on a regular grid (gantry tilt or non-uniform slice spacing).
enum class IrregularSeriesPolicy { ResampleWithWarning, Refuse };

/// Which series to read and how to treat an irregular one.
struct DicomSeriesReadOptions {
  std::string seriesInstanceUid;  ///< empty = the series with the most slices
  IrregularSeriesPolicy policy = IrregularSeriesPolicy::ResampleWithWarning;
  /// Slice spacing in mm of the regular grid when a series must be resampled; 0 = automatic (the smallest slice gap,
  /// but not below the in-plane pixel spacing). Regular series are read as they are, whatever this says.
  double resampleSpacing_mm = 0.0;
};

/// Reads DICOM CT series (any transfer syntax DCMTK decodes, incl. JPEG, JPEG-LS, RLE) from a folder tree.
class DicomSeriesReader {
 public:
  /// All image series found in folder (recursively; files with or without extension; non-DICOM files skipped), the
  /// largest first. Error when the folder is missing, holds no DICOM image, or a DICOM file cannot be parsed.
  static Result<std::vector<DicomSeriesSummary>> scan(const std::filesystem::path& folder);

  /// Reads one series as a Volume of HU (RescaleSlope/Intercept applied), geometry in LPS mm from
  /// ImagePositionPatient/ImageOrientationPatient/PixelSpacing (slice spacing from positions, not SliceThickness).
  /// Tilted or irregular series are resampled with a warning on the Result, or refused, per options.policy.
  /// The Volume's `dicom` keeps the patient, study, series and frame of reference and every slice's SOP instance.
  /// Errors name the file and the tag: missing tags, mixed sizes or orientations, duplicate positions, truncated or
  /// undecodable pixel data, unknown series UID (the message lists the available ones).
  static Result<Volume> read(const std::filesystem::path& folder, const DicomSeriesReadOptions& options = {});
};

}  // namespace fct
