#pragma once
// NrrdFormat: NRRD volumes (.nrrd with attached data, .nhdr with a detached data file), read and written in LPS.

#include <filesystem>
#include <string>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// NRRD reader and header writer. Reads 3D scalar volumes with space RAS, LAS or LPS (`space directions`,
/// `space origin`; plain `spacings` without a space give identity axes), raw or gzip encoding, any byte order.
class NrrdFormat {
 public:
  /// Reads a .nrrd or .nhdr file into a float volume in LPS mm; fails with a message for unreadable, truncated,
  /// non-3D or unsupported files (other spaces, encodings or types).
  static Result<Volume> read(const std::filesystem::path& path);
  /// The text header (ending with the blank line) of a raw, native-endian float32 NRRD in LPS space; the voxels
  /// (Volume::voxels(), i fastest) follow it in an attached file.
  static std::string header(const Volume& volume);
};

}  // namespace fct
