#include "Simulation/DrrXraySimulator.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "Base/SeededRandom.h"
#include "Drr/DrrVolume.h"

namespace fct {

Result<FloatImage> DrrXraySimulator::intensityFromDrr(const FloatImage& drr, double unattenuatedIntensity,
                                                      double noisePhotons, std::uint32_t seed) {
  if (drr.empty() || drr.pixels.size() != static_cast<std::size_t>(drr.cols) * drr.rows) {
    return fail("cannot simulate an X-ray from an empty or inconsistent DRR");
  }
  if (!std::isfinite(unattenuatedIntensity) || unattenuatedIntensity <= 0.0) {
    return fail(fmt::format("unattenuated intensity I0 must be positive, got {}", unattenuatedIntensity));
  }
  if (!std::isfinite(noisePhotons) || noisePhotons < 0.0) {
    return fail(fmt::format("noise photon count must be 0 (no noise) or positive, got {}", noisePhotons));
  }
  const auto bad = std::find_if(drr.pixels.begin(), drr.pixels.end(), [](float p) { return !(p >= 0.0f) || !std::isfinite(p); });
  if (bad != drr.pixels.end()) {
    return fail(fmt::format("DRR pixel {} has line integral {}; an attenuation DRR must be finite and >= 0",
                            bad - drr.pixels.begin(), *bad));
  }
  FloatImage image = FloatImage::filled(drr.cols, drr.rows);
  tbb::parallel_for(0, drr.rows, [&](int row) {
    const std::size_t begin = static_cast<std::size_t>(row) * drr.cols;
    if (noisePhotons == 0.0) {
      for (int col = 0; col < drr.cols; ++col) {
        image.pixels[begin + col] = static_cast<float>(unattenuatedIntensity * std::exp(-double(drr.pixels[begin + col])));
      }
      return;
    }
    SeededRandom random(SeededRandom::streamSeed(seed, static_cast<std::uint32_t>(row)));
    const double intensityPerPhoton = unattenuatedIntensity / noisePhotons;
    for (int col = 0; col < drr.cols; ++col) {
      const double expected = noisePhotons * std::exp(-double(drr.pixels[begin + col]));
      image.pixels[begin + col] = static_cast<float>(intensityPerPhoton * static_cast<double>(random.poisson(expected)));
    }
  });
  return image;
}

Result<SimulatedCase> DrrXraySimulator::writeCase(const Volume& ct, const std::vector<ViewSpec>& views,
                                                  const Eigen::Isometry3d& T_world_from_ct,
                                                  const XraySimulationOptions& options,
                                                  const std::filesystem::path& outDir, const std::string& ctSource) {
  if (Status checked = SimulatedCaseWriter::checkViews(views); !checked) return fail(checked.error());
  if (!std::isfinite(options.unattenuatedIntensity) || options.unattenuatedIntensity <= 0.0 ||
      options.unattenuatedIntensity > 65535.0) {
    return fail(fmt::format("unattenuated intensity I0 must be in (0, 65535] to fit a 16-bit PNG, got {}",
                            options.unattenuatedIntensity));
  }

  auto drrVolume = DrrVolume::create(ct);
  if (!drrVolume.ok()) return fail(drrVolume.error());
  const double waterAttenuation_per_mm = drrVolume.value().options().waterAttenuation_per_mm;
  DrrRendererOptions rendererOptions;
  rendererOptions.method = options.method;
  auto renderer =
      DrrRendererFactory::create(std::make_shared<const DrrVolume>(std::move(drrVolume).value()), rendererOptions);
  if (!renderer.ok()) return fail(renderer.error());

  // Compute every image first, so that a failure writes nothing.
  std::vector<double> maxLineIntegral;
  std::vector<FloatImage> images;
  for (std::size_t n = 0; n < views.size(); ++n) {
    auto drr = renderer.value()->render(views[n].camera, T_world_from_ct, 0);
    if (!drr.ok()) return fail(fmt::format("view '{}': {}", views[n].name, drr.error()));
    maxLineIntegral.push_back(*std::max_element(drr.value().pixels.begin(), drr.value().pixels.end()));
    auto image = intensityFromDrr(drr.value(), options.unattenuatedIntensity, options.noisePhotons,
                                  options.seed + static_cast<std::uint32_t>(n));
    if (!image.ok()) return fail(fmt::format("view '{}': {}", views[n].name, image.error()));
    images.push_back(std::move(image).value());
  }

  nlohmann::ordered_json parameters;
  parameters["model"] = "drr";
  parameters["ct"] = ctSource;
  parameters["method"] = std::string(DrrRendererFactory::methodName(options.method));
  parameters["drr_values"] = std::string(DrrVolume::valueKindName(DrrValueKind::Attenuation));
  parameters["water_attenuation_per_mm"] = waterAttenuation_per_mm;
  parameters["intensity_model"] = "I = I0 * exp(-p); with noise I = I0 * k / N, k ~ Poisson(N * exp(-p))";
  parameters["i0"] = options.unattenuatedIntensity;
  parameters["noise_photons"] = options.noisePhotons;
  parameters["seed"] = options.seed;
  parameters["png"] = "16-bit grey, value = I rounded and clamped to 0..65535, MONOCHROME2 (bright = more signal)";
  nlohmann::ordered_json perView = nlohmann::ordered_json::array();
  for (std::size_t n = 0; n < views.size(); ++n) {
    perView.push_back({{"name", views[n].name},
                       {"image", views[n].name + ".png"},
                       {"seed", options.seed + static_cast<std::uint32_t>(n)},
                       {"max_line_integral", maxLineIntegral[n]}});
  }
  parameters["images"] = perView;
  auto written = SimulatedCaseWriter::write(views, images, {}, T_world_from_ct, parameters, outDir);
  if (!written.ok()) return fail(written.error());
  written.value().maxLineIntegral = std::move(maxLineIntegral);
  return written;
}

}  // namespace fct
