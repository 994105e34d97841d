// fluoroct phantom: writes the built-in procedural CT phantom (PhantomBuilder) to a volume file.
#include <fmt/core.h>

#include <array>
#include <memory>
#include <string>

#include "CliSupport.h"
#include "IO/Volume/VolumeFileIO.h"
#include "Simulation/PhantomBuilder.h"

namespace fct::cli {

void registerPhantomCommand(CLI::App& app, CommandAction& action) {
  struct Options {
    std::string out;
    std::array<int, 3> dims{160, 160, 120};
    double spacing_mm = 1.0;
    std::uint32_t seed = 7;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("phantom", "Write the built-in CT phantom (lumbar spine and femur-like shaft, "
                                                    "LPS, centred at the origin) to a .nrrd, .mha or .mhd file");
  command->add_option("--out", options->out, "Output volume file (.nrrd, .mha or .mhd)")->required();
  command->add_option("--dims", options->dims, "Voxels along x y z")->capture_default_str();
  command->add_option("--spacing-mm", options->spacing_mm, "Isotropic voxel size in mm")->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the trabecular texture and noise")->capture_default_str();
  command->callback([&action, options] {
    action = [options] {
      PhantomOptions phantomOptions;
      phantomOptions.dims = Eigen::Vector3i(options->dims[0], options->dims[1], options->dims[2]);
      phantomOptions.spacing_mm = options->spacing_mm;
      phantomOptions.seed = options->seed;
      auto volume = PhantomBuilder::build(phantomOptions);
      if (!volume.ok()) return reportError(volume.error());
      const Status written = VolumeFileIO::write(volume.value(), options->out);
      if (!written.ok()) return reportError(written.error());
      const auto [lo, hi] = volume.value().valueRange();
      fmt::print("wrote {}: phantom {}x{}x{} voxels at {} mm, seed {}, HU {:.0f}..{:.0f}, LPS centre (0,0,0)\n",
                 options->out, options->dims[0], options->dims[1], options->dims[2], options->spacing_mm,
                 options->seed, lo, hi);
      return 0;
    };
  });
}

}  // namespace fct::cli
