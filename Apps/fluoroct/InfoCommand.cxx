// fluoroct info: what a CT (DICOM folder or volume file) or an X-ray (DICOM, PNG, TIFF) holds, as text or JSON.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <Eigen/Core>
#include <algorithm>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "CliSupport.h"
#include "IO/Dicom/XrayDicomReader.h"
#include "IO/Volume/CtLoader.h"
#include "IO/Xray/XrayLoader.h"

namespace fct::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct InfoOptions {
  std::string path;
  bool json = false;
  std::string seriesUid;
  bool refuseIrregular = false;
  double resample_mm = 0.0;
  int frame = 0;
};

json vectorJson(const Eigen::Vector2d& v) { return json::array({v.x(), v.y()}); }
json vectorJson(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
json matrixJson(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (int r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

bool isVolumeFile(const fs::path& path) {
  const std::string name = path.filename().string();
  for (const char* ext : {".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd"}) {
    const std::string e(ext);
    if (name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0) return true;
  }
  return false;
}

int printCt(const InfoOptions& options) {
  DicomSeriesReadOptions dicomOptions;
  dicomOptions.seriesInstanceUid = options.seriesUid;
  dicomOptions.policy =
      options.refuseIrregular ? IrregularSeriesPolicy::Refuse : IrregularSeriesPolicy::ResampleWithWarning;
  dicomOptions.resampleSpacing_mm = options.resample_mm;
  json series = json::array();
  if (fs::is_directory(options.path)) {
    const auto found = DicomSeriesReader::scan(options.path);
    if (!found.ok()) return reportError(found.error());
    for (const auto& s : found.value()) {
      series.push_back({{"uid", s.seriesInstanceUid}, {"description", s.seriesDescription}, {"modality", s.modality},
                        {"files", s.fileCount}, {"rows", s.rows}, {"cols", s.cols}});
    }
  }
  const auto loaded = CtLoader::load(options.path, dicomOptions);
  if (!loaded.ok()) {
    // The reader says in its own words that it refused an irregular series; name the option that asked it to.
    const bool refused = options.refuseIrregular && loaded.error().find("not on a regular grid") != std::string::npos;
    return reportError(refused ? "--refuse-irregular: " + loaded.error() +
                                     "; leave out --refuse-irregular to resample it (--resample-mm MM sets the spacing)"
                               : loaded.error());
  }
  const Volume& ct = loaded.value();
  const auto [lo, hi] = ct.valueRange();
  if (options.json) {
    json out = {{"type", "ct"},
                {"path", options.path},
                {"dims", json::array({ct.dims().x(), ct.dims().y(), ct.dims().z()})},
                {"spacing_mm", vectorJson(ct.spacing_mm())},
                {"origin_lps_mm", vectorJson(ct.origin_lps_mm())},
                {"direction_lps", matrixJson(ct.direction_lps())},
                {"centre_lps_mm", vectorJson(ct.centre_lps_mm())},
                {"hu_range", json::array({lo, hi})},
                {"description", ct.description},
                {"series", series},
                {"warnings", loaded.warnings()}};
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("CT            {}\n", options.path);
  fmt::print("dims          {} x {} x {} voxels\n", ct.dims().x(), ct.dims().y(), ct.dims().z());
  fmt::print("spacing       {:.4g} x {:.4g} x {:.4g} mm\n", ct.spacing_mm().x(), ct.spacing_mm().y(), ct.spacing_mm().z());
  fmt::print("origin (LPS)  ({:.3f}, {:.3f}, {:.3f}) mm\n", ct.origin_lps_mm().x(), ct.origin_lps_mm().y(),
             ct.origin_lps_mm().z());
  const Eigen::Matrix3d& d = ct.direction_lps();
  fmt::print("direction     i ({:.4f}, {:.4f}, {:.4f})  j ({:.4f}, {:.4f}, {:.4f})  k ({:.4f}, {:.4f}, {:.4f})\n", d(0, 0),
             d(1, 0), d(2, 0), d(0, 1), d(1, 1), d(2, 1), d(0, 2), d(1, 2), d(2, 2));
  fmt::print("values        {:.0f} .. {:.0f} HU\n", lo, hi);
  for (const auto& s : series) {
    fmt::print("series        {} ({} files, {}) {}\n", s["uid"].get<std::string>(), s["files"].get<int>(),
               s["modality"].get<std::string>(), s["description"].get<std::string>());
  }
  if (!ct.description.empty()) fmt::print("source        {}\n", ct.description);
  for (const auto& warning : loaded.warnings()) fmt::print("warning       {}\n", warning);
  return 0;
}

/// Geometry of a camera as the view-file keys name it.
json cameraJson(const Camera& camera) {
  const auto& in = camera.intrinsics();
  return {{"source_to_detector_mm", in.sourceToDetector_mm},
          {"pixel_spacing_mm", vectorJson(in.pixelSpacing_mm)},
          {"principal_point_px", vectorJson(in.principalPoint_px)},
          {"T_world_from_camera", matrixJson(camera.T_world_from_camera().matrix())}};
}

int printXray(const InfoOptions& options) {
  XrayDicomHeader header;
  std::vector<std::string> warnings;
  json geometry = nullptr;
  json tags = json::object();
  if (XrayLoader::isPlainImageFile(options.path)) {
    const auto image = XrayLoader::load(options.path, options.frame);
    if (!image.ok()) return reportError(image.error());
    header.modality = image.value().modality;
    header.photometric = image.value().photometric;
    header.cols = image.value().cols;
    header.rows = image.value().rows;
    header.bitsStored = image.value().bitsStored;
    header.missingGeometry = {"source_to_detector_mm", "detector.pixel_spacing_mm", "principal_point_px",
                              "T_world_from_camera (a PNG/TIFF carries no geometry: give it in a view file)"};
    warnings = image.warnings();
  } else {
    const auto read = XrayDicomReader::readHeader(options.path);
    if (!read.ok()) return reportError(read.error());
    header = read.value();
    warnings = read.warnings();
    const auto& g = header.geometry;
    if (g.sourceToDetector_mm) tags["source_to_detector_mm"] = *g.sourceToDetector_mm;
    if (g.sourceToPatient_mm) tags["source_to_patient_mm"] = *g.sourceToPatient_mm;
    if (g.pixelSpacing_mm) tags["pixel_spacing_mm"] = vectorJson(*g.pixelSpacing_mm);
    if (g.primaryAngle_deg) tags["primary_angle_deg"] = *g.primaryAngle_deg;
    if (g.secondaryAngle_deg) tags["secondary_angle_deg"] = *g.secondaryAngle_deg;
    if (g.detectorActiveOrigin_mm) tags["detector_active_origin_mm"] = vectorJson(*g.detectorActiveOrigin_mm);
    if (header.missingGeometry.empty()) {
      const auto camera = XrayGeometryReader::cameraFromTags(g, header.cols, header.rows);
      if (camera.ok()) {
        geometry = cameraJson(camera.value());
        geometry["tags"] = tags;
        for (const auto& w : camera.warnings()) warnings.push_back(w);
      } else {
        warnings.push_back(camera.error());
      }
    }
  }
  if (options.frame < 0 || options.frame >= header.frames) {
    return reportError(fmt::format("frame {} does not exist: '{}' has {} frame(s) (0-based)", options.frame,
                                   options.path, header.frames));
  }
  if (options.json) {
    json out = {{"type", "xray"},
                {"path", options.path},
                {"modality", header.modality},
                {"cols", header.cols},
                {"rows", header.rows},
                {"frames", header.frames},
                {"bits_stored", header.bitsStored},
                {"photometric", header.photometric},
                {"transfer_syntax", header.transferSyntax},
                {"geometry", geometry},
                {"geometry_tags", tags},
                {"missing_geometry", header.missingGeometry},
                {"warnings", warnings}};
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("X-ray         {}\n", options.path);
  fmt::print("modality      {}\n", header.modality);
  fmt::print("size          {} x {} pixels, {} frame(s)\n", header.cols, header.rows, header.frames);
  fmt::print("pixels        {} bits stored, {}{}\n", header.bitsStored, header.photometric,
             header.transferSyntax.empty() ? "" : ", " + header.transferSyntax);
  for (const auto& [key, value] : tags.items()) fmt::print("tag           {} = {}\n", key, value.dump());
  if (!geometry.is_null()) {
    fmt::print("geometry      complete: camera built from the tags (SID {} mm, principal point {})\n",
               geometry["source_to_detector_mm"].dump(), geometry["principal_point_px"].dump());
  } else {
    fmt::print("geometry      incomplete; missing: {}\n", fmt::join(header.missingGeometry, "; "));
    fmt::print("              supply them in a view file (see README, \"View file\")\n");
  }
  for (const auto& warning : warnings) fmt::print("warning       {}\n", warning);
  return 0;
}

}  // namespace

void registerInfoCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand(
      "info", "Describe a CT (DICOM folder, .nii/.nii.gz/.nrrd/.mha) or an X-ray (DICOM, .png, .tif)");
  command->add_option("PATH", options->path, "CT folder or file, or X-ray file")->required();
  command->add_flag("--json", options->json, "Print exactly one JSON object on stdout");
  command->add_option("--series", options->seriesUid, "DICOM SeriesInstanceUID to read (default: the largest series)");
  command->add_flag("--refuse-irregular", options->refuseIrregular,
                    "Fail on a gantry-tilted or irregularly spaced series instead of resampling it");
  command->add_option("--resample-mm", options->resample_mm,
                      "Slice spacing for resampling a tilted/irregular series (default: the smallest gap)");
  command->add_option("--frame", options->frame, "Frame of a multi-frame X-ray (0-based)");
  command->callback([&action, options] {
    action = [options]() -> int {
      std::error_code ec;
      const fs::path path(options->path);
      if (!fs::exists(path, ec)) {
        return reportError(fmt::format("no such file or folder: '{}'", options->path));
      }
      if (fs::is_directory(path, ec) || isVolumeFile(path)) return printCt(*options);
      return printXray(*options);
    };
  });
}

}  // namespace fct::cli
