// fluoroct simulate: renders simulated fluoroscopic X-rays (DRRs with optional quantum noise) of a CT at a known pose
// and writes a ready-to-register case folder (images, view file, true pose, parameters).
#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include "CliSupport.h"
#include "CtVolumeReader.h"
#include "DrrXraySimulator.h"
#include "PoseFile.h"
#include "ViewFile.h"

namespace fct::cli {

void registerSimulateCommand(CLI::App& app, CommandAction& action) {
  struct Options {
    std::string ct;
    std::string views;
    std::string pose;
    std::string out;
    std::string method = "siddon";
    XraySimulationOptions simulation;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "simulate", "Simulate fluoroscopic X-rays of a CT at a pose: writes DIR/<view>.png (16-bit), DIR/views.json, "
                  "DIR/truth_pose.json and DIR/simulation.json");
  command->add_option("--ct", options->ct, "CT: DICOM series folder or volume file (.nii, .nii.gz, .nrrd, .mha)")
      ->required();
  command->add_option("--views", options->views, "View file with the C-arm cameras (e.g. from 'fluoroct views')")
      ->required();
  command->add_option("--pose", options->pose, "Pose file with the true T_world_from_ct")->required();
  command->add_option("--out", options->out, "Output folder (created if missing)")->required();
  command->add_option("--method", options->method, "DRR method: siddon or raycast")->capture_default_str();
  command->add_option("--noise-photons", options->simulation.noisePhotons,
                      "Photons per pixel of an unattenuated ray for Poisson noise; 0 = no noise")
      ->capture_default_str();
  command->add_option("--seed", options->simulation.seed, "Noise seed")->capture_default_str();
  command->add_option("--i0", options->simulation.unattenuatedIntensity,
                      "Image value of an unattenuated ray (I = I0 exp(-p)), at most 65535")
      ->capture_default_str();
  command->callback([&action, options] {
    action = [options] {
      auto method = DrrRendererFactory::parseMethod(options->method);
      if (!method.ok()) return reportError(method.error());
      options->simulation.method = method.value();
      auto views = ViewFile::read(options->views);
      if (!views.ok()) return reportError(views.error());
      auto pose = PoseFile::read(options->pose);
      if (!pose.ok()) return reportError(pose.error());
      auto ct = CtVolumeReader::read(options->ct);
      if (!ct.ok()) return reportError(ct.error());
      for (const std::string& warning : ct.warnings()) fmt::print(stderr, "warning: {}\n", warning);
      std::error_code ec;
      const std::filesystem::path ctPath = std::filesystem::absolute(options->ct, ec);
      auto simulated = DrrXraySimulator::writeCase(ct.value(), views.value(), pose.value(), options->simulation,
                                                   options->out, ec ? options->ct : ctPath.string());
      if (!simulated.ok()) return reportError(simulated.error());
      for (std::size_t n = 0; n < simulated.value().views.size(); ++n) {
        const ViewSpec& view = simulated.value().views[n];
        fmt::print("wrote {} ({}x{}, max line integral {:.2f})\n", view.imagePath.string(),
                   view.camera.intrinsics().cols, view.camera.intrinsics().rows, simulated.value().maxLineIntegral[n]);
      }
      fmt::print("wrote {}, {} and {}\n", simulated.value().viewFile.string(), simulated.value().poseFile.string(),
                 simulated.value().parameterFile.string());
      return 0;
    };
  });
}

}  // namespace fct::cli
