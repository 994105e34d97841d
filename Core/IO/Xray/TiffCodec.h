#pragma once
// TiffCodec: TIFF decoding and encoding in memory with libtiff (the reader and the writer of one format side by side).

#include <cstdint>
#include <string>
#include <string_view>

#include "Base/Result.h"
#include "IO/Xray/DecodedRaster.h"

namespace fct {

/// TIFF bytes to samples and back; every libtiff error becomes a Result error, nothing is thrown.
class TiffCodec {
 public:
  /// Decodes the first image of a TIFF (classic or BigTIFF, any compression libtiff has, strips or tiles, interleaved
  /// or planar): unsigned 8- or 16-bit or float32 samples, grey (black- or white-is-zero; white-is-zero is flipped to
  /// black-is-zero with a note), grey + extra samples, RGB(A), or an 8-bit palette (expanded to RGB). Fails naming
  /// the pixel type for others (signed integers, 1-bit, float64, CMYK, YCbCr) and with libtiff's reason on damaged
  /// data; fails before allocating the image when a side exceeds `maxSide` pixels or the image `maxPixels` (libtiff's
  /// own allocations are bounded by the same image as float32 RGBA).
  static Result<DecodedRaster> decode(std::string_view bytes, std::uint32_t maxSide, std::uint64_t maxPixels);

  /// Encodes rows*cols float32 grey values (row-major) as an uncompressed TIFF; fails only if libtiff does.
  static Result<std::string> encodeFloat32(const float* pixels, int cols, int rows);
};

}  // namespace fct
