#pragma once
// PngCodec: PNG decoding and encoding in memory with libpng (the reader and the writer of one format side by side).

#include <cstdint>
#include <string>
#include <string_view>

#include "Base/Result.h"
#include "IO/Xray/DecodedRaster.h"

namespace fct {

/// PNG bytes to samples and back; every libpng error becomes a Result error, nothing is thrown.
class PngCodec {
 public:
  /// Decodes a whole PNG held in `bytes`: grey, grey + alpha, RGB, RGBA (8 or 16 bits) or palette (expanded to RGB);
  /// grey of 1, 2 or 4 bits is widened to 8. Fails with libpng's reason on damaged or truncated data, and before
  /// allocating the image when a side exceeds `maxSide` pixels or the image `maxPixels`.
  static Result<DecodedRaster> decode(std::string_view bytes, std::uint32_t maxSide, std::uint64_t maxPixels);

  /// Encodes rows*cols 16-bit grey values (row-major) as a PNG; fails only if libpng does.
  static Result<std::string> encodeGrey16(const std::uint16_t* pixels, int cols, int rows);

  /// Encodes rows*cols RGB triplets of 8 bits (row-major, R first) as a PNG; fails only if libpng does.
  static Result<std::string> encodeRgb8(const std::uint8_t* pixels, int cols, int rows);
};

}  // namespace fct
