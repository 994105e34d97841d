#pragma once
// CtVolumeReader: the one way the tools open a CT given on the command line: a DICOM series folder or a volume file.

#include <filesystem>

#include "Result.h"
#include "Volume.h"

namespace fct {

/// Reads a CT from a folder (DICOM series: the largest one; a tilted or irregular series is resampled, with a warning
/// on the Result) or from a volume file (NIfTI, NRRD, MetaImage; see VolumeFileIO), in LPS mm and HU.
class CtVolumeReader {
 public:
  /// The CT at `path`; fails with the reader's message (missing path, no DICOM image, unknown extension, ...).
  static Result<Volume> read(const std::filesystem::path& path);
};

}  // namespace fct
