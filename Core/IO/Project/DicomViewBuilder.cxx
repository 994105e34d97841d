#include "IO/Project/DicomViewBuilder.h"

#include <fmt/core.h>

#include <set>

#include "IO/Dicom/XrayDicomReader.h"

namespace fct {

Result<std::vector<ViewSpec>> DicomViewBuilder::build(const std::vector<std::filesystem::path>& files,
                                                      const DicomViewOptions& options) {
  if (files.empty()) return fail("no DICOM files given: name one X-ray DICOM file per view");
  std::vector<ViewSpec> views;
  std::vector<std::string> warnings;
  std::set<std::string> names;
  for (const std::filesystem::path& file : files) {
    const std::string label = file.filename().string();
    const int frame = options.frame.value_or(0);
    auto header = XrayDicomReader::readHeader(file, frame);
    if (!header) return fail(header.error());
    for (const auto& w : header.warnings()) warnings.push_back(w);
    const XrayDicomHeader& h = header.value();
    auto camera = XrayGeometryReader::frameCamera(h.geometry, h.cols, h.rows, options.overrides);
    if (!camera) return fail(fmt::format("'{}': {}", label, camera.error()));
    for (const auto& w : camera.warnings()) warnings.push_back(fmt::format("'{}': {}", label, w));
    if (!camera.value().orientationKnown) {
      warnings.push_back(fmt::format("'{}': PatientOrientation (0020,0020) is {}; the image is taken as seen from the "
                                     "source (columns toward the patient's right at 0/0): check it on known anatomy",
                                     label,
                                     h.geometry.patientOrientation.empty()
                                         ? "absent"
                                         : "'" + h.geometry.patientOrientation + "', not in L/R/A/P/H/F letters"));
    }
    ViewSpec view;
    std::string base = file.stem().string();
    if (base.empty()) base = "view";
    if (options.frame && h.frames > 1) base += fmt::format("_f{}", frame);
    view.name = base;
    for (int n = 2; !names.insert(view.name).second; ++n) view.name = fmt::format("{}_{}", base, n);
    view.imagePath = std::filesystem::absolute(file).lexically_normal();
    view.frame = frame;
    view.mirrorColumns = camera.value().mirrorColumns;
    view.camera = camera.value().camera;
    views.push_back(std::move(view));
  }
  Result<std::vector<ViewSpec>> result(std::move(views));
  for (auto& w : warnings) result.addWarning(std::move(w));
  return result;
}

}  // namespace fct
