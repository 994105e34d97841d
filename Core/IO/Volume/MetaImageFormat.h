#pragma once
// MetaImageFormat: MetaImage volumes (.mha with local data, .mhd with a separate data file). MetaImage positions
// are LPS (ITK convention), so no frame conversion is needed.

#include <filesystem>
#include <string>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// MetaImage reader and header writer. Geometry from ElementSpacing, Offset (or Position/Origin) and
/// TransformMatrix (or Rotation/Orientation; row n is the direction of axis n), else AnatomicalOrientation.
class MetaImageFormat {
 public:
  /// Reads a .mha or .mhd file into a float volume in LPS mm; fails with a message for unreadable, truncated,
  /// non-3D, multi-channel or unsupported files.
  static Result<Volume> read(const std::filesystem::path& path);
  /// The text header of a raw, native-endian MET_FLOAT MetaImage; data_file is "LOCAL" (voxels follow the header,
  /// .mha) or the data file's name relative to the header (.mhd).
  static std::string header(const Volume& volume, const std::string& data_file);
};

}  // namespace fct
