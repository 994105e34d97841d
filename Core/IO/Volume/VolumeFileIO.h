#pragma once
// VolumeFileIO: reads and writes volume files by extension, always handing out volumes in the LPS frame.

#include <filesystem>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// Volume files: NIfTI-1 (.nii, .nii.gz; RAS on disk), NRRD (.nrrd, .nhdr; RAS/LAS/LPS space) and MetaImage
/// (.mha, .mhd; LPS). Whatever the file's frame, the Volume is in LPS mm with its direction cosines.
class VolumeFileIO {
 public:
  /// Reads NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr) or MetaImage (.mha, .mhd) into LPS; voxels become float
  /// (HU for CT). Fails with a message for a missing, unknown, truncated or malformed file.
  static Result<Volume> read(const std::filesystem::path& path);
  /// Writes NRRD (.nrrd) or MetaImage (.mha, or .mhd plus a .raw data file) with LPS space and direction cosines;
  /// float32 voxels; atomic (temp + rename): on failure no file is created or changed.
  static Status write(const Volume& volume, const std::filesystem::path& path);
};

}  // namespace fct
