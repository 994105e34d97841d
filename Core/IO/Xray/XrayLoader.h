#pragma once
// XrayLoader: loads an X-ray image from a DICOM file (any name) or a PNG/TIFF file.

#include <filesystem>

#include "Base/Result.h"
#include "Image/XrayImage.h"

namespace fct {

/// One entry point for every X-ray image source.
class XrayLoader {
 public:
  /// .png, .tif and .tiff files go to XrayImageFileReader (frame must be 0); anything else is read as DICOM with
  /// XrayDicomReader (frame = 0-based frame of a multi-frame file). Fails with the reader's message, or
  /// "no such file" when the path does not exist.
  static Result<XrayImage> load(const std::filesystem::path& path, int frame = 0);
  /// True when the path's extension names a PNG or TIFF image.
  static bool isPlainImageFile(const std::filesystem::path& path);
};

}  // namespace fct
