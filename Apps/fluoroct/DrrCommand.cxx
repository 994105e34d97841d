// fluoroct drr: renders a DRR of a CT for every view of a view file (or one) and writes one image per view; with
// --image, the one view's DRR to exactly that file (the form the 3D Slicer CLI module uses; SlicerModule.h).
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "CliSupport.h"
#include "Drr/DrrRendererFactory.h"
#include "Drr/DrrVolume.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/CtLoader.h"
#include "IO/Xray/ImageFileWriter.h"
#include "SlicerModule.h"

namespace fct::cli {

namespace {

namespace fs = std::filesystem;

struct DrrCommandOptions {
  std::string ct, views, pose, view, out;
  std::string image;                ///< exact output file of the one selected view's DRR (instead of --out)
  std::string returnParameterFile;  ///< optional "name = value" file of the scalar results (Slicer CLI modules)
  std::string method = "siddon";
  std::string values = "attenuation";
  int level = 0;
  std::string transgraphCache;  ///< empty = the default cache folder; "none" = no cache
  double transgraphSpacing_mm = TransgraphParameters{}.spacing_mm;
};

/// A view name made safe for a file name: characters other than letters, digits, '-', '_' and '.' become '_'.
std::string fileSafe(const std::string& name) {
  std::string safe = name;
  for (char& c : safe) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  return safe;
}

/// Writes one DRR in the format given by the extension (".nrrd", ".pfm", ".tif"/".tiff": float32; ".png": 16-bit,
/// windowed from the image's minimum to its maximum).
Status writeDrr(const FloatImage& image, const fs::path& path, const std::string& extension,
                const Eigen::Vector2d& pixelSpacing_mm) {
  if (extension == ".nrrd") return ImageFileWriter::writeNrrd2d(image, path, pixelSpacing_mm);
  if (extension == ".pfm") return ImageFileWriter::writePfm(image, path);
  if (extension == ".tif" || extension == ".tiff") return ImageFileWriter::writeTiff(image, path);
  const auto [lo, hi] = std::minmax_element(image.pixels.begin(), image.pixels.end());
  return ImageFileWriter::writePng16(image, path, *lo, *hi > *lo ? *hi : *lo + 1.0f);
}

/// The output file of view `name`: --image itself, or PREFIX_<view>.<ext> of --out.
fs::path outputPath(const DrrCommandOptions& options, const std::string& name) {
  if (!options.image.empty()) return options.image;
  const fs::path out(options.out);
  return fs::path((out.parent_path() / out.stem()).string() + "_" + fileSafe(name) + out.extension().string());
}

int runDrr(const DrrCommandOptions& options) {
  if (options.out.empty() == options.image.empty()) {
    return reportError("give exactly one of --out PREFIX.ext (one file per view) or --image FILE (one view's DRR)");
  }
  const std::string flag = options.image.empty() ? "--out" : "--image";
  const fs::path out(options.image.empty() ? options.out : options.image);
  const std::string extension = out.extension().string();
  if (extension != ".nrrd" && extension != ".pfm" && extension != ".tif" && extension != ".tiff" &&
      extension != ".png") {
    return reportError(fmt::format("{} '{}' must end in .nrrd, .pfm, .tif or .png", flag, out.string()));
  }
  if (!out.parent_path().empty() && !fs::is_directory(out.parent_path())) {
    return reportError(fmt::format("output folder '{}' does not exist; create it first", out.parent_path().string()));
  }
  const auto method = DrrRendererFactory::parseMethod(options.method);
  if (!method.ok()) return reportError("--method: " + method.error());
  const auto valueKind = DrrVolume::parseValueKind(options.values);
  if (!valueKind.ok()) return reportError("--values: " + valueKind.error());
  if (options.level < 0) return reportError(fmt::format("--level must be 0 or more, got {}", options.level));

  auto views = ViewFile::read(options.views);
  if (!views.ok()) return reportError(views.error());
  printWarnings(views.warnings());
  std::vector<ViewSpec> selected = views.value();
  if (!options.view.empty()) {
    std::erase_if(selected, [&](const ViewSpec& v) { return v.name != options.view; });
    if (selected.empty()) {
      std::string names;
      for (const auto& v : views.value()) names += (names.empty() ? "" : ", ") + v.name;
      return reportError(fmt::format("view '{}' is not in {}; its views are: {}", options.view, options.views, names));
    }
  }
  if (!options.image.empty() && selected.size() > 1) {
    std::string names;
    for (const auto& v : selected) names += (names.empty() ? "" : ", ") + v.name;
    return reportError(fmt::format("--image writes one DRR, but {} has {} views ({}); choose one with --view",
                                   options.views, selected.size(), names));
  }
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  if (!options.pose.empty()) {
    const auto pose = readPoseOrTransform(options.pose);
    if (!pose.ok()) return reportError("--pose: " + pose.error());
    T_world_from_ct = pose.value();
  }

  auto ct = CtLoader::load(options.ct);
  if (!ct.ok()) return reportError(ct.error());
  printWarnings(ct.warnings());
  DrrValueOptions valueOptions;
  valueOptions.kind = valueKind.value();
  auto drrVolume = DrrVolume::create(std::move(ct).value(), valueOptions);  // the HU values are not needed after
  if (!drrVolume.ok()) return reportError(drrVolume.error());
  DrrRendererOptions rendererOptions;
  rendererOptions.method = method.value();
  rendererOptions.transgraph.spacing_mm = options.transgraphSpacing_mm;
  if (options.transgraphCache == "none") {
    rendererOptions.transgraphCacheFolder = std::nullopt;
  } else {
    rendererOptions.transgraphCacheFolder = fs::path(options.transgraphCache);
  }
  const auto prepared = std::make_shared<const DrrVolume>(std::move(drrVolume).value());

  // Render every view before writing any file, so a view that cannot be rendered leaves nothing behind.
  std::vector<FloatImage> images(selected.size());
  std::vector<double> seconds(selected.size());
  for (std::size_t n = 0; n < selected.size(); ++n) {
    // The transgraph method builds (or loads from its cache) one table per view around the requested pose.
    const auto renderer =
        DrrRendererFactory::createForView(prepared, rendererOptions, selected[n].camera, T_world_from_ct);
    if (!renderer.ok()) return reportError(fmt::format("view '{}': {}", selected[n].name, renderer.error()));
    printWarnings(renderer.warnings());
    const auto start = std::chrono::steady_clock::now();
    const Status rendered = renderer.value()->render(selected[n].camera, T_world_from_ct, options.level, images[n]);
    if (!rendered.ok()) return reportError(fmt::format("view '{}': {}", selected[n].name, rendered.error()));
    seconds[n] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  // The files are written side by side (each durably, so their flushes to disk overlap); errors in view order.
  std::vector<Status> written(selected.size(), Ok{});
  std::vector<std::thread> writers;
  for (std::size_t n = 0; n < selected.size(); ++n) {
    writers.emplace_back([&, n] {
      const Eigen::Vector2d spacing_mm = selected[n].camera.downsampled(options.level).intrinsics().pixelSpacing_mm;
      written[n] = writeDrr(images[n], outputPath(options, selected[n].name), extension, spacing_mm);
    });
  }
  for (std::thread& writer : writers) writer.join();
  for (std::size_t n = 0; n < selected.size(); ++n) {
    if (!written[n].ok()) return reportError(written[n].error());
    const fs::path path = outputPath(options, selected[n].name);
    const auto [lo, hi] = std::minmax_element(images[n].pixels.begin(), images[n].pixels.end());
    fmt::print("wrote {}: {} x {} px, {} {} DRR, level {}, values {:.4g}..{:.4g}, {:.3f} s\n", path.string(),
               images[n].cols, images[n].rows, options.method, options.values, options.level, *lo, *hi, seconds[n]);
  }
  if (!options.returnParameterFile.empty()) {
    double total_s = 0.0;
    for (const double s : seconds) total_s += s;
    const Status written =
        writeReturnParameters(options.returnParameterFile, {{"renderSeconds", fmt::format("{:.4f}", total_s)}});
    if (!written.ok()) return reportError(written.error());
  }
  return 0;
}

}  // namespace

void registerDrrCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<DrrCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "drr", "Render digitally reconstructed radiographs of a CT for the views of a view file; writes "
             "PREFIX_<view name>.<ext> per view (float32 .nrrd/.pfm/.tif, or a min-max windowed 16-bit .png)");
  command->add_option("--ct", options->ct, "CT volume file (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd) or DICOM folder")
      ->required();
  command->add_option("--views", options->views, "View file (JSON) with the calibrated cameras")->required();
  command->add_option("--pose", options->pose,
                      "Pose file with T_world_from_ct, or ITK transform (.tfm, as 3D Slicer saves it) (default: "
                      "identity)");
  command->add_option("--view", options->view, "Render only the view with this name");
  command->add_option("--method", options->method, "siddon (exact voxel traversal), raycast (trilinear sampling) or transgraph (precomputed ray table per view, cached on disk; see README)")
      ->capture_default_str();
  command->add_option("--values", options->values,
                      "attenuation (integral of mu from HU, dimensionless) or raw (integral of voxel value, value*mm)")
      ->capture_default_str();
  command->add_option("--level", options->level, "Pyramid level: detector downsampled by 2^level per axis")
      ->capture_default_str();
  command->add_option("--transgraph-cache", options->transgraphCache,
                      "Folder of the transgraph table cache (default: $XDG_CACHE_HOME/fluoroct/transgraph or "
                      "~/.cache/fluoroct/transgraph); 'none' disables the cache");
  command->add_option("--transgraph-spacing-mm", options->transgraphSpacing_mm,
                      "Transgraph plane sampling step in mm (smaller: more accurate, rays grow as step^-4)")
      ->check(positiveNumber())
      ->capture_default_str();
  command->add_option("--out", options->out, "Output prefix and format, e.g. out/drr.nrrd -> out/drr_<view>.nrrd");
  command->add_option("--image", options->image,
                      "Instead of --out: write the DRR of the one view (--view, or the view file's only view) to "
                      "exactly this file");
  command->add_option("--returnparameterfile", options->returnParameterFile,
                      "Write the scalar results (renderSeconds) as 'name = value' lines, as 3D Slicer's CLI modules do");
  addModuleXmlFlag(command, drrModuleXml());
  command->callback([&action, options] { action = [options] { return runDrr(*options); }; });
}

}  // namespace fct::cli
