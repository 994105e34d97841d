#include "DrrXraySimulator.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <system_error>

#include "DrrVolume.h"
#include "ImageFileWriter.h"
#include "JsonDocument.h"
#include "PoseFile.h"
#include "SeededRandom.h"

namespace fct {

namespace {

/// A seed for row `row` of a stream: an integer hash, so neighbouring rows get unrelated generators.
std::uint32_t rowSeed(std::uint32_t seed, int row) {
  std::uint32_t h = seed * 0x9E3779B9u ^ (static_cast<std::uint32_t>(row) + 0x7F4A7C15u) * 0x85EBCA6Bu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return h;
}

/// True when `name` is usable as a file name on every platform: letters, digits, '-', '_' and '.', not starting with '.'.
bool isSafeFileStem(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
  });
}

}  // namespace

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
    SeededRandom random(rowSeed(seed, row));
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
  if (views.empty()) return fail("no views to simulate; the view file lists none");
  for (const ViewSpec& view : views) {
    if (!isSafeFileStem(view.name)) {
      return fail(fmt::format("view name '{}' cannot name an image file; use letters, digits, '-', '_' or '.'",
                              view.name));
    }
  }
  if (outDir.empty()) return fail("output folder is empty");
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
  SimulatedCase result;
  std::vector<FloatImage> images;
  for (std::size_t n = 0; n < views.size(); ++n) {
    auto drr = renderer.value()->render(views[n].camera, T_world_from_ct, 0);
    if (!drr.ok()) return fail(fmt::format("view '{}': {}", views[n].name, drr.error()));
    result.maxLineIntegral.push_back(*std::max_element(drr.value().pixels.begin(), drr.value().pixels.end()));
    auto image = intensityFromDrr(drr.value(), options.unattenuatedIntensity, options.noisePhotons,
                                  options.seed + static_cast<std::uint32_t>(n));
    if (!image.ok()) return fail(fmt::format("view '{}': {}", views[n].name, image.error()));
    images.push_back(std::move(image).value());
  }

  std::error_code ec;
  std::filesystem::create_directories(outDir, ec);
  if (ec) return fail(fmt::format("cannot create output folder '{}': {}", outDir.string(), ec.message()));
  const std::filesystem::path dir = std::filesystem::absolute(outDir, ec);
  if (ec) return fail(fmt::format("cannot resolve output folder '{}': {}", outDir.string(), ec.message()));

  result.views = views;
  for (std::size_t n = 0; n < views.size(); ++n) {
    result.views[n].imagePath = dir / (views[n].name + ".png");
    result.views[n].frame = 0;
    if (Status written = ImageFileWriter::writePng16(images[n], result.views[n].imagePath, 0.0f, 65535.0f); !written) {
      return fail(written.error());
    }
  }
  result.viewFile = dir / "views.json";
  result.poseFile = dir / "truth_pose.json";
  result.parameterFile = dir / "simulation.json";
  if (Status written = ViewFile::write(result.views, result.viewFile); !written) return fail(written.error());
  if (Status written = PoseFile::write(T_world_from_ct, result.poseFile); !written) return fail(written.error());

  nlohmann::ordered_json parameters;
  parameters["ct"] = ctSource;
  parameters["views"] = "views.json";
  parameters["pose"] = "truth_pose.json";
  parameters["T_world_from_ct"] = JsonDocument::array(T_world_from_ct.matrix());
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
                       {"max_line_integral", result.maxLineIntegral[n]}});
  }
  parameters["images"] = perView;
  if (Status written = JsonDocument::write(parameters, result.parameterFile); !written) return fail(written.error());
  return result;
}

}  // namespace fct
