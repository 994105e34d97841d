#include "TestXrayLoader.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmimgle/dcmimage.h>

namespace fct::test {

std::optional<XrayImage> loadXrayWithDcmtk(const std::filesystem::path& path) {
  DcmFileFormat file;
  if (file.loadFile(path.string().c_str()).bad()) return std::nullopt;
  DicomImage image(&file, file.getDataset()->getOriginalXfer(), CIF_UsePartialAccessToPixelData, 0, 1);
  if (image.getStatus() != EIS_Normal || !image.isMonochrome()) return std::nullopt;
  image.setNoVoiTransformation();
  XrayImage xray;
  xray.cols = static_cast<int>(image.getWidth());
  xray.rows = static_cast<int>(image.getHeight());
  xray.bitsStored = image.getDepth();
  const auto* values = static_cast<const Uint16*>(image.getOutputData(16, 0, 0));  // MONOCHROME2 output
  if (!values) return std::nullopt;
  const double scale = static_cast<double>((1 << xray.bitsStored) - 1) / 65535.0;
  xray.pixels.resize(static_cast<std::size_t>(xray.cols) * xray.rows);
  for (std::size_t i = 0; i < xray.pixels.size(); ++i) xray.pixels[i] = static_cast<float>(values[i] * scale);
  OFString text;
  if (file.getDataset()->findAndGetOFString(DCM_PhotometricInterpretation, text).good()) xray.photometric = text.c_str();
  if (file.getDataset()->findAndGetOFString(DCM_Modality, text).good()) xray.modality = text.c_str();
  xray.sourcePath = path.string();
  return xray;
}

}  // namespace fct::test
