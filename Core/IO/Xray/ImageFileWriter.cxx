#include "IO/Xray/ImageFileWriter.h"

#include "Base/AtomicFile.h"
#include "IO/Xray/PngCodec.h"
#include "IO/Xray/TiffCodec.h"

#include <fmt/core.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace fct {

namespace {

Status checkImage(const FloatImage& image, const std::filesystem::path& path) {
  if (image.cols <= 0 || image.rows <= 0 || image.pixels.size() != static_cast<std::size_t>(image.cols) * image.rows) {
    return fail(fmt::format("cannot write '{}': image is empty or inconsistent ({} x {} with {} pixels)",
                            path.filename().string(), image.cols, image.rows, image.pixels.size()));
  }
  return Ok{};
}

/// The pixel bytes after `header`, rows top to bottom or (PFM) bottom to top.
std::string rawBytes(const std::string& header, const FloatImage& image, bool bottomUp) {
  std::string bytes = header;
  const std::size_t rowBytes = sizeof(float) * static_cast<std::size_t>(image.cols);
  bytes.reserve(header.size() + rowBytes * static_cast<std::size_t>(image.rows));
  for (int r = 0; r < image.rows; ++r) {
    const int row = bottomUp ? image.rows - 1 - r : r;
    bytes.append(reinterpret_cast<const char*>(image.pixels.data() + static_cast<std::size_t>(row) * image.cols),
                 rowBytes);
  }
  return bytes;
}

/// Writes encoded bytes (or the encoder's error, naming `path`) with AtomicFile.
Status writeEncoded(const std::filesystem::path& path, const Result<std::string>& encoded) {
  if (!encoded) return fail(fmt::format("cannot write '{}': {}", path.string(), encoded.error()));
  return AtomicFile::write(path, {encoded.value()});
}

}  // namespace

static_assert(sizeof(float) == 4 && std::endian::native == std::endian::little,
              "the PFM and NRRD writers write native floats and declare them little-endian float32");

Status ImageFileWriter::writePfm(const FloatImage& image, const std::filesystem::path& path) {
  if (Status ok = checkImage(image, path); !ok) return ok;
  const std::string header = fmt::format("Pf\n{} {}\n-1.0\n", image.cols, image.rows);  // negative scale: little endian
  return AtomicFile::write(path, {rawBytes(header, image, /*bottomUp=*/true)});
}

Status ImageFileWriter::writeTiff(const FloatImage& image, const std::filesystem::path& path) {
  if (Status ok = checkImage(image, path); !ok) return ok;
  return writeEncoded(path, TiffCodec::encodeFloat32(image.pixels.data(), image.cols, image.rows));
}

Status ImageFileWriter::writePng16(const FloatImage& image, const std::filesystem::path& path, float windowMin,
                                   float windowMax) {
  if (Status ok = checkImage(image, path); !ok) return ok;
  if (!std::isfinite(windowMin) || !std::isfinite(windowMax) || !(windowMin < windowMax)) {
    return fail(fmt::format("cannot write '{}': window {} .. {} must be finite with min < max", path.string(), windowMin,
                            windowMax));
  }
  std::vector<std::uint16_t> grey(image.pixels.size());
  const double scale = 65535.0 / (static_cast<double>(windowMax) - windowMin);
  std::transform(image.pixels.begin(), image.pixels.end(), grey.begin(), [&](float v) {
    const double mapped = std::isnan(v) ? 0.0 : std::clamp((v - windowMin) * scale, 0.0, 65535.0);
    return static_cast<std::uint16_t>(std::lround(mapped));
  });
  return writeEncoded(path, PngCodec::encodeGrey16(grey.data(), image.cols, image.rows));
}

Status ImageFileWriter::writePngRgb(const RgbImage& image, const std::filesystem::path& path) {
  if (image.cols <= 0 || image.rows <= 0 || image.pixels.size() != 3 * static_cast<std::size_t>(image.cols) * image.rows) {
    return fail(fmt::format("cannot write '{}': colour image is empty or inconsistent ({} x {} with {} bytes)",
                            path.filename().string(), image.cols, image.rows, image.pixels.size()));
  }
  return writeEncoded(path, PngCodec::encodeRgb8(image.pixels.data(), image.cols, image.rows));
}

Status ImageFileWriter::writeNrrd2d(const FloatImage& image, const std::filesystem::path& path,
                                    const Eigen::Vector2d& pixelSpacing_mm) {
  if (Status ok = checkImage(image, path); !ok) return ok;
  if (!pixelSpacing_mm.allFinite() || (pixelSpacing_mm.array() <= 0.0).any()) {
    return fail(fmt::format("cannot write '{}': pixel spacing {} x {} mm must be positive", path.string(),
                            pixelSpacing_mm.x(), pixelSpacing_mm.y()));
  }
  const std::string header = fmt::format(
      "NRRD0004\n# written by FluoroCT\ntype: float\ndimension: 2\nsizes: {} {}\nspacings: {} {}\nendian: little\n"
      "encoding: raw\n\n",
      image.cols, image.rows, pixelSpacing_mm.x(), pixelSpacing_mm.y());
  return AtomicFile::write(path, {rawBytes(header, image, /*bottomUp=*/false)});
}

}  // namespace fct
