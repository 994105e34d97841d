#include "Evaluation/StudyXraySource.h"

#include <fmt/format.h>

#include <cmath>

#include "Simulation/CtSliceDegrader.h"
#include "Simulation/FluoroscopySimulator.h"

namespace fct {

namespace {

/// The simulated C-arm: 80 kVp polyenergetic beam, quantum noise, detector blur and vignetting; no distortion,
/// collimator or foreign objects (those are studied separately).
FluoroscopyOptions studyOptions() {
  FluoroscopyOptions o;
  o.tubeVoltage_kvp = 80.0;
  o.photonsPerPixel = 10000.0;
  o.psfSigma_px = 0.7;
  o.vignetting = 0.1;
  return o;
}

}  // namespace

std::string StudyXraySource::description() {
  const FluoroscopyOptions o = studyOptions();
  return fmt::format("FluoroscopySimulator on the original CT (exact material path lengths, {:g} kVp spectrum with "
                     "NIST attenuation, automatic exposure, Poisson noise at {:g} photons per pixel at the reference level, PSF sigma {:g} px, vignetting "
                     "{:g}; no distortion, collimator or foreign objects): a forward model independent of "
                     "registration's DRR",
                     o.tubeVoltage_kvp, o.photonsPerPixel, o.psfSigma_px, o.vignetting);
}

Result<std::vector<RegistrationView>> StudyXraySource::simulate(const Volume& ct, const std::vector<ViewSpec>& views,
                                                                const Eigen::Isometry3d& T_world_from_ct,
                                                                std::uint32_t seed) {
  FluoroscopyOptions options = studyOptions();
  options.seed = seed;
  std::vector<RegistrationView> out;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const ViewSpec& spec = views[v];
    auto image = FluoroscopySimulator::render(ct, spec.camera, T_world_from_ct, options,
                                              seed + static_cast<std::uint32_t>(v));
    if (!image) return fail(fmt::format("view '{}': {}", spec.name, image.error()));
    XrayImage xray;
    xray.cols = image.value().cols;
    xray.rows = image.value().rows;
    xray.modality = "simulated";
    xray.pixels = std::move(image.value().pixels);
    out.push_back(RegistrationView{spec.name, std::move(xray), spec.camera, {}});
  }
  return out;
}

Result<Volume> StudyXraySource::registrationCt(const Volume& ct, double sliceSpacing_mm) {
  if (!std::isfinite(sliceSpacing_mm) || sliceSpacing_mm < 0.0) {
    return fail(fmt::format("slice spacing must be 0 (the original CT) or positive, got {} mm", sliceSpacing_mm));
  }
  if (effectiveSliceSpacing_mm(ct, sliceSpacing_mm) == 0.0) return ct;
  return CtSliceDegrader::degrade(ct, sliceSpacing_mm);
}

double StudyXraySource::effectiveSliceSpacing_mm(const Volume& ct, double sliceSpacing_mm) {
  return sliceSpacing_mm > ct.spacing_mm().z() ? sliceSpacing_mm : 0.0;
}

}  // namespace fct
