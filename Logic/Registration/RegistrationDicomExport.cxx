#include "Registration/RegistrationDicomExport.h"

#include <fmt/core.h>

#include "IO/Dicom/DicomRegistrationWriter.h"
#include "IO/Xray/XrayLoader.h"

namespace fct {

Result<std::filesystem::path> RegistrationDicomExport::write(const Volume& ct, const std::vector<RegistrationView>& views,
                                                             const RegistrationResult& result,
                                                             const std::filesystem::path& path) {
  std::vector<std::filesystem::path> xrayDicomFiles;
  for (const RegistrationView& view : views) {
    const std::string& source = view.xray.sourcePath;
    if (!source.empty() && !XrayLoader::isPlainImageFile(source)) xrayDicomFiles.emplace_back(source);
  }
  auto registration = DicomRegistrationWriter::describe(ct, result.T_world_from_ct, xrayDicomFiles);
  if (!registration) return fail(registration.error());
  const double similarity = result.stages.empty() ? 0.0 : result.stages.back().similarity;
  registration.value().contentDescription =
      fmt::format("FluoroCT bone pose T_world_from_ct{}, final similarity {:.4f}",
                  result.cancelled ? " (cancelled: best pose so far)" : "", similarity);
  if (Status written = DicomRegistrationWriter::write(registration.value(), path); !written) {
    return fail(written.error());
  }
  Result<std::filesystem::path> out(path);
  for (const std::string& warning : registration.warnings()) out.addWarning(warning);
  return out;
}

}  // namespace fct
