#pragma once
// PoseFile: the bone pose as JSON, {"T_world_from_ct": [[4 x 4]]}, LPS mm, row-major.

#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string_view>

#include "Base/JsonReader.h"
#include "Base/Result.h"

namespace fct {

/// Reads and writes pose files.
class PoseFile {
 public:
  /// Reads T_world_from_ct (LPS mm). Fails naming the file and key on bad JSON, a missing key, NaN, a last row
  /// other than [0, 0, 0, 1] or a 3x3 part that is not a rotation. Unknown keys are ignored with a warning.
  static Result<Eigen::Isometry3d> read(const std::filesystem::path& path);

  /// Reads the pose at `key` (4 x 4 rows, LPS mm) of the object `reader` reads, checked like read() (finite, last row
  /// [0, 0, 0, 1], a rotation); on failure records the error on `reader`, naming its place and the key, and returns
  /// nullopt (also when `reader` already has an error).
  static std::optional<Eigen::Isometry3d> readKey(JsonReader& reader, std::string_view key);

  /// Writes T_world_from_ct atomically; fails if it is not a finite rigid transform or the path is unwritable.
  static Status write(const Eigen::Isometry3d& T_world_from_ct, const std::filesystem::path& path);
};

}  // namespace fct
