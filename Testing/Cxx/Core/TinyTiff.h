#pragma once
// TinyTiff: a minimal uncompressed 8-bit grey TIFF written byte by byte, with any declared size, for the X-ray image
// reader tests and the fuzz seed of the TIFF whose header declared more pixels than any detector.

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace fct::test {

/// Appends `value` as `bytes` bytes in the given byte order.
inline void put(std::string& out, std::uint64_t value, int bytes, bool bigEndian) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>(value >> (8 * (bigEndian ? bytes - 1 - i : i))));
}

/// An uncompressed 8-bit grey TIFF (classic or BigTIFF, either byte order) whose header declares cols x rows pixels;
/// its one strip holds the pixels of the first min(cols x rows, 4) of them, each 50.
inline std::string tinyTiff(std::uint32_t cols, std::uint32_t rows, bool bigEndian, bool bigTiff) {
  const int offsetBytes = bigTiff ? 8 : 4, countBytes = bigTiff ? 8 : 2;
  const std::uint64_t pixelBytes = std::min<std::uint64_t>(std::uint64_t{cols} * rows, 4);
  // tag, type (3 SHORT, 4 LONG), value: width, length, bits per sample, no compression, min-is-black, strip offset,
  // samples per pixel, rows per strip, strip byte count.
  const std::uint64_t headerBytes = bigTiff ? 16 : 8;
  const std::vector<std::array<std::uint64_t, 3>> tags{{256, 4, cols}, {257, 4, rows},       {258, 3, 8},
                                                       {259, 3, 1},    {262, 3, 1},          {273, 4, headerBytes},
                                                       {277, 3, 1},    {278, 4, rows},       {279, 4, pixelBytes}};
  std::string out = bigEndian ? "MM" : "II";
  put(out, bigTiff ? 43 : 42, 2, bigEndian);
  if (bigTiff) {
    put(out, 8, 2, bigEndian);
    put(out, 0, 2, bigEndian);
  }
  put(out, headerBytes + pixelBytes, offsetBytes, bigEndian);  // the directory follows the pixels
  out.append(pixelBytes, static_cast<char>(50));
  put(out, tags.size(), countBytes, bigEndian);
  for (const auto& [tag, type, value] : tags) {
    put(out, tag, 2, bigEndian);
    put(out, type, 2, bigEndian);
    put(out, 1, offsetBytes, bigEndian);                            // one value
    put(out, value, type == 3 ? 2 : 4, bigEndian);                  // left-justified in the value field
    out.append(static_cast<std::size_t>(offsetBytes - (type == 3 ? 2 : 4)), '\0');
  }
  put(out, 0, offsetBytes, bigEndian);  // no next directory
  return out;
}

}  // namespace fct::test
