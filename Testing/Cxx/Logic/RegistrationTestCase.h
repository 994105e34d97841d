#pragma once
// Known-truth registration cases for the registration tests and benchmark: a CT, the three standard C-arm views
// (StandardViews: AP, lateral, oblique45 tilted) around the bone centre, X-rays simulated in-process by rendering
// DRRs at a truth pose (Siddon) turned into noisy detector images (DrrXraySimulator::intensityFromDrr, Poisson noise
// with the exposure raised per view so that its darkest pixel still gets a few photons, as exposure control does);
// and start poses at a given mean bone-surface distance from the truth (random direction in scaled parameter space,
// fixed seed).

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Drr/DrrRendererFactory.h"
#include "Evaluation/PoseOffset.h"
#include "Geometry/RigidPose.h"
#include "Image/BoneSurface.h"
#include "Image/Volume.h"
#include "Registration/RegistrationCase.h"
#include "Search/PoseOptimizer.h"
#include "Simulation/DrrXraySimulator.h"
#include "Simulation/PhantomBuilder.h"
#include "Simulation/StandardViews.h"

namespace fct::test {

/// The built-in phantom at 80 x 80 x 60 voxels of 2 mm: a small CT for fast registration tests.
inline Volume smallPhantom() {
  PhantomOptions options;
  options.dims = Eigen::Vector3i(80, 80, 60);
  options.spacing_mm = 2.0;
  return PhantomBuilder::build(options).value();
}

/// Detector and noise of a simulated case.
struct KnownTruthOptions {
  int cols = 192;
  int rows = 192;
  double pixelSpacing_mm = 1.6;
  double sourceToIsocentre_mm = 700.0;
  double sourceToDetector_mm = 1000.0;
  double noisePhotons = 2000.0;       ///< photons per unattenuated pixel (Poisson noise), at least:
  double darkestPhotons = 20.0;       ///< photons at the view's darkest pixel (like automatic exposure control)
  double referenceIntensity = 4000;  ///< I0 of the simulated detector
  std::uint32_t seed = 11;
};

/// A CT, views with simulated X-rays, and the truth pose.
struct KnownTruthCase {
  Volume ct;
  std::vector<RegistrationView> views;
  Eigen::Isometry3d T_truth = Eigen::Isometry3d::Identity();
};

/// Builds the case: the truth pose turns the bone by a few degrees about its centroid and puts the centroid near the
/// world origin (the isocentre of the three views). Fails when the CT has no bone or rendering fails.
inline Result<KnownTruthCase> simulateCase(Volume ct, const KnownTruthOptions& o = {}) {
  auto bone = BoneSurface::extract(ct);
  if (!bone) return fail(bone.error());
  KnownTruthCase c;
  const Eigen::Vector3d centre = bone.value().centroid_ct_mm();
  PoseParameters truth;
  truth.rotation_deg = Eigen::Vector3d(4.0, -3.0, 6.0);
  truth.translation_mm = -centre + Eigen::Vector3d(2.0, -3.0, 1.5);
  c.T_truth = RigidPose::toTransform(truth, centre);

  auto drrVolume = DrrVolume::create(ct);
  if (!drrVolume) return fail(drrVolume.error());
  auto renderer = DrrRendererFactory::create(std::make_shared<const DrrVolume>(std::move(drrVolume).value()));
  if (!renderer) return fail(renderer.error());
  StandardViewOptions viewOptions;
  viewOptions.count = 3;
  viewOptions.cols = o.cols;
  viewOptions.rows = o.rows;
  viewOptions.pixelSpacing_mm = o.pixelSpacing_mm;
  viewOptions.sourceToDetector_mm = o.sourceToDetector_mm;
  viewOptions.sourceToIsocentre_mm = o.sourceToIsocentre_mm;
  auto views = StandardViews::build(Eigen::Vector3d::Zero(), viewOptions);
  if (!views) return fail(views.error());
  for (std::size_t v = 0; v < views.value().size(); ++v) {
    const ViewSpec& spec = views.value()[v];
    auto drr = renderer.value()->render(spec.camera, c.T_truth, 0);
    if (!drr) return fail(drr.error());
    const float maxLineIntegral = *std::max_element(drr.value().pixels.begin(), drr.value().pixels.end());
    const double photons = std::max(o.noisePhotons, o.darkestPhotons * std::exp(static_cast<double>(maxLineIntegral)));
    auto intensity = DrrXraySimulator::intensityFromDrr(drr.value(), o.referenceIntensity, photons,
                                                        o.seed + static_cast<std::uint32_t>(v));
    if (!intensity) return fail(intensity.error());
    XrayImage xray;
    xray.cols = o.cols;
    xray.rows = o.rows;
    xray.modality = "simulated";
    xray.pixels = std::move(intensity.value().pixels);
    c.views.push_back(RegistrationView{spec.name, std::move(xray), spec.camera, {}});
  }
  c.ct = std::move(ct);
  return c;
}
/// A start pose whose mean bone-surface distance from `T_truth` is `distance_mm` (PoseOffset's random offset about
/// the case's bone). Deterministic for a seed.
inline Eigen::Isometry3d startPose(const RegistrationCase& registrationCase, const Eigen::Isometry3d& T_truth,
                                   double distance_mm, std::uint32_t seed) {
  return PoseOffset::randomAtSurfaceDistance(*registrationCase.bone(), T_truth, distance_mm, seed).value();
}

}  // namespace fct::test
