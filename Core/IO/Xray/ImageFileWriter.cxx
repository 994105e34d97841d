#include "IO/Xray/ImageFileWriter.h"

#include "Base/AtomicFile.h"

#include <fmt/core.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

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

/// Encodes `mat` in the format of `path`'s extension in memory, then writes it with AtomicFile.
Status encodeAndWrite(const std::filesystem::path& path, const cv::Mat& mat) {
  std::vector<unsigned char> encoded;
  try {
    if (!cv::imencode(path.extension().string(), mat, encoded)) {
      return fail(fmt::format("cannot write '{}': OpenCV's encoder refused the image", path.string()));
    }
  } catch (const cv::Exception& e) {
    return fail(fmt::format("cannot write '{}': {}", path.string(), e.what()));
  }
  return AtomicFile::write(path, {AtomicFile::bytesOf(encoded.data(), encoded.size())});
}

cv::Mat wrap(const FloatImage& image) {
  return cv::Mat(image.rows, image.cols, CV_32F, const_cast<float*>(image.pixels.data()));  // read-only use
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
  return encodeAndWrite(path, wrap(image));
}

Status ImageFileWriter::writePng16(const FloatImage& image, const std::filesystem::path& path, float windowMin,
                                   float windowMax) {
  if (Status ok = checkImage(image, path); !ok) return ok;
  if (!std::isfinite(windowMin) || !std::isfinite(windowMax) || !(windowMin < windowMax)) {
    return fail(fmt::format("cannot write '{}': window {} .. {} must be finite with min < max", path.string(), windowMin,
                            windowMax));
  }
  cv::Mat png(image.rows, image.cols, CV_16U);
  const double scale = 65535.0 / (static_cast<double>(windowMax) - windowMin);
  for (int r = 0; r < image.rows; ++r) {
    auto* out = png.ptr<std::uint16_t>(r);
    for (int c = 0; c < image.cols; ++c) {
      const float v = image.at(c, r);
      const double mapped = std::isnan(v) ? 0.0 : std::clamp((v - windowMin) * scale, 0.0, 65535.0);
      out[c] = static_cast<std::uint16_t>(std::lround(mapped));
    }
  }
  return encodeAndWrite(path, png);
}

Status ImageFileWriter::writePngRgb(const RgbImage& image, const std::filesystem::path& path) {
  if (image.cols <= 0 || image.rows <= 0 || image.pixels.size() != 3 * static_cast<std::size_t>(image.cols) * image.rows) {
    return fail(fmt::format("cannot write '{}': colour image is empty or inconsistent ({} x {} with {} bytes)",
                            path.filename().string(), image.cols, image.rows, image.pixels.size()));
  }
  cv::Mat bgr;
  cv::cvtColor(cv::Mat(image.rows, image.cols, CV_8UC3, const_cast<std::uint8_t*>(image.pixels.data())), bgr,
               cv::COLOR_RGB2BGR);
  return encodeAndWrite(path, bgr);
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
