#include "IO/Volume/VolumeFileIO.h"

#include "Base/AtomicFile.h"

#include <fmt/core.h>

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

/// Writes header then the voxels with AtomicFile.
Status writeAtomically(const std::filesystem::path& path, const std::string& header, std::span<const float> voxels) {
  return AtomicFile::write(path, {header, AtomicFile::bytesOf(voxels.data(), voxels.size())});
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
