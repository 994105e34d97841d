#include "Registration/RegistrationViewLoader.h"

#include <fmt/core.h>

#include <algorithm>
#include <string>

#include "IO/Project/DewarpFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Xray/XrayLoader.h"
#include "XrayPrep/XrayDewarper.h"

namespace fct {

namespace {

/// Flips an image left-right in place (column c <-> cols-1-c), with its field-of-view mask; drops its own camera,
/// which belonged to the unflipped pixels.
void mirrorColumns(XrayImage& image) {
  for (int row = 0; row < image.rows; ++row) {
    const auto begin = static_cast<std::ptrdiff_t>(row) * image.cols;
    std::reverse(image.pixels.begin() + begin, image.pixels.begin() + begin + image.cols);
    if (!image.fovMask.empty()) std::reverse(image.fovMask.begin() + begin, image.fovMask.begin() + begin + image.cols);
  }
  image.camera.reset();
}

/// The view's image from frame `frame` of `imagePath`, flipped and dewarped as the view says, with its spheres.
Result<RegistrationView> loadImage(const ViewSpec& spec, const std::filesystem::path& imagePath, int frame) {
  auto image = XrayLoader::load(imagePath, frame);
  if (!image) return fail(fmt::format("view '{}': {}", spec.name, image.error()));
  std::vector<std::string> warnings;
  for (const std::string& warning : image.warnings()) warnings.push_back(fmt::format("view '{}': {}", spec.name, warning));
  if (spec.mirrorColumns) mirrorColumns(image.value());
  const CameraIntrinsics& detector = spec.camera.intrinsics();
  if (image.value().cols != detector.cols || image.value().rows != detector.rows) {
    return fail(fmt::format("view '{}': the image is {}x{} pixels but the detector is {}x{}; fix the view file's "
                            "detector size or give the matching image",
                            spec.name, image.value().cols, image.value().rows, detector.cols, detector.rows));
  }
  RegistrationView view{spec.name, std::move(image).value(), spec.camera, spec.calibrationSpheres};
  if (!spec.dewarpPath.empty()) {
    auto dewarp = DewarpFile::read(spec.dewarpPath);
    if (!dewarp) return fail(fmt::format("view '{}': {}", spec.name, dewarp.error()));
    for (const std::string& warning : dewarp.warnings()) warnings.push_back(fmt::format("view '{}': {}", spec.name, warning));
    auto dewarped = XrayDewarper::apply(view.xray, dewarp.value().field);
    if (!dewarped) return fail(fmt::format("view '{}': {}", spec.name, dewarped.error()));
    view.xray = std::move(dewarped).value();
    view.spheres = XrayDewarper::mapCircles(view.spheres, dewarp.value().field);
  }
  Result<RegistrationView> loaded(std::move(view));
  for (std::string& warning : warnings) loaded.addWarning(std::move(warning));
  return loaded;
}

}  // namespace

Result<RegistrationView> RegistrationViewLoader::loadView(const ViewSpec& spec) {
  if (spec.imagePath.empty()) {
    return fail(fmt::format("view '{}' has no image; registration needs an X-ray per view: add the key \"image\" "
                            "with the view's X-ray file",
                            spec.name));
  }
  return loadImage(spec, spec.imagePath, spec.frame);
}

Result<RegistrationView> RegistrationViewLoader::loadFrame(const ViewSpec& spec, int frame) {
  if (!spec.sequence) {
    return fail(fmt::format("view '{}' has no sequence; tracking needs a \"sequence\" of frames per view", spec.name));
  }
  if (frame < 0 || frame >= spec.sequence->frameCount()) {
    return fail(fmt::format("view '{}': frame {} is outside its sequence of {} frames", spec.name, frame,
                            spec.sequence->frameCount()));
  }
  const auto [path, fileFrame] = spec.sequence->frame(frame);
  return loadImage(spec, path, fileFrame);
}

Result<std::vector<RegistrationView>> RegistrationViewLoader::load(const std::filesystem::path& viewFile) {
  auto specs = ViewFile::read(viewFile);
  if (!specs) return fail(specs.error());
  std::vector<std::string> warnings = specs.warnings();
  std::vector<RegistrationView> views;
  for (const ViewSpec& spec : specs.value()) {
    auto view = loadView(spec);
    if (!view) return fail(fmt::format("{}: {}", viewFile.string(), view.error()));
    warnings.insert(warnings.end(), view.warnings().begin(), view.warnings().end());
    views.push_back(std::move(view).value());
  }
  Result<std::vector<RegistrationView>> loaded(std::move(views));
  for (std::string& warning : warnings) loaded.addWarning(std::move(warning));
  return loaded;
}

}  // namespace fct
