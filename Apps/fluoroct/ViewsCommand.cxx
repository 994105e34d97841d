// fluoroct views: writes a view file of standard C-arm views (AP, lateral, obliques) around a CT's centre.
#include <fmt/core.h>

#include <memory>
#include <string>

#include "CliSupport.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/CtLoader.h"
#include "Simulation/StandardViews.h"

namespace fct::cli {

void registerViewsCommand(CLI::App& app, CommandAction& action) {
  struct Options {
    std::string ct;
    std::string out;
    std::string detector = "800x600";
    std::string imagePrefix;
    StandardViewOptions views;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "views", "Write a view file of standard C-arm views (ap, lateral, oblique45, oblique30, oblique60) looking at "
               "the CT's centre");
  command->add_option("--ct", options->ct, "CT: DICOM series folder or volume file (.nii, .nii.gz, .nrrd, .mha)")
      ->required();
  command->add_option("--out", options->out, "Output view file (.json)")->required();
  command->add_option("--count", options->views.count, "Number of views, 1..5")->capture_default_str();
  command->add_option("--sid-mm", options->views.sourceToDetector_mm, "Source-to-detector distance in mm")
      ->capture_default_str();
  command->add_option("--sad-mm", options->views.sourceToIsocentre_mm, "Source-to-isocentre distance in mm")
      ->capture_default_str();
  command->add_option("--detector", options->detector, "Detector size in pixels, COLSxROWS")->capture_default_str();
  command->add_option("--pixel-mm", options->views.pixelSpacing_mm, "Detector pixel size in mm")->capture_default_str();
  command->add_option("--tilt-deg", options->views.obliqueTilt_deg, "Cranial/caudal tilt of the oblique views in degrees")
      ->capture_default_str();
  command->add_option("--images", options->imagePrefix,
                      "Set each view's image to PREFIX_<view>.png (relative to the current folder)");
  command->callback([&action, options] {
    action = [options] {
      int cols = 0, rows = 0;
      if (!parseDetectorSize(options->detector, cols, rows)) {
        return reportError(fmt::format("--detector must be COLSxROWS, e.g. 800x600, got '{}'", options->detector));
      }
      options->views.cols = cols;
      options->views.rows = rows;
      auto ct = CtLoader::load(options->ct);
      if (!ct.ok()) return reportError(ct.error());
      const Eigen::Vector3d centre_mm = ct.value().centre_lps_mm();
      auto views = StandardViews::build(centre_mm, options->views);
      if (!views.ok()) return reportError(views.error());
      if (!options->imagePrefix.empty()) {
        for (ViewSpec& view : views.value()) view.imagePath = options->imagePrefix + "_" + view.name + ".png";
      }
      const Status written = ViewFile::write(views.value(), options->out);
      if (!written.ok()) return reportError(written.error());
      std::string names;
      for (const ViewSpec& view : views.value()) names += (names.empty() ? "" : ", ") + view.name;
      fmt::print("wrote {}: {} views ({}) at isocentre LPS ({:.1f}, {:.1f}, {:.1f}) mm, SID {} mm, SAD {} mm, "
                 "detector {}x{} at {} mm\n",
                 options->out, views.value().size(), names, centre_mm.x(), centre_mm.y(), centre_mm.z(),
                 options->views.sourceToDetector_mm, options->views.sourceToIsocentre_mm, cols, rows,
                 options->views.pixelSpacing_mm);
      return 0;
    };
  });
}

}  // namespace fct::cli
