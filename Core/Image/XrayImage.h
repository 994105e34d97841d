#pragma once
// XrayImage: one fluoroscopic / radiographic frame as float pixels in the MONOCHROME2 display sense (higher value is
// displayed brighter; MONOCHROME1 files are inverted on import), with what was known about its origin and geometry.
// Note the physical polarity differs by modality: raw fluoroscopy (XA, RF) is bright where more signal reaches the
// detector (bone dark), while processed radiographs (CR, DX) are usually stored with bone bright. The registration's
// X-ray preparation decides the polarity; Core does not guess it.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "Geometry/Camera.h"

namespace fct {

/// A 2D X-ray image: row-major float pixels (row 0 = detector top), plus acquisition facts.
struct XrayImage {
  int cols = 0;
  int rows = 0;
  std::vector<float> pixels;             ///< rows*cols values, row-major, MONOCHROME2 sense
  int bitsStored = 0;                    ///< original bit depth (8, 12, 16); 0 if unknown
  std::string photometric;               ///< original photometric interpretation ("MONOCHROME1", "MONOCHROME2", ...)
  std::string modality;                  ///< DICOM modality (XA, RF, DX, CR) or "PNG"/"TIFF"
  int frameIndex = 0;                    ///< frame taken from a multi-frame file (0-based)
  int frameCount = 1;                    ///< frames in the source file
  std::vector<std::uint8_t> fovMask;     ///< rows*cols, 1 = inside the field of view; empty if unknown
  std::optional<Camera> camera;          ///< geometry, if known
  std::string sourcePath;                ///< file it came from

  /// Pixel value at (col,row); no bounds check.
  float at(int col, int row) const { return pixels[static_cast<std::size_t>(row) * cols + col]; }
};

}  // namespace fct
