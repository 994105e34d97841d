#include "StudyXraySource.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "DrrRendererFactory.h"
#include "DrrVolume.h"
#include "DrrXraySimulator.h"

namespace fct {

namespace {

constexpr double kUnattenuatedIntensity = 4000.0;
constexpr double kMinimumPhotons = 2000.0;   ///< photons per unattenuated pixel, at least
constexpr double kDarkestPhotons = 20.0;     ///< photons at the darkest pixel (automatic exposure control)

}  // namespace

std::string StudyXraySource::description() {
  return "DrrXraySimulator: Siddon attenuation DRR of the original CT turned into I0 exp(-p) with Poisson noise "
         "(at least 2000 photons per open pixel, 20 at the darkest); the same ray model as registration's DRRs";
}

Result<std::vector<RegistrationView>> StudyXraySource::simulate(const Volume& ct, const std::vector<ViewSpec>& views,
                                                                const Eigen::Isometry3d& T_world_from_ct,
                                                                std::uint32_t seed) {
  auto drrVolume = DrrVolume::create(ct);
  if (!drrVolume) return fail("simulation CT: " + drrVolume.error());
  auto renderer = DrrRendererFactory::create(std::make_shared<const DrrVolume>(std::move(drrVolume).value()));
  if (!renderer) return fail(renderer.error());
  std::vector<RegistrationView> out;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const ViewSpec& spec = views[v];
    auto drr = renderer.value()->render(spec.camera, T_world_from_ct, 0);
    if (!drr) return fail(fmt::format("view '{}': {}", spec.name, drr.error()));
    const float maxLineIntegral = *std::max_element(drr.value().pixels.begin(), drr.value().pixels.end());
    const double photons = std::max(kMinimumPhotons, kDarkestPhotons * std::exp(static_cast<double>(maxLineIntegral)));
    auto intensity = DrrXraySimulator::intensityFromDrr(drr.value(), kUnattenuatedIntensity, photons,
                                                        seed + static_cast<std::uint32_t>(v));
    if (!intensity) return fail(fmt::format("view '{}': {}", spec.name, intensity.error()));
    XrayImage xray;
    xray.cols = intensity.value().cols;
    xray.rows = intensity.value().rows;
    xray.modality = "simulated";
    xray.pixels = std::move(intensity.value().pixels);
    out.push_back(RegistrationView{spec.name, std::move(xray), spec.camera, {}});
  }
  return out;
}

Result<Volume> StudyXraySource::registrationCt(const Volume& ct, double sliceSpacing_mm) {
  if (!std::isfinite(sliceSpacing_mm) || sliceSpacing_mm < 0.0) {
    return fail(fmt::format("slice spacing must be 0 (the original CT) or positive, got {} mm", sliceSpacing_mm));
  }
  if (sliceSpacing_mm == 0.0) return ct;
  return fail(fmt::format("resampling the CT to {} mm slices needs CtSliceDegrader, which this build does not have; "
                          "run the 'ideal' scenario only",
                          sliceSpacing_mm));
}

}  // namespace fct
