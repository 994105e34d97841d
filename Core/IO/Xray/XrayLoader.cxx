#include "IO/Xray/XrayLoader.h"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>

#include "IO/Dicom/XrayDicomReader.h"
#include "IO/Xray/XrayImageFileReader.h"

namespace fct {

bool XrayLoader::isPlainImageFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".tif" || ext == ".tiff";
}

Result<XrayImage> XrayLoader::load(const std::filesystem::path& path, int frame) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return fail(fmt::format("no such file: '{}'; give an X-ray DICOM, PNG or TIFF file", path.string()));
  }
  if (!isPlainImageFile(path)) return XrayDicomReader::read(path, frame);
  if (frame != 0) {
    return fail(fmt::format("'{}' is a single image: frame {} does not exist (use frame 0)", path.string(), frame));
  }
  return XrayImageFileReader::read(path);
}

}  // namespace fct
