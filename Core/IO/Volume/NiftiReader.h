#pragma once
// NiftiReader: reads single-file NIfTI-1 volumes (.nii, .nii.gz) into the LPS frame.

#include <filesystem>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// NIfTI-1 reader. NIfTI stores positions in RAS; they are converted to LPS (x and y negated). The voxel-to-RAS
/// map is the sform when sform_code > 0, else the qform (quaternion, qfac flips k), else pixdim alone.
class NiftiReader {
 public:
  /// Reads a .nii or .nii.gz file into a float volume in LPS mm (scl_slope/scl_inter applied); fails with a
  /// message for unreadable, truncated, non-3D, unsupported-type or sheared files.
  static Result<Volume> read(const std::filesystem::path& path);
};

}  // namespace fct
