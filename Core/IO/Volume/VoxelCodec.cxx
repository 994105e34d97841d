#include "IO/Volume/VoxelCodec.h"

#include <fmt/core.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>

namespace fct {
namespace {

template <typename T>
void convert(const char* bytes, std::size_t count, bool swap, float* out) {
  for (std::size_t n = 0; n < count; ++n) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, bytes + n * sizeof(T), sizeof(T));
    if (swap) std::reverse(raw, raw + sizeof(T));
    T value;
    std::memcpy(&value, raw, sizeof(T));
    out[n] = static_cast<float>(value);
  }
}

}  // namespace

std::size_t VoxelCodec::bytesPerScalar(ScalarType type) {
  switch (type) {
    case ScalarType::UInt8:
    case ScalarType::Int8: return 1;
    case ScalarType::UInt16:
    case ScalarType::Int16: return 2;
    case ScalarType::UInt32:
    case ScalarType::Int32:
    case ScalarType::Float32: return 4;
    case ScalarType::Float64: return 8;
  }
  return 0;
}

const char* VoxelCodec::name(ScalarType type) {
  switch (type) {
    case ScalarType::UInt8: return "uint8";
    case ScalarType::Int8: return "int8";
    case ScalarType::UInt16: return "uint16";
    case ScalarType::Int16: return "int16";
    case ScalarType::UInt32: return "uint32";
    case ScalarType::Int32: return "int32";
    case ScalarType::Float32: return "float32";
    case ScalarType::Float64: return "float64";
  }
  return "unknown";
}

Result<std::size_t> VoxelCodec::voxelCount(const Eigen::Vector3i& dims, const std::string& source) {
  if ((dims.array() <= 0).any()) {
    return fail(fmt::format("{}: volume dimensions must be positive, got {}x{}x{}", source, dims.x(), dims.y(), dims.z()));
  }
  const std::size_t count = static_cast<std::size_t>(dims.x()) * static_cast<std::size_t>(dims.y()) *
                            static_cast<std::size_t>(dims.z());
  constexpr std::size_t kMaxVoxels = std::size_t{1} << 32;
  if (count > kMaxVoxels) {
    return fail(fmt::format("{}: {}x{}x{} voxels is more than this program handles (4 Gi voxels); crop or downsample",
                            source, dims.x(), dims.y(), dims.z()));
  }
  return count;
}

Result<std::string> VoxelCodec::readFile(const std::filesystem::path& path) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) {
    return fail(fmt::format("cannot open '{}': {}", path.string(), std::strerror(errno)));
  }
  std::string content;
  char buffer[1 << 16];
  int got = 0;
  while ((got = gzread(file, buffer, sizeof(buffer))) > 0) content.append(buffer, static_cast<std::size_t>(got));
  int code = Z_OK;
  const std::string zerror = got < 0 ? gzerror(file, &code) : "";
  gzclose(file);
  if (got < 0) {
    return fail(fmt::format("cannot read '{}': {} (is the file truncated or not really gzip?)", path.string(), zerror));
  }
  return content;
}

Result<std::string> VoxelCodec::inflate(std::string_view compressed, std::size_t expected_bytes) {
  std::string out(expected_bytes, '\0');
  z_stream stream{};
  if (inflateInit2(&stream, 15 + 32) != Z_OK) return fail("zlib could not start decompressing");  // 15+32: zlib or gzip
  std::size_t produced = 0;
  std::size_t consumed = 0;
  int code = Z_OK;
  // zlib counts in uInt; feed and drain in chunks so that volumes above 4 GB work too.
  constexpr std::size_t kChunk = 1u << 30;
  while (code == Z_OK && produced < expected_bytes) {
    stream.avail_in = static_cast<uInt>(std::min(kChunk, compressed.size() - consumed));
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + consumed));
    stream.avail_out = static_cast<uInt>(std::min(kChunk, expected_bytes - produced));
    stream.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
    const uInt inBefore = stream.avail_in;
    const uInt outBefore = stream.avail_out;
    code = ::inflate(&stream, Z_NO_FLUSH);
    consumed += inBefore - stream.avail_in;
    produced += outBefore - stream.avail_out;
    if (code == Z_BUF_ERROR) {  // no progress possible: the input ran out before the expected size
      const bool stuck = inBefore == stream.avail_in && outBefore == stream.avail_out;
      code = Z_OK;
      if (stuck) break;
    }
  }
  inflateEnd(&stream);
  if (code != Z_OK && code != Z_STREAM_END) {
    return fail(fmt::format("compressed voxel data is corrupt ({}); the file is damaged",
                            stream.msg ? stream.msg : "zlib error"));
  }
  if (produced < expected_bytes) {
    return fail(fmt::format("compressed voxel data ends early: {} of {} bytes; the file is truncated", produced,
                            expected_bytes));
  }
  return out;
}

std::vector<float> VoxelCodec::toFloat(std::string_view bytes, std::size_t count, ScalarType type, bool big_endian) {
  std::vector<float> out(count);
  const bool swap = big_endian != (std::endian::native == std::endian::big);
  const char* p = bytes.data();
  switch (type) {
    case ScalarType::UInt8: convert<std::uint8_t>(p, count, swap, out.data()); break;
    case ScalarType::Int8: convert<std::int8_t>(p, count, swap, out.data()); break;
    case ScalarType::UInt16: convert<std::uint16_t>(p, count, swap, out.data()); break;
    case ScalarType::Int16: convert<std::int16_t>(p, count, swap, out.data()); break;
    case ScalarType::UInt32: convert<std::uint32_t>(p, count, swap, out.data()); break;
    case ScalarType::Int32: convert<std::int32_t>(p, count, swap, out.data()); break;
    case ScalarType::Float32: convert<float>(p, count, swap, out.data()); break;
    case ScalarType::Float64: convert<double>(p, count, swap, out.data()); break;
  }
  return out;
}

Result<Volume> VoxelCodec::assemble(const Eigen::Vector3i& dims, const Eigen::Matrix3d& axes_lps_mm,
                                    const Eigen::Vector3d& origin_lps_mm, std::vector<float> voxels,
                                    const std::string& source) {
  if (!axes_lps_mm.allFinite() || !origin_lps_mm.allFinite()) {
    return fail(fmt::format("{}: voxel spacing, directions or origin contain NaN or infinity", source));
  }
  const Eigen::Vector3d spacing_mm = axes_lps_mm.colwise().norm().transpose();
  if ((spacing_mm.array() <= 0.0).any()) {
    return fail(fmt::format("{}: voxel spacing must be positive, got {} x {} x {} mm", source, spacing_mm.x(),
                            spacing_mm.y(), spacing_mm.z()));
  }
  const Eigen::Matrix3d direction = axes_lps_mm * spacing_mm.cwiseInverse().asDiagonal();
  const double shear = (direction.transpose() * direction - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (shear > 1e-4) {
    return fail(fmt::format("{}: the voxel axes are not perpendicular (sheared grid, largest axis cosine {:.3g}); "
                            "resample the volume to an orthogonal grid first", source, shear));
  }
  auto volume = Volume::create(dims, spacing_mm, origin_lps_mm, direction);
  if (!volume.ok()) return fail(fmt::format("{}: {}", source, volume.error()));
  if (voxels.size() != volume.value().voxelCount()) {
    return fail(fmt::format("{}: {} voxels decoded but the dimensions {}x{}x{} need {}", source, voxels.size(), dims.x(),
                            dims.y(), dims.z(), volume.value().voxelCount()));
  }
  volume.value().voxels() = std::move(voxels);
  return volume;
}

}  // namespace fct
