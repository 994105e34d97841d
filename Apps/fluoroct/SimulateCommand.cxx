// fluoroct simulate: renders simulated fluoroscopic X-rays of a CT at a known pose — either the registration's own
// DRR with quantum noise (--model drr) or the physical forward model (--model physical: polyenergetic spectrum,
// materials, detector and intensifier effects, foreign objects) — and writes a ready-to-register case folder (images,
// view file, true pose, parameters), optionally with a thick-slice CT for the registration (--ct-slice-mm).
#include <fmt/core.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <memory>
#include <string>
#include <system_error>

#include "Base/JsonDocument.h"
#include "CliSupport.h"
#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/CtLoader.h"
#include "IO/Volume/VolumeFileIO.h"
#include "SequenceCaseWriter.h"
#include "Simulation/BoneMotion.h"
#include "Simulation/CtSliceDegrader.h"
#include "Simulation/DrrXraySimulator.h"
#include "Simulation/FluoroscopySimulator.h"

namespace fct::cli {

namespace {

/// Options that only the physical model reads.
constexpr const char* kPhysicalOnly[] = {"--kvp",          "--filtration-mm-al",     "--monochromatic-kev",
                                         "--psf-px",       "--gain",                 "--offset",
                                         "--gamma",        "--pincushion",           "--s-distortion-deg",
                                         "--vignetting",   "--collimator",           "--kwires",
                                         "--screws",       "--plate",                "--spheres",
                                         "--sphere-pitch-mm", "--fixed-exposure",    "--gas-pockets",
                                         "--grid-pitch-mm", "--patient-extension-mm", "--scatter-to-primary",
                                         "--scatter-sigma-mm"};
/// Options that only the DRR model reads.
constexpr const char* kDrrOnly[] = {"--method", "--i0"};

}  // namespace

void registerSimulateCommand(CLI::App& app, CommandAction& action) {
  struct Options {
    std::string ct;
    std::string views;
    std::string pose;
    std::string out;
    std::string model = "drr";
    std::string method = "siddon";
    double noisePhotons = 0.0;
    std::uint32_t seed = 1;
    double ctSlice_mm = 0.0;
    XraySimulationOptions drr;
    FluoroscopyOptions physical;
    BoneMotionOptions motion{.frames = 0};  ///< frames 0: single images, no sequence
    bool toolsFixed = false;
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
  command->add_option("--model", options->model,
                      "Forward model: drr (the registration's DRR, I = I0 exp(-p)) or physical (polyenergetic, "
                      "materials, detector and intensifier effects; independent of the registration's DRR)")
      ->capture_default_str();
  command->add_option("--noise-photons,--dose", options->noisePhotons,
                      "Photons per pixel for Poisson noise (drr: of an unattenuated ray; physical: at the exposure "
                      "reference level, see --fixed-exposure); 0 = no noise")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the noise (view n uses seed + n) and of object placement")
      ->capture_default_str();
  command->add_option("--ct-slice-mm", options->ctSlice_mm,
                      "Also write DIR/ct_registration.nrrd: the CT resampled to this slice spacing with a matching "
                      "slice-thickness blur (2.4 = the paper's realistic, 4.2 = bad scenario); X-rays use the original")
      ->capture_default_str();
  // DRR model.
  command->add_option("--method", options->method, "drr model: DRR method, siddon or raycast")->capture_default_str();
  command->add_option("--i0", options->drr.unattenuatedIntensity,
                      "drr model: image value of an unattenuated ray (I = I0 exp(-p)), at most 65535")
      ->capture_default_str();
  // Physical model.
  FluoroscopyOptions& p = options->physical;
  command->add_option("--kvp", p.tubeVoltage_kvp, "physical: tube voltage, 50..120 kVp")->capture_default_str();
  command->add_option("--filtration-mm-al", p.filtration_mmAl, "physical: total tube filtration in mm Al")
      ->capture_default_str();
  command->add_option("--monochromatic-kev", p.monochromatic_keV,
                      "physical: a monochromatic beam at this energy (10..150 keV) instead of the tube spectrum, so no "
                      "beam hardening; 0 = the spectrum of --kvp and --filtration-mm-al")
      ->capture_default_str();
  command->add_option("--patient-extension-mm", p.patientExtension_mm,
                      "physical: the patient continues this far (mm, 0..1000) beyond the CT's end faces along its slice "
                      "axis, as anatomy above and below a CT slab does")
      ->capture_default_str();
  command->add_option("--scatter-to-primary", p.scatterToPrimary,
                      "physical: scatter haze, this fraction (0..5) of the blurred primary signal is added; 0 = none")
      ->capture_default_str();
  command->add_option("--scatter-sigma-mm", p.scatterSigma_mm,
                      "physical: scatter haze blur, Gaussian sigma on the detector in mm (1..500)")
      ->capture_default_str();
  command->add_flag("--fixed-exposure", [options](std::int64_t) { options->physical.automaticExposure = false; },
                    "physical: no automatic exposure: --dose and --gain refer to an unattenuated ray instead of the "
                    "image's 99th-percentile level");
  command->add_option("--psf-px", p.psfSigma_px, "physical: Gaussian point-spread sigma in pixels")->capture_default_str();
  command->add_option("--gain", p.gain, "physical: pixel value of an unattenuated ray")->capture_default_str();
  command->add_option("--offset", p.offset, "physical: dark offset added to every pixel")->capture_default_str();
  command->add_option("--gamma", p.gamma, "physical: display gamma (value = offset + gain * signal^gamma)")
      ->capture_default_str();
  command->add_option("--pincushion", p.pincushion,
                      "physical: intensifier pincushion k (r' = r (1 + k (r/R)^2)), -0.1..0.1; writes the distortion "
                      "field as DIR/<view>_distortion_dcol.nrrd and _drow.nrrd")
      ->capture_default_str();
  command->add_option("--s-distortion-deg", p.sDistortion_deg, "physical: intensifier S-distortion at r = R, degrees")
      ->capture_default_str();
  command->add_option("--vignetting", p.vignetting, "physical: brightness loss at the detector corners, 0..0.9")
      ->capture_default_str();
  command->add_option("--collimator", p.collimatorRadiusFraction,
                      "physical: circular collimator radius as a fraction of half the smaller detector side; 0 = none")
      ->capture_default_str();
  command->add_option("--kwires", p.kwireCount, "physical: number of steel K-wires through the bone surface")
      ->capture_default_str();
  command->add_option("--screws", p.screwCount, "physical: number of titanium screws into the bone")
      ->capture_default_str();
  command->add_flag("--plate", p.plate, "physical: a steel bone plate on the bone surface");
  command->add_option("--gas-pockets", p.gasPocketCount,
                      "physical: soft-tissue change, number of bowel-gas pockets near the bone (not in the CT)")
      ->capture_default_str();
  command->add_flag("--spheres", p.calibrationSpheres,
                    "physical: a calibration grid of steel spheres near the detector, listed in views.json");
  command->add_option("--sphere-pitch-mm", p.sphereSpacing_mm, "physical: calibration grid pitch in mm")
      ->capture_default_str();
  command->add_option("--grid-pitch-mm", p.gridPitch_mm,
                      "physical: also write DIR/<view>_grid.png, the view's detector with only a dewarp calibration "
                      "plate (steel beads of radius 1.5 mm at this pitch, 20 mm from the detector; no patient) through "
                      "the same distortion, noise and blur, for 'fluoroct dewarp-calibrate'; 0 = none")
      ->capture_default_str();
  BoneMotionOptions& m = options->motion;
  command->add_option("--frames", m.frames,
                      "physical: write a fluoroscopy sequence of this many frames of the bone moving (DIR/<view>_<k>.tif, "
                      "DIR/views.json with each view's \"sequence\", DIR/truth_track.json) for 'fluoroct track'; 0 = "
                      "single images")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--motion-mm", m.maxTranslation_mm, "sequence: bound of each translation of the bone, mm")
      ->capture_default_str();
  command->add_option("--motion-deg", m.maxRotation_deg, "sequence: bound of each rotation of the bone, degrees")
      ->capture_default_str();
  command->add_option("--motion-period-frames", m.minPeriod_frames,
                      "sequence: shortest period of the smooth motion, frames (sets how fast the bone moves; the longest is "
                      "three times it)")
      ->capture_default_str();
  command->add_option("--jerk-frame", m.jerkFrame,
                      "sequence: frame of a sudden step of the bone (--jerk-mm, --jerk-deg); -1 = none")
      ->capture_default_str();
  command->add_option("--jerk-mm", m.jerkTranslation_mm, "sequence: translation of the jerk, mm")->capture_default_str();
  command->add_option("--jerk-deg", m.jerkRotation_deg, "sequence: rotation of the jerk, degrees")->capture_default_str();
  command->add_option("--motion-seed", m.seed, "sequence: seed of the motion")->capture_default_str();
  command->add_flag("--tools-fixed", options->toolsFixed,
                    "sequence: K-wires, screws and plate stay where they are while the bone moves (held tools)");
  command->callback([&action, options, command] {
    const bool physical = options->model == "physical";
    const auto firstGiven = [command](const auto& names) -> std::string {
      for (const char* name : names) {
        if (command->count(name) > 0) return name;
      }
      return {};
    };
    const std::string misplaced = physical ? firstGiven(kDrrOnly) : firstGiven(kPhysicalOnly);
    action = [options, physical, misplaced] {
      if (options->model != "drr" && options->model != "physical") {
        return reportError(fmt::format("unknown model '{}'; use drr or physical", options->model));
      }
      if (!misplaced.empty()) {
        return reportError(fmt::format("{} does not apply to --model {}", misplaced, options->model));
      }
      if (options->ctSlice_mm < 0.0) {
        return reportError(fmt::format("--ct-slice-mm must be positive (or 0 for none), got {}", options->ctSlice_mm));
      }
      auto views = ViewFile::read(options->views);
      if (!views.ok()) return reportError(views.error());
      auto pose = PoseFile::read(options->pose);
      if (!pose.ok()) return reportError(pose.error());
      auto ct = CtLoader::load(options->ct);
      if (!ct.ok()) return reportError(ct.error());
      printWarnings(ct.warnings());
      std::optional<Volume> registrationCt;
      if (options->ctSlice_mm > 0.0) {
        auto degraded = CtSliceDegrader::degrade(ct.value(), options->ctSlice_mm);
        if (!degraded.ok()) return reportError(degraded.error());
        registrationCt = std::move(degraded).value();
      }
      std::error_code ec;
      const std::filesystem::path ctPath = std::filesystem::absolute(options->ct, ec);
      const std::string ctSource = ec ? options->ct : ctPath.string();
      if (options->motion.frames > 0) {
        if (!physical) return reportError("--frames needs --model physical (the sequence is rendered by the physical simulator)");
        if (options->physical.gridPitch_mm > 0.0) return reportError("--grid-pitch-mm does not apply to a sequence (--frames)");
        if (registrationCt) return reportError("--ct-slice-mm does not apply to a sequence (--frames)");
        options->motion.maxPeriod_frames = 3.0 * options->motion.minPeriod_frames;
        auto motion = BoneMotion::create(options->motion);
        if (!motion.ok()) return reportError(motion.error());
        options->physical.photonsPerPixel = options->noisePhotons;
        options->physical.seed = options->seed;
        auto sequence = SequenceCaseWriter::write(ct.value(), views.value(), pose.value(), motion.value(),
                                                  options->physical, options->toolsFixed, options->out);
        if (!sequence.ok()) return reportError(sequence.error());
        fmt::print("wrote {} ({} frames; track it with fluoroct track --views {}) and {}\n",
                   sequence.value().viewFile.string(), sequence.value().frames, sequence.value().viewFile.string(),
                   sequence.value().truthFile.string());
        return 0;
      }
      Result<SimulatedCase> simulated = fail("no model");
      if (physical) {
        options->physical.photonsPerPixel = options->noisePhotons;
        options->physical.seed = options->seed;
        simulated = FluoroscopySimulator::writeCase(ct.value(), views.value(), pose.value(), options->physical,
                                                    options->out, ctSource);
      } else {
        auto method = DrrRendererFactory::parseMethod(options->method);
        if (!method.ok()) return reportError("--method: " + method.error());
        options->drr.method = method.value();
        options->drr.noisePhotons = options->noisePhotons;
        options->drr.seed = options->seed;
        simulated = DrrXraySimulator::writeCase(ct.value(), views.value(), pose.value(), options->drr, options->out,
                                                ctSource);
      }
      if (!simulated.ok()) {
        // The simulator says it found no room for a gas pocket in its own words; name the option that asked for them.
        const bool noRoomForGas = physical && options->physical.gasPocketCount > 0 &&
                                  simulated.error().find("for a gas pocket") != std::string::npos;
        return reportError(noRoomForGas ? "--gas-pockets: " + simulated.error() : simulated.error());
      }
      for (std::size_t n = 0; n < simulated.value().views.size(); ++n) {
        const ViewSpec& view = simulated.value().views[n];
        fmt::print("wrote {} ({}x{}, max line integral {:.2f})\n", view.imagePath.string(),
                   view.camera.intrinsics().cols, view.camera.intrinsics().rows, simulated.value().maxLineIntegral[n]);
      }
      if (physical && options->physical.gridPitch_mm > 0.0) {
        for (const ViewSpec& view : simulated.value().views) {
          fmt::print("wrote {} (dewarp calibration grid, pitch {} mm)\n",
                     (view.imagePath.parent_path() / (view.name + "_grid.png")).string(), options->physical.gridPitch_mm);
        }
      }
      if (registrationCt) {
        const std::filesystem::path path = std::filesystem::path(options->out) / "ct_registration.nrrd";
        if (Status written = VolumeFileIO::write(*registrationCt, path); !written) return reportError(written.error());
        nlohmann::ordered_json document;
        try {
          std::ifstream file(simulated.value().parameterFile);
          document = nlohmann::ordered_json::parse(file);
        } catch (const nlohmann::json::exception& e) {
          return reportError(fmt::format("cannot re-read {}: {}", simulated.value().parameterFile.string(), e.what()));
        }
        document["registration_ct"] = {{"file", "ct_registration.nrrd"},
                                       {"slice_spacing_mm", options->ctSlice_mm},
                                       {"slice_profile", "box of width slice_spacing_mm over the original slab (spacing rounded to fill it exactly)"}};
        if (Status written = JsonDocument::write(document, simulated.value().parameterFile); !written) {
          return reportError(written.error());
        }
        fmt::print("wrote {} ({} slices of {} mm)\n", path.string(), registrationCt->dims().z(), options->ctSlice_mm);
      }
      fmt::print("wrote {}, {} and {}\n", simulated.value().viewFile.string(), simulated.value().poseFile.string(),
                 simulated.value().parameterFile.string());
      return 0;
    };
  });
}

}  // namespace fct::cli
