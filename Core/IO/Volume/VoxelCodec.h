#pragma once
// VoxelCodec: the parts of volume file reading shared by the NIfTI, NRRD and MetaImage formats:
// reading (and gunzipping) files, inflating zlib/gzip payloads, converting stored scalars to float and
// assembling a Volume from a file's voxel-to-LPS axes.

#include <Eigen/Core>

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// Scalar types a volume file may store.
enum class ScalarType { UInt8, Int8, UInt16, Int16, UInt32, Int32, Float32, Float64 };

/// Byte-level helpers for volume files.
class VoxelCodec {
 public:
  /// Size in bytes of one stored scalar.
  static std::size_t bytesPerScalar(ScalarType type);
  /// Human-readable name ("int16", "float32", ...).
  static const char* name(ScalarType type);

  /// Voxel count of dims; fails naming `source` when a dimension is not positive or the total is implausibly large.
  static Result<std::size_t> voxelCount(const Eigen::Vector3i& dims, const std::string& source);
  /// Whole content of a file, transparently decompressed when the file is gzip-compressed; fails if unreadable.
  static Result<std::string> readFile(const std::filesystem::path& path);
  /// Inflates a zlib or gzip stream that must yield exactly expected_bytes; fails on corrupt or short data.
  static Result<std::string> inflate(std::string_view compressed, std::size_t expected_bytes);
  /// Converts count stored scalars (given byte order) to float voxels; bytes must hold count scalars.
  static std::vector<float> toFloat(std::string_view bytes, std::size_t count, ScalarType type, bool big_endian);
  /// A Volume from dims, the LPS mm step of one voxel along i, j, k (columns of axes_lps_mm), the LPS position of
  /// voxel (0,0,0) and the voxels; fails with a message naming `source` for zero-length or sheared axes.
  static Result<Volume> assemble(const Eigen::Vector3i& dims, const Eigen::Matrix3d& axes_lps_mm,
                                 const Eigen::Vector3d& origin_lps_mm, std::vector<float> voxels,
                                 const std::string& source);
};

}  // namespace fct
