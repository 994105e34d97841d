#include "IO/Xray/ImageFileWriter.h"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
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

/// Runs `write` on a temporary file beside `path` (same extension, so format-by-extension encoders work), then
/// renames it into place; removes the temporary file on failure.
Status writeAtomically(const std::filesystem::path& path, const std::function<Status(const std::filesystem::path&)>& write) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    return fail(fmt::format("cannot write '{}': folder '{}' does not exist", path.string(), folder.string()));
  }
  const std::filesystem::path temp =
      folder / fmt::format(".{}.tmp{}{}", path.stem().string(), ::getpid(), path.extension().string());
  Status status = Ok{};
  try {
    status = write(temp);
  } catch (const cv::Exception& e) {
    status = fail(fmt::format("cannot write '{}': {}", path.string(), e.what()));
  }
  if (status) {
    std::filesystem::rename(temp, path, ec);
    if (ec) status = fail(fmt::format("cannot write '{}': {}", path.string(), ec.message()));
  }
  if (!status) std::filesystem::remove(temp, ec);
  return status;
}

Status writeBinary(const std::filesystem::path& temp, const std::filesystem::path& path, const std::string& header,
                   const FloatImage& image, bool bottomUp) {
  std::ofstream out(temp, std::ios::binary | std::ios::trunc);
  out << header;
  const auto rowBytes = static_cast<std::streamsize>(sizeof(float) * static_cast<std::size_t>(image.cols));
  for (int r = 0; r < image.rows; ++r) {
    const int row = bottomUp ? image.rows - 1 - r : r;
    out.write(reinterpret_cast<const char*>(image.pixels.data() + static_cast<std::size_t>(row) * image.cols), rowBytes);
  }
  out.close();
  if (!out) return fail(fmt::format("cannot write '{}': disk full or not writable", path.string()));
  return Ok{};
}

Status imwriteStatus(const std::filesystem::path& temp, const std::filesystem::path& path, const cv::Mat& mat) {
  if (!cv::imwrite(temp.string(), mat)) {
    return fail(fmt::format("cannot write '{}': OpenCV's encoder refused it (folder not writable?)", path.string()));
  }
  return Ok{};
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
  return writeAtomically(path, [&](const std::filesystem::path& temp) {
    return writeBinary(temp, path, header, image, /*bottomUp=*/true);
  });
}

Status ImageFileWriter::writeTiff(const FloatImage& image, const std::filesystem::path& path) {
  if (Status ok = checkImage(image, path); !ok) return ok;
  return writeAtomically(path, [&](const std::filesystem::path& temp) { return imwriteStatus(temp, path, wrap(image)); });
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
  return writeAtomically(path, [&](const std::filesystem::path& temp) { return imwriteStatus(temp, path, png); });
}

Status ImageFileWriter::writePngRgb(const RgbImage& image, const std::filesystem::path& path) {
  if (image.cols <= 0 || image.rows <= 0 || image.pixels.size() != 3 * static_cast<std::size_t>(image.cols) * image.rows) {
    return fail(fmt::format("cannot write '{}': colour image is empty or inconsistent ({} x {} with {} bytes)",
                            path.filename().string(), image.cols, image.rows, image.pixels.size()));
  }
  cv::Mat bgr;
  cv::cvtColor(cv::Mat(image.rows, image.cols, CV_8UC3, const_cast<std::uint8_t*>(image.pixels.data())), bgr,
               cv::COLOR_RGB2BGR);
  return writeAtomically(path, [&](const std::filesystem::path& temp) { return imwriteStatus(temp, path, bgr); });
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
  return writeAtomically(path, [&](const std::filesystem::path& temp) {
    return writeBinary(temp, path, header, image, /*bottomUp=*/false);
  });
}

}  // namespace fct
