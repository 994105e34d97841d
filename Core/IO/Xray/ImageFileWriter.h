#pragma once
// ImageFileWriter: writes FloatImages (DRRs, prepared X-rays) to files. Every image is encoded in memory and written with
// AtomicFile, so a failed write never leaves a half-written file.

#include <Eigen/Core>

#include <filesystem>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/RgbImage.h"

namespace fct {

/// Writers for 2D float images in PFM, float32 TIFF, windowed 16-bit PNG and float32 NRRD.
class ImageFileWriter {
 public:
  /// Writes a grey-scale PFM ("Pf", little-endian float32, rows stored bottom to top as the format requires).
  /// Fails on an empty or inconsistent image or an unwritable path.
  static Status writePfm(const FloatImage& image, const std::filesystem::path& path);

  /// Writes a single-channel float32 TIFF (row 0 at the top). Fails on an empty image or an unwritable path.
  static Status writeTiff(const FloatImage& image, const std::filesystem::path& path);

  /// Writes a 16-bit grey PNG mapping windowMin..windowMax linearly to 0..65535 (clamped; NaN -> 0).
  /// Fails unless windowMin < windowMax are finite, on an empty image or an unwritable path.
  static Status writePng16(const FloatImage& image, const std::filesystem::path& path, float windowMin, float windowMax);

  /// Writes an 8-bit RGB PNG (e.g. an overlay). Fails on an empty or inconsistent image or an unwritable path.
  static Status writePngRgb(const RgbImage& image, const std::filesystem::path& path);

  /// Writes a 2D float32 NRRD (raw, little endian, columns fastest) with `spacings` = pixelSpacing_mm (du, dv).
  /// Fails on an empty image, non-positive spacing or an unwritable path.
  static Status writeNrrd2d(const FloatImage& image, const std::filesystem::path& path,
                            const Eigen::Vector2d& pixelSpacing_mm = Eigen::Vector2d(1.0, 1.0));
};

}  // namespace fct
