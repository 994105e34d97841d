// fluoroct dewarp-calibrate: fits the image-intensifier dewarp of a C-arm from an X-ray of a calibration plate with
// beads on a square grid, prints the residuals per polynomial degree and writes the dewarp file that a view file
// names with its "dewarp" key.
#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <string>

#include "CliSupport.h"
#include "IO/Project/DewarpFile.h"
#include "IO/Xray/XrayLoader.h"
#include "XrayPrep/DewarpCalibrator.h"
#include "XrayPrep/FieldOfViewDetector.h"

namespace fct::cli {

void registerDewarpCalibrateCommand(CLI::App& app, CommandAction& action) {
  struct Options {
    std::string grid;
    std::string out;
    int frame = 0;
    DewarpCalibrationOptions calibration;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "dewarp-calibrate", "Fit the image-intensifier dewarp from an X-ray of a bead grid plate and write a dewarp file");
  command->add_option("grid", options->grid, "X-ray of the calibration plate (DICOM, PNG or TIFF; beads dark)")
      ->required();
  command->add_option("--pitch-mm", options->calibration.pitch_mm, "Bead pitch of the plate in mm")
      ->required()
      ->check(positiveNumber());
  command->add_option("--out", options->out, "Dewarp file to write (JSON)")->required();
  command->add_option("--pixel-spacing-mm", options->calibration.pixelSpacing_mm,
                      "Detector pixel size in mm, to check the pitch (the plate's magnification must be 0.9..1.8); "
                      "default: the DICOM image's, else the pitch is not checked")
      ->check(positiveNumber());
  command->add_option("--degree", options->calibration.degree,
                      "Polynomial degree 2..9; default: the highest of 2..7 within 2 % of the best cross-validated "
                      "residual");
  command->add_option("--frame", options->frame, "Frame of a multi-frame image (0-based)")->capture_default_str();
  command->callback([&action, options] {
    action = [options] {
      auto grid = XrayLoader::load(options->grid, options->frame);
      if (!grid) return reportError(grid.error());
      printWarnings(grid.warnings());
      const XrayImage& xray = grid.value();
      DewarpCalibrationOptions calibration = options->calibration;
      if (calibration.pixelSpacing_mm == 0.0 && xray.camera) {
        calibration.pixelSpacing_mm = xray.camera->intrinsics().pixelSpacing_mm.mean();
      }
      if (calibration.pixelSpacing_mm == 0.0) {
        printWarnings({"the pixel spacing is unknown, so --pitch-mm is not checked; give --pixel-spacing-mm"});
      }
      const FloatImage image{xray.cols, xray.rows, xray.pixels};
      auto field = FieldOfViewDetector().detect(image);
      if (!field) return reportError("field-of-view detection: " + field.error());
      ValidMask mask = field.value().mask;
      if (!xray.fovMask.empty()) {
        auto given = ValidMask::fromBytes(xray.cols, xray.rows, xray.fovMask);
        if (!given) return reportError(given.error());
        (void)mask.intersect(given.value());
      }
      auto calibrated = DewarpCalibrator(calibration).calibrate(image, mask);
      if (!calibrated) {
        return reportError(fmt::format("{}: {}", options->grid, calibrated.error()));
      }
      const DewarpCalibrationResult& result = calibrated.value();
      DewarpFileContents contents{result.field, result.record};
      contents.calibration.gridImage = std::filesystem::path(options->grid).filename().string();
      const DewarpCalibration& r = contents.calibration;
      fmt::print("{} beads on the grid around the centre bead ({} more found off it)\n", result.beads.size(),
                 result.unindexedBeadCount);
      fmt::print("ideal lattice: pitch {:.3f} px, rotation {:.3f} deg", r.latticePitch_px, r.latticeRotation_deg);
      if (r.magnification > 0.0) {
        fmt::print(", magnification {:.4f} at {} mm pixels", r.magnification, calibration.pixelSpacing_mm);
      }
      fmt::print("\n{:>6}  {:>14}  {:>26}\n", "degree", "fit RMS (px)", "cross-validated RMS (px)");
      for (const DewarpDegreeResidual& d : result.degrees) {
        fmt::print("{:>6}  {:>14.4f}  {:>26}\n", d.degree, d.fitRms_px,
                   options->calibration.degree ? std::string("-") : fmt::format("{:.4f}", d.crossValidatedRms_px));
      }
      fmt::print("polynomial degree {}{}: residual RMS {:.4f} px, max {:.4f} px over {} beads ({} left out as outliers)\n",
                 result.field.degree(),
                 options->calibration.degree ? " (given)" : " (highest within 2 % of the best cross-validated RMS)",
                 r.rmsResidual_px, r.maxResidual_px, r.beadCount, r.rejectedBeadCount);
      if (Status written = DewarpFile::write(contents, options->out); !written) return reportError(written.error());
      fmt::print("wrote {}\n", options->out);
      return 0;
    };
  });
}

}  // namespace fct::cli
