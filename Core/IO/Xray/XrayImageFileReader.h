#pragma once
// XrayImageFileReader: X-ray images from plain PNG and TIFF files (decoded by PngCodec and TiffCodec: libpng, libtiff;
// no geometry: the camera comes from a view file).

#include <filesystem>

#include "Base/Result.h"
#include "Image/XrayImage.h"

namespace fct {

/// Reads grey-scale PNG and TIFF images as XrayImages (MONOCHROME2 sense, no camera, no field-of-view mask).
class XrayImageFileReader {
 public:
  /// Reads an 8- or 16-bit (or float32 TIFF) grey-scale image; modality "PNG" or "TIFF", bitsStored 8, 16 or 32.
  /// Colour images are converted to grey (luma) with a warning; an alpha channel is dropped. Fails on a missing
  /// file, an extension other than .png/.tif/.tiff, undecodable data or another pixel type (e.g. signed 16-bit).
  static Result<XrayImage> read(const std::filesystem::path& path);
};

}  // namespace fct
