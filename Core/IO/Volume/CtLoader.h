#pragma once
// CtLoader: loads a CT from whatever the user points at: a DICOM folder or a NIfTI/NRRD/MetaImage file.

#include <filesystem>

#include "Base/Result.h"
#include "Image/Volume.h"
#include "IO/Dicom/DicomSeriesReader.h"

namespace fct {

/// One entry point for every CT source, so that all commands and widgets accept the same inputs.
class CtLoader {
 public:
  /// A folder is read as a DICOM series (options apply: series UID, policy for tilted/irregular series); a file is
  /// read by VolumeFileIO (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd). Warnings (e.g. resampling) are kept on the
  /// Result. Fails with the reader's message, or "no such file or folder" when the path does not exist.
  static Result<Volume> load(const std::filesystem::path& path, const DicomSeriesReadOptions& dicomOptions = {});
};

}  // namespace fct
