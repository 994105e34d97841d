#include "CtVolumeReader.h"

#include <fmt/core.h>

#include <system_error>

#include "DicomSeriesReader.h"
#include "VolumeFileIO.h"

namespace fct {

Result<Volume> CtVolumeReader::read(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return fail(fmt::format("CT '{}' does not exist", path.string()));
  if (std::filesystem::is_directory(path, ec)) return DicomSeriesReader::read(path);
  return VolumeFileIO::read(path);
}

}  // namespace fct
