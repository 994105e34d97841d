// RoiBoneFraction: how many of the dynamic ROIs of a case's X-rays sit on a bone edge, against all candidate windows
// (the chance level). A window is on a bone edge when the DRR of the CT's bone alone (voxels of at least 250 HU; the
// rest air), rendered at the case's true pose, varies inside it by more than a tenth of that DRR's 99th percentile.
// Usage: RoiBoneFraction CASE_FOLDER [FRACTION]  (a studio case: ct.*, views.json, truth_pose.json)
#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "Drr/DrrRendererFactory.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/CtLoader.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationViewLoader.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: {} CASE_FOLDER [FRACTION]\n", argv[0]);
    return 2;
  }
  const fs::path folder = argv[1];
  const double fraction = argc > 2 ? std::stod(argv[2]) : 0.12;
  fs::path ctPath;
  for (const char* name : {"ct.nrrd", "ct.nii.gz", "ct.nii", "ct.mha"}) {
    if (fs::exists(folder / name)) ctPath = folder / name;
  }
  auto ct = fct::CtLoader::load(ctPath);
  auto views = fct::RegistrationViewLoader::load(folder / "views.json");
  auto truth = fct::PoseFile::read(folder / "truth_pose.json");
  if (!ct || !views || !truth) {
    fmt::print(stderr, "cannot read the case: {}{}{}\n", ct ? "" : ct.error(), views ? "" : views.error(),
               truth ? "" : truth.error());
    return 1;
  }
  auto registrationCase = fct::RegistrationCase::create(ct.value(), views.value());
  fct::Volume bone = ct.value();
  for (int k = 0; k < bone.dims().z(); ++k)
    for (int j = 0; j < bone.dims().y(); ++j)
      for (int i = 0; i < bone.dims().x(); ++i)
        if (bone.at(i, j, k) < 250.0f) bone.at(i, j, k) = -1000.0f;
  auto boneVolume = fct::DrrVolume::create(bone);
  if (!registrationCase || !boneVolume) {
    fmt::print(stderr, "cannot prepare: {}\n", registrationCase ? boneVolume.error() : registrationCase.error());
    return 1;
  }
  auto renderer = fct::DrrRendererFactory::create(std::make_shared<const fct::DrrVolume>(std::move(boneVolume).value()), {});
  if (!renderer) return 1;
  for (std::size_t v = 0; v < registrationCase.value().viewCount(); ++v) {
    auto drr = renderer.value()->render(registrationCase.value().camera(v), truth.value(), 0);
    if (!drr) return 1;
    const fct::FloatImage& image = drr.value();
    std::vector<float> sorted = image.pixels;
    std::sort(sorted.begin(), sorted.end());
    const double edge = 0.1 * sorted[static_cast<std::size_t>(0.99 * (sorted.size() - 1))];
    const auto onBoneEdge = [&](const fct::RoiSelection& selection) {
      int count = 0;
      for (const fct::RoiWindow& window : selection.windows) {
        float lo = 1e30f, hi = -1e30f;
        for (int r = window.row0; r < window.row0 + selection.windowSize; ++r)
          for (int c = window.col0; c < window.col0 + selection.windowSize; ++c) {
            const float value = image.pixels[static_cast<std::size_t>(r) * image.cols + c];
            lo = std::min(lo, value);
            hi = std::max(hi, value);
          }
        if (hi - lo > edge) ++count;
      }
      return selection.windows.empty() ? 0.0 : static_cast<double>(count) / selection.windows.size();
    };
    auto rois = registrationCase.value().rois(v, 0, 7, fraction);
    auto all = registrationCase.value().allWindows(v, 0, 7);
    if (!rois || !all) return 1;
    fmt::print("view '{}': {} ROIs (fraction {:.2f}), {:.1f} % on a bone edge; all {} windows: {:.1f} %\n",
               registrationCase.value().viewName(v), rois.value().windows.size(), fraction,
               100.0 * onBoneEdge(rois.value()), all.value().windows.size(), 100.0 * onBoneEdge(all.value()));
  }
  return 0;
}
