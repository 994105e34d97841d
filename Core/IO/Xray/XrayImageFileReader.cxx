#include "IO/Xray/XrayImageFileReader.h"

#include <fmt/core.h>

#include "IO/Xray/PngCodec.h"
#include "IO/Xray/TiffCodec.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <optional>

namespace fct {

namespace {

/// True when the file starts with the signature of its format (PNG: 89 'PNG' 0D 0A 1A 0A; TIFF: "II*\0", "MM\0*", or
/// BigTIFF "II+\0", "MM\0+"), so that a file under the wrong name gets an error that says so.
bool hasSignature(std::ifstream& file, const std::string& modality) {
  char head[8] = {};
  file.read(head, sizeof head);
  const std::string bytes(head, static_cast<std::size_t>(file.gcount()));
  if (modality == "PNG") return bytes == std::string("\x89PNG\r\n\x1a\n", 8);
  const std::string first4 = bytes.substr(0, 4);
  for (const char* tiff : {"II*\0", "MM\0*", "II+\0", "MM\0+"}) {
    if (first4 == std::string(tiff, 4)) return true;
  }
  return false;
}

/// The largest image FluoroCT decodes: more than any X-ray detector (a 43 cm flat panel at 0.1 mm is 4300 pixels a
/// side). A decoder allocates the whole image its header declares before it decodes a byte, so a damaged header would
/// otherwise ask for gigabytes.
constexpr std::uint32_t kMaxImageSide = 16384;
constexpr std::uint64_t kMaxImagePixels = std::uint64_t{1} << 25;  // 33.5 million: 5792 x 5792
/// The largest file read into memory for decoding: the largest image as uncompressed float32 RGBA (512 MiB) with room
/// for the file's own structure. A larger file is not an X-ray image of an accepted size, whatever its header says.
constexpr std::uint64_t kMaxFileBytes = std::uint64_t{1} << 30;

/// Width and height in pixels as an image file's header declares them.
struct DeclaredSize {
  std::uint64_t cols = 0, rows = 0;
};

/// Reads an unsigned integer of `bytes` bytes (1 to 8) at `offset`, in the file's byte order; nullopt past the end.
std::optional<std::uint64_t> readUnsigned(std::ifstream& file, std::uint64_t offset, int bytes, bool bigEndian) {
  unsigned char b[8] = {};
  file.clear();
  file.seekg(static_cast<std::streamoff>(offset));
  if (!file.read(reinterpret_cast<char*>(b), bytes)) return std::nullopt;
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value |= std::uint64_t{b[bigEndian ? bytes - 1 - i : i]} << (8 * i);
  return value;
}

/// The size in the IHDR chunk of a PNG (big-endian width and height at bytes 16 and 20).
std::optional<DeclaredSize> pngDeclaredSize(std::ifstream& file) {
  const auto cols = readUnsigned(file, 16, 4, true), rows = readUnsigned(file, 20, 4, true);
  if (!cols || !rows) return std::nullopt;
  return DeclaredSize{*cols, *rows};
}

/// The ImageWidth (256) and ImageLength (257) of a TIFF's first directory, classic or BigTIFF; nullopt when the
/// directory cannot be read or lacks either tag (libtiff then reports the file itself).
std::optional<DeclaredSize> tiffDeclaredSize(std::ifstream& file) {
  const auto order = readUnsigned(file, 0, 2, false);
  if (!order) return std::nullopt;
  const bool big = *order == 0x4D4D;  // "MM"
  const bool bigTiff = readUnsigned(file, 2, 2, big) == 43u;  // 42: classic (hasSignature checked it is one of the two)
  // Classic: a 4-byte directory offset, a 2-byte entry count, 12-byte entries (tag, type, 4-byte count, 4-byte value);
  // BigTIFF: 8, 8 and 20 (8-byte count and value).
  const int offsetBytes = bigTiff ? 8 : 4, countBytes = bigTiff ? 8 : 2, entryBytes = bigTiff ? 20 : 12;
  const auto directory = readUnsigned(file, bigTiff ? 8 : 4, offsetBytes, big);
  if (!directory) return std::nullopt;
  const auto entries = readUnsigned(file, *directory, countBytes, big);
  if (!entries) return std::nullopt;
  std::optional<std::uint64_t> cols, rows;
  for (std::uint64_t i = 0; i < std::min<std::uint64_t>(*entries, 4096) && !(cols && rows); ++i) {
    const std::uint64_t entry = *directory + countBytes + i * entryBytes;
    const auto tag = readUnsigned(file, entry, 2, big), type = readUnsigned(file, entry + 2, 2, big);
    if (!tag || !type) return std::nullopt;
    if (*tag != 256 && *tag != 257) continue;
    const int valueBytes = *type == 3 ? 2 : *type == 4 ? 4 : *type == 16 ? 8 : 0;  // SHORT, LONG, LONG8
    if (valueBytes == 0) continue;
    const auto value = readUnsigned(file, entry + 4 + offsetBytes, valueBytes, big);
    (*tag == 256 ? cols : rows) = value;
  }
  if (!cols || !rows) return std::nullopt;
  return DeclaredSize{*cols, *rows};
}

/// The grey image of a decoded raster: channel 0 of grey (+ alpha) and of RGB(A) whose channels agree everywhere,
/// otherwise luma 0.299 R + 0.587 G + 0.114 B (rounded to the nearest integer for integer samples). Says in
/// `warnings` what it dropped or converted.
std::vector<float> greyOf(const DecodedRaster& raster, const std::string& name, std::vector<std::string>& warnings) {
  const auto pixels = static_cast<std::size_t>(raster.cols) * raster.rows;
  const auto step = static_cast<std::size_t>(raster.channels);
  const float* in = raster.samples.data();
  if (raster.channels == 2 || raster.channels == 4) warnings.push_back(fmt::format("'{}': alpha channel ignored", name));
  bool sameChannels = raster.channels < 3;
  if (!sameChannels) {
    sameChannels = true;
    for (std::size_t n = 0; n < pixels && sameChannels; ++n) {
      sameChannels = in[n * step] == in[n * step + 1] && in[n * step + 1] == in[n * step + 2];
    }
  }
  std::vector<float> grey(pixels);
  if (sameChannels) {
    for (std::size_t n = 0; n < pixels; ++n) grey[n] = in[n * step];
    return grey;
  }
  const bool integer = raster.sampleType != RasterSampleType::Float32;
  for (std::size_t n = 0; n < pixels; ++n) {
    const double luma = 0.299 * in[n * step] + 0.587 * in[n * step + 1] + 0.114 * in[n * step + 2];
    grey[n] = static_cast<float>(integer ? std::round(luma) : luma);
  }
  warnings.push_back(
      fmt::format("'{}' is a colour image; converted to grey (luma 0.299 R + 0.587 G + 0.114 B)", name));
  return grey;
}

}  // namespace

Result<XrayImage> XrayImageFileReader::read(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string modality;
  if (extension == ".png") {
    modality = "PNG";
  } else if (extension == ".tif" || extension == ".tiff") {
    modality = "TIFF";
  } else {
    return fail(fmt::format("'{}' is not a PNG or TIFF file (extension '{}'); DICOM X-rays go through the DICOM reader",
                            path.filename().string(), extension));
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail(fmt::format("X-ray file '{}' does not exist", path.string()));

  std::ifstream header(path, std::ios::binary);
  if (!hasSignature(header, modality)) {
    return fail(fmt::format("'{}' is not a {} file: it does not start with the {} signature (damaged, or another format "
                            "under a .{} name)",
                            path.filename().string(), modality, modality, extension.substr(1)));
  }
  if (const auto size = modality == "PNG" ? pngDeclaredSize(header) : tiffDeclaredSize(header);
      size && (size->cols > kMaxImageSide || size->rows > kMaxImageSide || size->cols * size->rows > kMaxImagePixels)) {
    return fail(fmt::format("'{}' declares an image of {} x {} pixels; FluoroCT reads X-ray images of at most {} pixels "
                            "a side and {} pixels in all (a damaged file, or not an X-ray image?)",
                            path.filename().string(), size->cols, size->rows, kMaxImageSide, kMaxImagePixels));
  }
  const std::uintmax_t fileBytes = std::filesystem::file_size(path, ec);
  if (ec || fileBytes > kMaxFileBytes) {
    return fail(ec ? fmt::format("cannot read '{}': {}", path.string(), ec.message())
                   : fmt::format("'{}' is {} bytes, more than any X-ray image FluoroCT reads ({} bytes at most; a damaged "
                                 "file, or not an X-ray image?)",
                                 path.filename().string(), fileBytes, kMaxFileBytes));
  }
  header.clear();
  header.seekg(0);
  std::string bytes(static_cast<std::size_t>(fileBytes), '\0');
  if (!header.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) {
    return fail(fmt::format("cannot read '{}': the file could not be read to its end", path.string()));
  }
  const std::string name = path.filename().string();
  auto raster = modality == "PNG" ? PngCodec::decode(bytes, kMaxImageSide, kMaxImagePixels)
                                  : TiffCodec::decode(bytes, kMaxImageSide, kMaxImagePixels);
  if (!raster) return fail(fmt::format("cannot read '{}': {}", name, raster.error()));
  const DecodedRaster& decoded = raster.value();
  std::vector<std::string> warnings;
  for (const std::string& note : decoded.notes) warnings.push_back(fmt::format("'{}': {}", name, note));

  XrayImage image;
  image.bitsStored = decoded.sampleType == RasterSampleType::UInt8 ? 8 : decoded.sampleType == RasterSampleType::UInt16 ? 16 : 32;
  image.cols = decoded.cols;
  image.rows = decoded.rows;
  image.photometric = "MONOCHROME2";
  image.modality = modality;
  image.sourcePath = path.string();
  image.pixels = greyOf(decoded, name, warnings);
  if (!std::all_of(image.pixels.begin(), image.pixels.end(), [](float v) { return std::isfinite(v); })) {
    return fail(fmt::format("'{}' contains NaN or infinite pixel values", path.filename().string()));
  }
  Result<XrayImage> result(std::move(image));
  for (auto& w : warnings) result.addWarning(std::move(w));
  return result;
}

}  // namespace fct
