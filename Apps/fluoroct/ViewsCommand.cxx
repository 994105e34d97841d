// fluoroct views: writes a view file, either of standard C-arm views (AP, lateral, obliques) around a CT's centre, or
// of one view per X-ray DICOM file from its C-arm geometry tags (--from-dicom).
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <memory>
#include <string>
#include <vector>

#include "CliSupport.h"
#include "IO/Project/DicomViewBuilder.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/CtLoader.h"
#include "Simulation/StandardViews.h"

namespace fct::cli {

namespace {

struct Options {
  std::string ct;
  std::vector<std::string> fromDicom;
  std::string out;
  std::string detector = "800x600";
  std::string imagePrefix;
  StandardViewOptions views;
  int frame = -1;  // -1: not given
  double sid_mm = 0.0, sod_mm = 0.0;
  std::vector<double> pixelSpacing_mm;
};

int writeStandardViews(Options& o) {
  int cols = 0, rows = 0;
  if (!parseDetectorSize(o.detector, cols, rows)) {
    return reportError(fmt::format("--detector must be COLSxROWS, e.g. 800x600, got '{}'", o.detector));
  }
  o.views.cols = cols;
  o.views.rows = rows;
  auto ct = CtLoader::load(o.ct);
  if (!ct.ok()) return reportError(ct.error());
  const Eigen::Vector3d centre_mm = ct.value().centre_lps_mm();
  auto views = StandardViews::build(centre_mm, o.views);
  if (!views.ok()) return reportError(views.error());
  if (!o.imagePrefix.empty()) {
    for (ViewSpec& view : views.value()) view.imagePath = o.imagePrefix + "_" + view.name + ".png";
  }
  const Status written = ViewFile::write(views.value(), o.out);
  if (!written.ok()) return reportError(written.error());
  std::string names;
  for (const ViewSpec& view : views.value()) names += (names.empty() ? "" : ", ") + view.name;
  fmt::print("wrote {}: {} views ({}) at isocentre LPS ({:.1f}, {:.1f}, {:.1f}) mm, SID {} mm, SAD {} mm, "
             "detector {}x{} at {} mm\n",
             o.out, views.value().size(), names, centre_mm.x(), centre_mm.y(), centre_mm.z(),
             o.views.sourceToDetector_mm, o.views.sourceToIsocentre_mm, cols, rows, o.views.pixelSpacing_mm);
  return 0;
}

int writeDicomViews(const Options& o) {
  DicomViewOptions options;
  if (o.frame >= 0) options.frame = o.frame;
  if (o.sid_mm > 0.0) options.overrides.sourceToDetector_mm = o.sid_mm;
  if (o.sod_mm > 0.0) options.overrides.sourceToPatient_mm = o.sod_mm;
  if (o.pixelSpacing_mm.size() == 1) {
    options.overrides.pixelSpacing_mm = Eigen::Vector2d(o.pixelSpacing_mm[0], o.pixelSpacing_mm[0]);
  } else if (o.pixelSpacing_mm.size() == 2) {
    options.overrides.pixelSpacing_mm = Eigen::Vector2d(o.pixelSpacing_mm[0], o.pixelSpacing_mm[1]);
  }
  const std::vector<std::filesystem::path> files(o.fromDicom.begin(), o.fromDicom.end());
  auto views = DicomViewBuilder::build(files, options);
  if (!views.ok()) {
    // The message names the view-file key of each missing value; offer the flag that supplies just those.
    std::vector<std::string> flags;
    for (const auto& [key, flag] : {std::pair{"source_to_detector_mm", "--sid-mm (source to detector)"},
                                    std::pair{"source_to_patient_mm", "--sod-mm (source to isocentre)"},
                                    std::pair{"detector.pixel_spacing_mm", "--pixel-spacing-mm (detector pixel size)"}}) {
      if (views.error().find(key) != std::string::npos) flags.emplace_back(flag);
    }
    const std::string hint = flags.empty() ? "" : fmt::format("; or give {}", fmt::join(flags, " and "));
    return reportError(views.error() + hint);
  }
  printWarnings(views.warnings());
  if (const Status written = ViewFile::write(views.value(), o.out); !written.ok()) return reportError(written.error());
  fmt::print("wrote {}: {} view{} from DICOM geometry tags\n", o.out, views.value().size(),
             views.value().size() == 1 ? "" : "s");
  for (const ViewSpec& view : views.value()) {
    const CameraIntrinsics& in = view.camera.intrinsics();
    const Eigen::Vector3d source_mm = view.camera.sourcePosition_world_mm();
    fmt::print("  {}: {} frame {}{}, {}x{} px at [{}, {}] mm, SID {} mm, source at LPS ({:.1f}, {:.1f}, {:.1f}) mm\n",
               view.name, view.imagePath.filename().string(), view.frame, view.mirrorColumns ? " (mirrored)" : "",
               in.cols, in.rows, in.pixelSpacing_mm.x(), in.pixelSpacing_mm.y(), in.sourceToDetector_mm, source_mm.x(),
               source_mm.y(), source_mm.z());
  }
  return 0;
}

}  // namespace

void registerViewsCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "views", "Write a view file: standard C-arm views (ap, lateral, oblique45, oblique30, oblique60) looking at the "
               "CT's centre (--ct), or one view per X-ray DICOM file from its C-arm geometry tags (--from-dicom)");
  auto* ct = command->add_option("--ct", options->ct,
                                 "CT: DICOM series folder or volume file (.nii, .nii.gz, .nrrd, .mha)");
  auto* fromDicom = command->add_option("--from-dicom", options->fromDicom,
                                        "X-ray DICOM files (XA, RF, DX, CR): one view each, camera from the C-arm tags "
                                        "(SID, SOD, ImagerPixelSpacing, positioner angles, PatientOrientation)");
  ct->excludes(fromDicom);
  command->add_option("--out", options->out, "Output view file (.json)")->required();
  command->add_option("--count", options->views.count, "Number of views, 1..5")->capture_default_str();
  auto* sid = command->add_option("--sid-mm", options->views.sourceToDetector_mm, "Source-to-detector distance in mm (with --from-dicom: replaces or supplies (0018,1110))")
                  ->capture_default_str();
  command->add_option("--sad-mm", options->views.sourceToIsocentre_mm, "Source-to-isocentre distance in mm")
      ->capture_default_str();
  command->add_option("--detector", options->detector, "Detector size in pixels, COLSxROWS")->capture_default_str();
  command->add_option("--pixel-mm", options->views.pixelSpacing_mm, "Detector pixel size in mm")->capture_default_str();
  command->add_option("--tilt-deg", options->views.obliqueTilt_deg, "Cranial/caudal tilt of the oblique views in degrees")
      ->capture_default_str();
  command->add_option("--images", options->imagePrefix,
                      "Set each view's image to PREFIX_<view>.png (relative to the current folder)");
  command->add_option("--frame", options->frame, "With --from-dicom: frame of every multi-frame file (0-based)")
      ->check(CLI::NonNegativeNumber)
      ->needs(fromDicom);
  command->add_option("--sod-mm", options->sod_mm,
                      "With --from-dicom: source-to-isocentre distance in mm, replacing or supplying (0018,1111)")
      ->check(positiveNumber())
      ->needs(fromDicom);
  command->add_option("--pixel-spacing-mm", options->pixelSpacing_mm,
                      "With --from-dicom: detector pixel size in mm, one value or DU DV (along columns, rows), "
                      "replacing or supplying ImagerPixelSpacing (0018,1164)")
      ->expected(1, 2)
      ->check(positiveNumber())
      ->needs(fromDicom);
  command->callback([&action, options, ct, fromDicom, sid] {
    action = [options, ct, fromDicom, sid] {
      if (fromDicom->count() > 0) {
        options->sid_mm = sid->count() > 0 ? options->views.sourceToDetector_mm : 0.0;
        return writeDicomViews(*options);
      }
      if (ct->count() == 0) return reportError("views needs --ct (standard views) or --from-dicom FILE... (DICOM views)");
      return writeStandardViews(*options);
    };
  });
}

}  // namespace fct::cli
