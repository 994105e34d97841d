#pragma once
// DamagedDicom: byte-level edits of DICOM files (element lengths, raw elements, the deflated dataset), for the DICOM
// reader tests and the fuzz seeds that keep the inputs of fixed reader defects.

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace fct::test {

using Bytes = std::vector<std::uint8_t>;

/// Raw deflate (no zlib header) or inflate of bytes, as the Deflated transfer syntax stores its dataset; empty when
/// the data does not inflate.
inline Bytes rawDeflate(const Bytes& in, bool compress) {
  z_stream z{};
  if ((compress ? deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY)
                : inflateInit2(&z, -MAX_WBITS)) != Z_OK) {
    return {};
  }
  Bytes out;
  std::array<std::uint8_t, 4096> chunk{};
  z.next_in = const_cast<Bytef*>(in.data());
  z.avail_in = static_cast<uInt>(in.size());
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = chunk.data();
    z.avail_out = static_cast<uInt>(chunk.size());
    status = compress ? deflate(&z, Z_FINISH) : inflate(&z, Z_NO_FLUSH);
    out.insert(out.end(), chunk.data(), chunk.data() + (chunk.size() - z.avail_out));
  }
  compress ? deflateEnd(&z) : inflateEnd(&z);
  return status == Z_STREAM_END ? out : Bytes{};
}

/// Where the dataset of a Part 10 file written by DCMTK starts: after the preamble and "DICM" (132 bytes) comes
/// (0002,0000) UL, whose 4-byte value is the length of the rest of group 0002.
inline std::size_t datasetStart(const Bytes& bytes) {
  return 144 + (bytes[140] | bytes[141] << 8 | bytes[142] << 16 | std::size_t{bytes[143]} << 24);
}

/// Where `pattern` first starts in bytes, or bytes.size() when it does not occur.
inline std::size_t find(const Bytes& bytes, const Bytes& pattern) {
  return static_cast<std::size_t>(std::search(bytes.begin(), bytes.end(), pattern.begin(), pattern.end()) -
                                  bytes.begin());
}

/// Writes a 32-bit value at `at` in the given byte order.
inline void putU32(Bytes& bytes, std::size_t at, std::uint32_t value, bool bigEndian = false) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<std::uint8_t>(value >> (8 * (bigEndian ? 3 - i : i)));
}

/// An element header and value in implicit VR little endian: tag, 32-bit length, value.
inline Bytes implicitElement(std::uint16_t group, std::uint16_t element, std::uint32_t length,
                             const Bytes& value = {}) {
  Bytes out(8 + value.size());
  out[0] = static_cast<std::uint8_t>(group);
  out[1] = static_cast<std::uint8_t>(group >> 8);
  out[2] = static_cast<std::uint8_t>(element);
  out[3] = static_cast<std::uint8_t>(element >> 8);
  putU32(out, 4, length);
  std::copy(value.begin(), value.end(), out.begin() + 8);
  return out;
}

/// The header of Pixel Data (7FE0,0010) OW as explicit VR little endian writes it (its length follows at +8).
inline const Bytes kExplicitPixelDataHeader{0xE0, 0x7F, 0x10, 0x00, 'O', 'W'};

/// A deflated Part 10 file with `edit` applied to its inflated dataset, deflated again; empty when it does not
/// inflate.
template <class Edit>
Bytes withDeflatedDatasetEdited(const Bytes& file, Edit edit) {
  const std::size_t start = datasetStart(file);
  Bytes dataset = rawDeflate(Bytes(file.begin() + static_cast<std::ptrdiff_t>(start), file.end()), false);
  if (dataset.empty()) return {};
  edit(dataset);
  Bytes out(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(start));
  const Bytes again = rawDeflate(dataset, true);
  out.insert(out.end(), again.begin(), again.end());
  return out;
}

}  // namespace fct::test
