#include "Registration/RegistrationViewLoader.h"

#include <fmt/core.h>

#include <string>

#include "IO/Project/DewarpFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Xray/XrayLoader.h"
#include "XrayPrep/XrayDewarper.h"

namespace fct {

Result<std::vector<RegistrationView>> RegistrationViewLoader::load(const std::filesystem::path& viewFile) {
  auto specs = ViewFile::read(viewFile);
  if (!specs) return fail(specs.error());
  std::vector<std::string> warnings = specs.warnings();
  std::vector<RegistrationView> views;
  for (const ViewSpec& spec : specs.value()) {
    if (spec.imagePath.empty()) {
      return fail(fmt::format("{}: view '{}' has no image; registration needs an X-ray per view: add the key "
                              "\"image\" with the view's X-ray file",
                              viewFile.string(), spec.name));
    }
    auto image = XrayLoader::load(spec.imagePath, spec.frame);
    if (!image) return fail(fmt::format("{}: view '{}': {}", viewFile.string(), spec.name, image.error()));
    for (const std::string& warning : image.warnings()) {
      warnings.push_back(fmt::format("view '{}': {}", spec.name, warning));
    }
    const CameraIntrinsics& detector = spec.camera.intrinsics();
    if (image.value().cols != detector.cols || image.value().rows != detector.rows) {
      return fail(fmt::format("{}: view '{}': the image is {}x{} pixels but the detector is {}x{}; fix the view "
                              "file's detector size or give the matching image",
                              viewFile.string(), spec.name, image.value().cols, image.value().rows, detector.cols,
                              detector.rows));
    }
    RegistrationView view{spec.name, std::move(image).value(), spec.camera, spec.calibrationSpheres};
    if (!spec.dewarpPath.empty()) {
      auto dewarp = DewarpFile::read(spec.dewarpPath);
      if (!dewarp) return fail(fmt::format("{}: view '{}': {}", viewFile.string(), spec.name, dewarp.error()));
      for (const std::string& warning : dewarp.warnings()) {
        warnings.push_back(fmt::format("view '{}': {}", spec.name, warning));
      }
      auto dewarped = XrayDewarper::apply(view.xray, dewarp.value().field);
      if (!dewarped) return fail(fmt::format("{}: view '{}': {}", viewFile.string(), spec.name, dewarped.error()));
      view.xray = std::move(dewarped).value();
      view.spheres = XrayDewarper::mapCircles(view.spheres, dewarp.value().field);
    }
    views.push_back(std::move(view));
  }
  Result<std::vector<RegistrationView>> loaded(std::move(views));
  for (std::string& warning : warnings) loaded.addWarning(std::move(warning));
  return loaded;
}

}  // namespace fct
