#include "IO/Volume/CtLoader.h"

#include <fmt/core.h>

#include "IO/Volume/VolumeFileIO.h"

namespace fct {

Result<Volume> CtLoader::load(const std::filesystem::path& path, const DicomSeriesReadOptions& dicomOptions) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return fail(fmt::format("no such file or folder: '{}'; give a DICOM folder or a .nii/.nii.gz/.nrrd/.mha file",
                            path.string()));
  }
  if (std::filesystem::is_directory(path, ec)) return DicomSeriesReader::read(path, dicomOptions);
  return VolumeFileIO::read(path);
}

}  // namespace fct
