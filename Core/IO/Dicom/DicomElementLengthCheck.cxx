#include "IO/Dicom/DicomElementLengthCheck.h"

#include <dcmtk/dcmdata/dctag.h>
#include <dcmtk/dcmdata/dcvr.h>
#include <dcmtk/dcmdata/dcxfer.h>
#include <fmt/core.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string_view>
#include <vector>

namespace fct {

namespace {

constexpr std::uint32_t kUndefinedLength = 0xFFFFFFFFu;
constexpr std::size_t kPreamble = 132;         // 128 bytes, then "DICM"
constexpr std::size_t kMetaBytesRead = 65536;  // the file meta information is a few hundred bytes

/// How a dataset's element headers are encoded.
struct Encoding {
  bool explicitVr = true;
  bool bigEndian = false;
};

std::uint16_t u16(const std::uint8_t* p, bool bigEndian) {
  return static_cast<std::uint16_t>(bigEndian ? (p[0] << 8) | p[1] : p[0] | (p[1] << 8));
}
std::uint32_t u32(const std::uint8_t* p, bool bigEndian) {
  const std::uint32_t first = u16(p, bigEndian), second = u16(p + 2, bigEndian);
  return bigEndian ? (first << 16) | second : first | (second << 16);
}

/// The VR named by the two bytes at p, as DCMTK's DcmVR reads it (an unknown name included).
DcmVR vrAt(const std::uint8_t* p) {
  const char name[3] = {static_cast<char>(p[0]), static_cast<char>(p[1]), '\0'};
  return DcmVR(name);
}

/// True when the two bytes name a VR whose explicit encoding has two reserved bytes and a 32-bit length, as DCMTK
/// decides it (an unknown VR included: DCMTK then assumes the form its DcmVR gives).
bool hasLongLength(const std::uint8_t* vr) { return vrAt(vr).usesExtendedLengthEncoding(); }

/// The encoding DCMTK guesses for a dataset without a (known) transfer syntax, from its first six bytes
/// (`DcmItem::checkTransferSyntax`): a VR in bytes 4-5 means explicit; a tag known only when byte-swapped, or a group
/// above 0x00FF that is at most 0x00FF swapped, means big endian.
Encoding guessedEncoding(const std::uint8_t* first6) {
  const bool explicitVr = std::isalpha(first6[4]) && std::isalpha(first6[5]) && vrAt(first6 + 4).isStandard();
  const DcmTag little(u16(first6, false), u16(first6 + 2, false)), big(u16(first6, true), u16(first6 + 2, true));
  const bool littleKnown = little.error().good(), bigKnown = big.error().good();
  bool bigEndian = false;
  if (littleKnown || bigKnown) {
    bigEndian = !littleKnown || (bigKnown && little.getGTag() > 0xFF && big.getGTag() <= 0xFF);
  }
  return Encoding{explicitVr, bigEndian};
}

/// A dataset's bytes read from the open file itself, skipping values without reading them.
class FileBytes {
 public:
  FileBytes(std::ifstream& file, std::uint64_t offset) : m_file(file) {
    m_file.clear();
    m_file.seekg(static_cast<std::streamoff>(offset));
  }
  /// Copies up to n bytes to out (or skips them when out is null); returns how many there were.
  std::uint64_t read(std::uint8_t* out, std::uint64_t n) {
    if (!out) {
      m_file.seekg(static_cast<std::streamoff>(n), std::ios::cur);  // the caller checked that n bytes follow
      return m_file ? n : 0;
    }
    m_file.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
    return static_cast<std::uint64_t>(m_file.gcount());
  }

 private:
  std::ifstream& m_file;
};

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

/// Walks the elements of a dataset of `total` bytes as DCMTK parses them (into sequences and items, over encapsulated
/// fragments; the items of an undefined-length UN in implicit VR little endian) and says which one declares more
/// bytes than follow it; empty when all fit or the walk ends early (DCMTK then reports what it finds). Byte positions
/// in the message count from `offset` of `where`.
template <class Bytes>
std::string firstOverlongElement(Bytes& stream, std::uint64_t total, Encoding base, std::uint64_t offset,
                                 std::string_view where) {
  std::uint64_t pos = 0;
  bool inFragments = false;        // inside an undefined-length OB/OW (encapsulated pixel data): items hold raw bytes
  std::vector<Encoding> sequences;  // the encoding inside each open undefined-length sequence, innermost last
  std::array<std::uint8_t, 12> h{};
  while (stream.read(h.data(), 8) == 8) {
    const Encoding e = sequences.empty() ? base : sequences.back();
    const std::uint16_t group = u16(h.data(), e.bigEndian), element = u16(h.data() + 2, e.bigEndian);
    std::uint32_t length = u32(h.data() + 4, e.bigEndian);  // items, delimiters and implicit VR: a 32-bit length
    std::uint64_t headerBytes = 8;
    bool sequence = false, pixelData = group == 0x7FE0 && element == 0x0010, unknownVr = false;
    if (group == 0xFFFE) {
      if (element == 0xE0DD) {  // sequence delimitation
        if (!sequences.empty()) sequences.pop_back();
        inFragments = false;
      }
    } else if (e.explicitVr) {
      const std::string_view vr(reinterpret_cast<const char*>(h.data() + 4), 2);
      length = u16(h.data() + 6, e.bigEndian);
      if (hasLongLength(h.data() + 4)) {
        if (stream.read(h.data() + 8, 4) != 4) return {};  // cut short: DCMTK reports the end as it finds it
        length = u32(h.data() + 8, e.bigEndian);
        headerBytes = 12;
      }
      sequence = vr == "SQ";
      unknownVr = vr == "UN";
      pixelData = pixelData || vr == "OB" || vr == "OW";
    } else {
      sequence = DcmTag(group, element).getEVR() == EVR_SQ;
    }
    pos += headerBytes;
    if (length == kUndefinedLength) {
      if (group == 0xFFFE) continue;  // an undefined-length item: its elements follow
      if (pixelData && !unknownVr) {
        inFragments = true;
        sequences.push_back(e);
      } else {
        // A sequence, or an undefined-length element DCMTK reads as one; a UN one holds implicit VR little endian.
        sequences.push_back(unknownVr ? Encoding{false, false} : e);
      }
      continue;
    }
    if (length > total - pos) {
      return fmt::format("element ({:04X},{:04X}) at byte {} of {} declares {} bytes, but only {} follow", group,
                         element, offset + pos - headerBytes, where, length, total - pos);
    }
    const bool container = group == 0xFFFE ? element == 0xE000 && !inFragments : sequence;
    if (!container) pos += stream.read(nullptr, length);  // a sequence's or item's elements follow its header
  }
  return {};
}

}  // namespace

Status DicomElementLengthCheck::check(const std::filesystem::path& path) {
  std::error_code ec;
  const std::uint64_t fileBytes = std::filesystem::file_size(path, ec);
  if (ec) return Ok{};  // the reader says the file cannot be read
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> bytes(kMetaBytesRead);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  const std::string name = path.filename().string();
  const bool part10 = bytes.size() >= kPreamble &&
                      std::string_view(reinterpret_cast<const char*>(bytes.data()) + 128, 4) == "DICM";
  // The file meta information (group 0002) is explicit VR little endian and never deflated; the dataset follows it.
  // Like DCMTK, read as many bytes as its group length (0002,0000) gives, whatever their tags, or else the elements
  // of group 0002.
  std::size_t pos = part10 ? kPreamble : 0;
  std::uint64_t metaEnd = 0;
  if (bytes.size() - pos >= 12 && u32(bytes.data() + pos, false) == 0x00000002u &&
      std::string_view(reinterpret_cast<const char*>(bytes.data()) + pos + 4, 2) == "UL" &&
      u16(bytes.data() + pos + 6, false) == 4) {
    metaEnd = pos + 12 + std::uint64_t{u32(bytes.data() + pos + 8, false)};
  }
  std::string syntax;
  while (bytes.size() - pos >= 12 && (metaEnd ? pos < metaEnd : u16(bytes.data() + pos, false) == 0x0002)) {
    const std::size_t headerBytes = hasLongLength(bytes.data() + pos + 4) ? 12 : 8;
    const std::uint32_t length =
        headerBytes == 12 ? u32(bytes.data() + pos + 8, false) : u16(bytes.data() + pos + 6, false);
    if (length > bytes.size() - pos - headerBytes) {  // beyond the file, or a meta information over 64 kB
      const std::uint64_t follow = fileBytes - pos - headerBytes;
      return fail(fmt::format("'{}' is a damaged DICOM file: element ({:04X},{:04X}) at byte {} of its file meta "
                              "information declares {} bytes, {} (truncated or corrupt file?)",
                              name, u16(bytes.data() + pos, false), u16(bytes.data() + pos + 2, false), pos, length,
                              length > follow ? fmt::format("but only {} follow", follow)
                                              : fmt::format("more than the {} kB a file meta information can hold",
                                                            kMetaBytesRead / 1024)));
    }
    if (u32(bytes.data() + pos, false) == 0x00100002u) {
      syntax.assign(reinterpret_cast<const char*>(bytes.data() + pos + headerBytes), length);
      while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' ')) syntax.pop_back();
    }
    pos += headerBytes + length;
  }
  if (bytes.size() - pos < 8) return Ok{};  // no dataset to speak of: DCMTK says what is wrong
  const DcmXfer xfer(syntax.c_str());
  const bool known = !syntax.empty() && xfer.getXfer() != EXS_Unknown;
  const Encoding encoding = known ? Encoding{xfer.isExplicitVR(), xfer.isBigEndian()} : guessedEncoding(&bytes[pos]);

  if (!known || xfer.getStreamCompression() != ESC_zlib) {
    FileBytes dataset(in, pos);
    const std::string problem = firstOverlongElement(dataset, fileBytes - pos, encoding, pos, "the file");
    if (problem.empty()) return Ok{};
    if (!part10) {
      return fail(fmt::format("'{}' is not a readable DICOM file: it has no DICOM preamble ('DICM' at byte 128), and "
                              "read as a bare dataset its {}",
                              name, problem));
    }
    return fail(fmt::format("'{}' is a damaged DICOM file: {} (truncated or corrupt file?)", name, problem));
  }
  bytes.insert(bytes.end(), std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  // Two passes over the inflated stream, neither holding it: its length, then its element headers.
  InflateStream counting(bytes, pos);
  const std::uint64_t total = counting.read(nullptr, UINT64_MAX);
  if (!counting.ok()) {
    return fail(fmt::format("'{}' is a damaged deflated DICOM file: its dataset does not inflate (truncated or "
                            "corrupt file?)",
                            name));
  }
  InflateStream walking(bytes, pos);
  if (const std::string problem = firstOverlongElement(walking, total, encoding, 0, "the inflated dataset");
      !problem.empty()) {
    return fail(fmt::format("'{}' is a damaged deflated DICOM file: {} (truncated or corrupt file?)", name, problem));
  }
  return Ok{};
}

}  // namespace fct
