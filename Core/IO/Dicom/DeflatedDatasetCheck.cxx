#include "IO/Dicom/DeflatedDatasetCheck.h"

#include <fmt/core.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string_view>
#include <vector>

namespace fct {

namespace {

// The transfer syntaxes DCMTK reads through zlib: Deflated Explicit VR Little Endian, JPIP Referenced Deflate.
constexpr std::array<std::string_view, 2> kDeflatedSyntaxUids{"1.2.840.10008.1.2.1.99", "1.2.840.10008.1.2.4.95"};
constexpr std::uint32_t kUndefinedLength = 0xFFFFFFFFu;
constexpr std::size_t kPreamble = 132;         // 128 bytes, then "DICM"
constexpr std::size_t kMetaBytesRead = 65536;  // the file meta information is a few hundred bytes

std::uint16_t u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
std::uint32_t u32(const std::uint8_t* p) { return std::uint32_t{u16(p)} | (std::uint32_t{u16(p + 2)} << 16); }

/// VRs whose explicit encoding has two reserved bytes and a 32-bit length (PS3.5 7.1.2).
bool hasLongLength(std::string_view vr) {
  static constexpr std::array<std::string_view, 13> kLong{"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                                          "SV", "UC", "UN", "UR", "UT", "UV"};
  return std::find(kLong.begin(), kLong.end(), vr) != kLong.end();
}

/// The raw deflate stream (no zlib header) of a Deflated transfer syntax file, inflated a little at a time.
class InflateStream {
 public:
  InflateStream(const std::vector<std::uint8_t>& file, std::size_t offset) {
    m_ok = inflateInit2(&m_z, -MAX_WBITS) == Z_OK;
    m_z.next_in = const_cast<Bytef*>(file.data() + offset);
    m_z.avail_in = static_cast<uInt>(std::min<std::size_t>(file.size() - offset, UINT32_MAX));
  }
  ~InflateStream() { inflateEnd(&m_z); }
  InflateStream(const InflateStream&) = delete;
  InflateStream& operator=(const InflateStream&) = delete;

  /// Copies up to n inflated bytes to out (or drops them when out is null); returns how many there were.
  std::uint64_t read(std::uint8_t* out, std::uint64_t n) {
    std::uint64_t done = 0;
    while (done < n && (m_next < m_end || fill())) {
      const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(n - done, m_end - m_next));
      if (out) std::copy(m_chunk.data() + m_next, m_chunk.data() + m_next + take, out + done);
      m_next += take;
      done += take;
    }
    return done;
  }
  /// False when the stream is not valid deflate data (a stream that is merely cut short is valid as far as it goes).
  bool ok() const { return m_ok; }

 private:
  /// Inflates the next chunk; false at the end of the stream or of the file, or on damaged data.
  bool fill() {
    while (m_ok && !m_ended) {
      m_z.next_out = m_chunk.data();
      m_z.avail_out = static_cast<uInt>(m_chunk.size());
      const int status = inflate(&m_z, Z_NO_FLUSH);
      m_ended = status == Z_STREAM_END || status == Z_BUF_ERROR;  // Z_BUF_ERROR: no input left, the file is short
      m_ok = status == Z_OK || m_ended;
      m_next = 0;
      m_end = m_chunk.size() - m_z.avail_out;
      if (m_end > 0) return true;
    }
    return false;
  }

  z_stream m_z{};
  std::array<std::uint8_t, 65536> m_chunk{};
  std::size_t m_next = 0, m_end = 0;
  bool m_ok = false, m_ended = false;
};

/// Walks the explicit VR little endian elements of an inflated dataset of `total` bytes (into sequences and items,
/// over encapsulated fragments) and says which one declares more bytes than follow it; empty when all fit.
std::string firstOverlongElement(InflateStream& stream, std::uint64_t total) {
  std::uint64_t pos = 0;
  bool inFragments = false;  // inside an undefined-length OB/OW (encapsulated pixel data): items hold raw bytes
  std::array<std::uint8_t, 12> h{};
  while (stream.read(h.data(), 8) == 8) {
    const std::uint16_t group = u16(h.data()), element = u16(h.data() + 2);
    const std::string_view vr(reinterpret_cast<const char*>(h.data() + 4), 2);
    std::uint32_t length = u32(h.data() + 4);  // items and delimitation items: tag and a 32-bit length, no VR
    std::uint64_t headerBytes = 8;
    if (group != 0xFFFE) {
      if (vr[0] < 'A' || vr[0] > 'Z' || vr[1] < 'A' || vr[1] > 'Z') {
        return fmt::format("the element at byte {} of the inflated dataset has no valid value representation", pos);
      }
      length = u16(h.data() + 6);
      if (hasLongLength(vr)) {
        if (stream.read(h.data() + 8, 4) != 4) return {};  // cut short: DCMTK reports the end as it finds it
        length = u32(h.data() + 8);
        headerBytes = 12;
      }
    } else if (element == 0xE0DD) {
      inFragments = false;  // sequence delimitation
    }
    pos += headerBytes;
    if (length == kUndefinedLength) {
      if (group != 0xFFFE && vr == "UN") return {};  // its items are implicit VR, which this walk does not follow
      if (group != 0xFFFE && (vr == "OB" || vr == "OW")) inFragments = true;
      continue;
    }
    if (length > total - pos) {
      return fmt::format("element ({:04X},{:04X}) at byte {} of the inflated dataset declares {} bytes, but only {} "
                         "follow",
                         group, element, pos - headerBytes, length, total - pos);
    }
    const bool container = group == 0xFFFE ? element == 0xE000 && !inFragments : vr == "SQ";
    if (!container) pos += stream.read(nullptr, length);  // a sequence's or item's elements follow its header
  }
  return {};
}

}  // namespace

Status DeflatedDatasetCheck::check(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> bytes(kMetaBytesRead);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  if (bytes.size() < kPreamble || std::string_view(reinterpret_cast<const char*>(bytes.data()) + 128, 4) != "DICM") {
    return Ok{};  // not a Part 10 file: no file meta information, so not deflated
  }
  // The file meta information (group 0002) is explicit VR little endian and never deflated; the dataset follows it.
  std::size_t pos = kPreamble;
  std::string syntax;
  while (bytes.size() - pos >= 12 && u16(bytes.data() + pos) == 0x0002) {
    const std::string_view vr(reinterpret_cast<const char*>(bytes.data() + pos + 4), 2);
    const std::size_t headerBytes = hasLongLength(vr) ? 12 : 8;
    const std::uint32_t length = headerBytes == 12 ? u32(bytes.data() + pos + 8) : u16(bytes.data() + pos + 6);
    if (length > bytes.size() - pos - headerBytes) break;  // DCMTK says what is wrong with this meta information
    if (u16(bytes.data() + pos + 2) == 0x0010) {
      syntax.assign(reinterpret_cast<const char*>(bytes.data() + pos + headerBytes), length);
      while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' ')) syntax.pop_back();
    }
    pos += headerBytes + length;
  }
  if (std::find(kDeflatedSyntaxUids.begin(), kDeflatedSyntaxUids.end(), syntax) == kDeflatedSyntaxUids.end()) {
    return Ok{};
  }
  bytes.insert(bytes.end(), std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  const std::string name = path.filename().string();
  // Two passes over the inflated stream, neither holding it: its length, then its element headers.
  InflateStream counting(bytes, pos);
  const std::uint64_t total = counting.read(nullptr, UINT64_MAX);
  if (!counting.ok()) {
    return fail(fmt::format("'{}' is a damaged deflated DICOM file: its dataset does not inflate (truncated or "
                            "corrupt file?)",
                            name));
  }
  InflateStream walking(bytes, pos);
  if (const std::string problem = firstOverlongElement(walking, total); !problem.empty()) {
    return fail(fmt::format("'{}' is a damaged deflated DICOM file: {} (truncated or corrupt file?)", name, problem));
  }
  return Ok{};
}

}  // namespace fct
