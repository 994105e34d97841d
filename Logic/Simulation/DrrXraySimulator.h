#pragma once
// DrrXraySimulator: makes a registration case from a CT: for each C-arm view, the attenuation DRR p at a known bone
// pose becomes a raw fluoroscopy-like detector image I = I0 · exp(-p) (bright where more signal arrives, bone dark),
// optionally with Poisson quantum noise, written as 16-bit PNGs with a view file, the true pose and the parameters.

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Drr/DrrRenderer.h"
#include "Drr/DrrRendererFactory.h"
#include "Image/FloatImage.h"
#include "Image/Volume.h"
#include "IO/Project/ViewFile.h"
#include "Simulation/SimulatedCaseWriter.h"

namespace fct {

/// Physics and randomness of the simulated X-rays.
struct XraySimulationOptions {
  DrrMethod method = DrrMethod::Siddon;  ///< DRR method used to render p
  double unattenuatedIntensity = 60000.0;  ///< I0: detector value of a ray through air (16-bit PNG, headroom for noise)
  double noisePhotons = 0.0;  ///< N: photons per pixel of an unattenuated ray; 0 = noiseless
  std::uint32_t seed = 1;     ///< noise seed; the same seed gives the same images
};

/// Simulates fluoroscopic X-ray images from a CT.
class DrrXraySimulator {
 public:
  /// Detector image of an attenuation DRR (values p >= 0, dimensionless): I = I0 · exp(-p) without noise; with
  /// N = noisePhotons > 0, I = I0 · k / N with k ~ Poisson(N · exp(-p)) drawn per pixel from `seed` (rows use
  /// independent streams, so the result does not depend on the thread count). Fails on an empty image, a
  /// non-positive or non-finite I0, a negative or non-finite N, or a negative or non-finite p.
  static Result<FloatImage> intensityFromDrr(const FloatImage& drr, double unattenuatedIntensity, double noisePhotons,
                                             std::uint32_t seed);

  /// Renders every view's full-detector attenuation DRR of `ct` at T_world_from_ct (CT LPS mm -> world LPS mm),
  /// turns it into a detector image (intensityFromDrr; view n uses seed + n) and writes, in `outDir` (created if
  /// missing): <view>.png (16-bit, values clamped to 0..65535), views.json, truth_pose.json and simulation.json
  /// (every parameter, `ctSource` as the CT's name). All images are computed before anything is written; each
  /// file is written atomically. Fails on an empty view list, a view name unusable as a file name, an invalid
  /// option, a DRR error, or an unwritable folder.
  static Result<SimulatedCase> writeCase(const Volume& ct, const std::vector<ViewSpec>& views,
                                         const Eigen::Isometry3d& T_world_from_ct, const XraySimulationOptions& options,
                                         const std::filesystem::path& outDir, const std::string& ctSource);
};

}  // namespace fct
