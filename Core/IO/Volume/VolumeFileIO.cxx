#include "IO/Volume/VolumeFileIO.h"

#include <fmt/core.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <span>
#include <system_error>

#include "IO/Volume/MetaImageFormat.h"
#include "IO/Volume/NiftiReader.h"
#include "IO/Volume/NrrdFormat.h"
#include "IO/Volume/TextHeader.h"

namespace fct {
namespace {

/// The file's format extension in lower case, including ".nii.gz".
std::string extensionOf(const std::filesystem::path& path) {
  const std::string name = TextHeader::lower(path.filename().string());
  if (name.size() > 7 && name.ends_with(".nii.gz")) return ".nii.gz";
  return TextHeader::lower(path.extension().string());
}

/// Writes header then the voxels to a temporary file beside `path` and renames it into place.
Status writeAtomically(const std::filesystem::path& path, const std::string& header, std::span<const float> voxels) {
  const std::filesystem::path parent = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(parent, ec)) {
    return fail(fmt::format("cannot write '{}': the folder '{}' does not exist; create it first", path.string(),
                            parent.string()));
  }
  const std::filesystem::path temp = parent / fmt::format(".{}.tmp-{}", path.filename().string(), ::getpid());
  std::FILE* file = std::fopen(temp.c_str(), "wb");
  if (!file) {
    return fail(fmt::format("cannot write '{}': {}; choose a writable folder", path.string(), std::strerror(errno)));
  }
  bool ok = std::fwrite(header.data(), 1, header.size(), file) == header.size() &&
            std::fwrite(voxels.data(), sizeof(float), voxels.size(), file) == voxels.size();
  const int writeErrno = errno;
  ok = (std::fclose(file) == 0) && ok;
  if (!ok) {
    std::filesystem::remove(temp, ec);
    return fail(fmt::format("writing '{}' failed: {}; check free disk space", path.string(), std::strerror(writeErrno)));
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    return fail(fmt::format("cannot move the finished file into place at '{}': {}", path.string(), ec.message()));
  }
  return Ok{};
}

}  // namespace

Result<Volume> VolumeFileIO::read(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return fail(fmt::format("volume file '{}' does not exist or is not a file", path.string()));
  }
  const std::string ext = extensionOf(path);
  if (ext == ".nii" || ext == ".nii.gz") return NiftiReader::read(path);
  if (ext == ".nrrd" || ext == ".nhdr") return NrrdFormat::read(path);
  if (ext == ".mha" || ext == ".mhd") return MetaImageFormat::read(path);
  return fail(fmt::format("'{}' has an unknown volume extension '{}'; use .nii, .nii.gz, .nrrd, .nhdr, .mha or .mhd "
                          "(DICOM series are read from their folder)", path.string(), ext));
}

Status VolumeFileIO::write(const Volume& volume, const std::filesystem::path& path) {
  if (volume.voxelCount() == 0) return fail("cannot write an empty volume");
  const std::string ext = extensionOf(path);
  if (ext == ".nrrd") return writeAtomically(path, NrrdFormat::header(volume), volume.voxels());
  if (ext == ".mha") return writeAtomically(path, MetaImageFormat::header(volume, "LOCAL"), volume.voxels());
  if (ext == ".mhd") {
    std::filesystem::path rawPath = path;
    rawPath.replace_extension(".raw");
    const Status raw = writeAtomically(rawPath, "", volume.voxels());
    if (!raw.ok()) return raw;
    const Status header = writeAtomically(path, MetaImageFormat::header(volume, rawPath.filename().string()), {});
    if (!header.ok()) {
      std::error_code ec;
      std::filesystem::remove(rawPath, ec);
    }
    return header;
  }
  return fail(fmt::format("cannot write '{}': unknown extension '{}'; use .nrrd, .mha or .mhd", path.string(), ext));
}

}  // namespace fct
