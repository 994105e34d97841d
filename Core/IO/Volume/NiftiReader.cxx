#include "IO/Volume/NiftiReader.h"

#include <fmt/core.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>

#include "IO/Volume/VoxelCodec.h"

namespace fct {
namespace {

constexpr std::size_t kHeaderBytes = 348;

/// Reads little- or big-endian fields of the 348-byte NIfTI-1 header.
class HeaderView {
 public:
  HeaderView(const std::string& bytes, bool swap) : m_bytes(bytes), m_swap(swap) {}
  template <typename T>
  T get(std::size_t offset) const {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, m_bytes.data() + offset, sizeof(T));
    if (m_swap) std::reverse(raw, raw + sizeof(T));
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }
  double f(std::size_t offset) const { return get<float>(offset); }

 private:
  const std::string& m_bytes;
  bool m_swap;
};

std::optional<ScalarType> scalarType(std::int16_t datatype) {
  switch (datatype) {
    case 2: return ScalarType::UInt8;
    case 4: return ScalarType::Int16;
    case 8: return ScalarType::Int32;
    case 16: return ScalarType::Float32;
    case 64: return ScalarType::Float64;
    case 256: return ScalarType::Int8;
    case 512: return ScalarType::UInt16;
    case 768: return ScalarType::UInt32;
    default: return std::nullopt;
  }
}

/// Millimetres per file unit from xyzt_units (0 = unknown is taken as mm, as all common tools do).
double mmPerUnit(std::uint8_t xyzt_units) {
  switch (xyzt_units & 0x07) {
    case 1: return 1000.0;  // metre
    case 3: return 0.001;   // micron
    default: return 1.0;
  }
}

}  // namespace

Result<Volume> NiftiReader::read(const std::filesystem::path& path) {
  const std::string source = fmt::format("NIfTI file '{}'", path.string());
  auto content = VoxelCodec::readFile(path);
  if (!content.ok()) return fail(content.error());
  const std::string& bytes = content.value();
  if (bytes.size() < kHeaderBytes) {
    return fail(fmt::format("{} is truncated: {} bytes, shorter than the 348-byte header", source, bytes.size()));
  }
  std::int32_t sizeofHdr = 0;
  std::memcpy(&sizeofHdr, bytes.data(), 4);
  const bool swap = sizeofHdr != 348;
  const HeaderView h(bytes, swap);
  if (h.get<std::int32_t>(0) != 348) {
    if (sizeofHdr == 540 || HeaderView(bytes, true).get<std::int32_t>(0) == 540) {
      return fail(fmt::format("{} is NIfTI-2, which is not supported; convert it to NIfTI-1 or NRRD", source));
    }
    return fail(fmt::format("{} is not a NIfTI-1 file (header size field is not 348)", source));
  }
  if (std::memcmp(bytes.data() + 344, "n+1", 4) != 0) {
    return fail(fmt::format("{} is not a single-file NIfTI-1 (.nii); .hdr/.img pairs are not supported, convert "
                            "to .nii or NRRD", source));
  }
  const bool bigEndian = (std::endian::native == std::endian::big) != swap;

  const int ndim = h.get<std::int16_t>(40);
  const Eigen::Vector3i dims(h.get<std::int16_t>(42), h.get<std::int16_t>(44), h.get<std::int16_t>(46));
  bool extraDimensions = false;
  for (int d = 4; d <= std::min(ndim, 7); ++d) extraDimensions |= h.get<std::int16_t>(40 + 2 * d) > 1;
  if (ndim < 1 || ndim > 7 || extraDimensions) {
    return fail(fmt::format("{} has {} dimensions; only 3D scalar volumes are supported (extract one 3D volume "
                            "first)", source, ndim));
  }
  const Eigen::Vector3i dims3(dims.x(), ndim >= 2 ? dims.y() : 1, ndim >= 3 ? dims.z() : 1);
  auto count = VoxelCodec::voxelCount(dims3, source);
  if (!count.ok()) return fail(count.error());

  const std::int16_t datatype = h.get<std::int16_t>(70);
  const auto type = scalarType(datatype);
  if (!type) {
    return fail(fmt::format("{} stores NIfTI datatype {}, which is not supported (use uint8, int8, int16, uint16, "
                            "int32, uint32, float32 or float64)", source, datatype));
  }
  const double voxOffset = h.f(108);
  if (!std::isfinite(voxOffset) || voxOffset < static_cast<double>(kHeaderBytes)) {
    return fail(fmt::format("{} has an invalid vox_offset {}", source, voxOffset));
  }
  if (voxOffset > static_cast<double>(bytes.size())) {
    return fail(fmt::format("{} is truncated or damaged: its voxel data would start at byte {:g} (vox_offset), beyond "
                            "the file's {} bytes", source, voxOffset, bytes.size()));
  }
  const std::size_t dataStart = static_cast<std::size_t>(voxOffset);
  const std::size_t dataBytes = count.value() * VoxelCodec::bytesPerScalar(*type);
  if (bytes.size() < dataStart || bytes.size() - dataStart < dataBytes) {
    return fail(fmt::format("{} is truncated: {}x{}x{} {} voxels need {} bytes of data but only {} follow the header",
                            source, dims3.x(), dims3.y(), dims3.z(), VoxelCodec::name(*type), dataBytes,
                            bytes.size() > dataStart ? bytes.size() - dataStart : 0));
  }

  // Voxel-to-RAS map in file units.
  const double unit_mm = mmPerUnit(h.get<std::uint8_t>(123));
  const int qformCode = h.get<std::int16_t>(252);
  const int sformCode = h.get<std::int16_t>(254);
  Eigen::Matrix3d axes_ras = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin_ras = Eigen::Vector3d::Zero();
  std::string geometry;
  const Eigen::Vector3d pixdim(h.f(80), h.f(84), h.f(88));
  if (sformCode > 0) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) axes_ras(r, c) = h.f(280 + 16 * r + 4 * c);
      origin_ras(r) = h.f(280 + 16 * r + 12);
    }
    geometry = "sform";
  } else {
    const Eigen::Vector3d step(pixdim.x() > 0 ? pixdim.x() : 1.0, pixdim.y() > 0 ? pixdim.y() : 1.0,
                               pixdim.z() > 0 ? pixdim.z() : 1.0);
    if (qformCode > 0) {
      const double b = h.f(256), c = h.f(260), d = h.f(264);
      const double a = std::sqrt(std::max(0.0, 1.0 - (b * b + c * c + d * d)));
      const Eigen::Matrix3d rotation = Eigen::Quaterniond(a, b, c, d).normalized().toRotationMatrix();
      const double qfac = h.f(76) < 0.0 ? -1.0 : 1.0;
      axes_ras = rotation * Eigen::Vector3d(step.x(), step.y(), qfac * step.z()).asDiagonal();
      origin_ras = Eigen::Vector3d(h.f(268), h.f(272), h.f(276));
      geometry = qfac < 0 ? "qform, qfac -1" : "qform";
    } else {
      axes_ras = step.asDiagonal();
      geometry = "no sform or qform: pixdim only";
    }
  }
  const Eigen::Matrix3d rasToLps = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();

  std::vector<float> voxels = VoxelCodec::toFloat(std::string_view(bytes).substr(dataStart, dataBytes),
                                                  count.value(), *type, bigEndian);
  const double slope = h.f(112);
  const double intercept = h.f(116);
  if (std::isfinite(slope) && slope != 0.0 && std::isfinite(intercept) && (slope != 1.0 || intercept != 0.0)) {
    for (float& v : voxels) v = static_cast<float>(slope * v + intercept);
  }
  auto volume = VoxelCodec::assemble(dims3, unit_mm * rasToLps * axes_ras, unit_mm * rasToLps * origin_ras,
                                     std::move(voxels), source);
  if (!volume.ok()) return volume;
  if (sformCode <= 0 && qformCode <= 0) {
    volume.addWarning(fmt::format("{} has neither sform nor qform; orientation assumed RAS-aligned with the voxel "
                                  "axes and origin at 0", source));
  }
  volume.value().description =
      fmt::format("{} ({}, {}, converted RAS to LPS)", path.filename().string(), VoxelCodec::name(*type), geometry);
  return volume;
}

}  // namespace fct
