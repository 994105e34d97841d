#pragma once
// Known-truth registration cases for the registration tests and benchmark: a CT, three C-arm views (AP, lateral,
// oblique with a cranial tilt) around the bone centre, X-rays simulated in-process by rendering DRRs at a truth pose
// (Siddon), with multiplicative Gaussian noise, converted to intensities I = I0 exp(-p); and start poses at a given
// mean bone-surface distance from the truth (random direction in scaled parameter space, fixed seed).

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "BoneSurface.h"
#include "Camera.h"
#include "DrrRendererFactory.h"
#include "PoseOptimizer.h"
#include "RegistrationCase.h"
#include "Result.h"
#include "RigidPose.h"
#include "SeededRandom.h"
#include "Volume.h"

namespace fct::test {

/// Detector and noise of a simulated case.
struct SimulatedCaseOptions {
  int cols = 256;
  int rows = 256;
  double pixelSpacing_mm = 1.2;
  double sourceToPatient_mm = 700.0;
  double sourceToDetector_mm = 1000.0;
  double noise = 0.01;               ///< standard deviation of the multiplicative intensity noise
  double referenceIntensity = 4000;  ///< I0 of the simulated detector
  std::uint32_t seed = 11;
};

/// A CT with its bone surface, views with simulated X-rays, and the truth pose.
struct SimulatedCase {
  Volume ct;
  std::vector<RegistrationView> views;
  Eigen::Isometry3d T_truth = Eigen::Isometry3d::Identity();
};

/// R_world_from_camera of a view looking along +y (posterior, AP) turned by `primary_deg` about the head-foot axis
/// and tilted by `cranial_deg` about the left-right axis; image rows point to the feet.
inline Eigen::Matrix3d viewRotation(double primary_deg, double cranial_deg) {
  Eigen::Matrix3d R_ap;
  R_ap.col(0) = Eigen::Vector3d(1, 0, 0);
  R_ap.col(1) = Eigen::Vector3d(0, 0, -1);
  R_ap.col(2) = Eigen::Vector3d(0, 1, 0);
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(cranial_deg * d, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(primary_deg * d, Eigen::Vector3d::UnitZ()))
             .toRotationMatrix() *
         R_ap;
}

/// Builds the case: the truth pose turns the bone by a few degrees about its centroid and puts the centroid near the
/// world origin (the isocentre of the three views). Fails when the CT has no bone or rendering fails.
inline Result<SimulatedCase> simulateCase(Volume ct, const SimulatedCaseOptions& o = {}) {
  auto bone = BoneSurface::extract(ct);
  if (!bone) return fail(bone.error());
  SimulatedCase c;
  const Eigen::Vector3d centre = bone.value().centroid_ct_mm();
  PoseParameters truth;
  truth.rotation_deg = Eigen::Vector3d(4.0, -3.0, 6.0);
  truth.translation_mm = -centre + Eigen::Vector3d(2.0, -3.0, 1.5);
  c.T_truth = RigidPose::toTransform(truth, centre);

  auto drrVolume = DrrVolume::create(ct);
  if (!drrVolume) return fail(drrVolume.error());
  auto renderer = DrrRendererFactory::create(std::make_shared<const DrrVolume>(std::move(drrVolume).value()));
  if (!renderer) return fail(renderer.error());
  const std::vector<std::pair<std::string, Eigen::Matrix3d>> views{
      {"AP", viewRotation(0.0, 0.0)}, {"LAT", viewRotation(90.0, 0.0)}, {"OBL", viewRotation(45.0, 20.0)}};
  SeededRandom random(o.seed);
  for (const auto& [name, R] : views) {
    const Camera camera = Camera::lookingAt(Eigen::Vector3d::Zero(), R, o.sourceToPatient_mm, o.sourceToDetector_mm,
                                            o.cols, o.rows, o.pixelSpacing_mm);
    auto drr = renderer.value()->render(camera, c.T_truth, 0);
    if (!drr) return fail(drr.error());
    XrayImage xray;
    xray.cols = o.cols;
    xray.rows = o.rows;
    xray.modality = "simulated";
    xray.pixels.resize(drr.value().pixels.size());
    for (std::size_t i = 0; i < xray.pixels.size(); ++i) {
      const double intensity = o.referenceIntensity * std::exp(-static_cast<double>(drr.value().pixels[i]));
      xray.pixels[i] = static_cast<float>(std::max(0.0, intensity * (1.0 + o.noise * random.normal())));
    }
    c.views.push_back(RegistrationView{name, std::move(xray), camera, {}});
  }
  c.ct = std::move(ct);
  return c;
}

/// A start pose whose mean bone-surface distance from `T_truth` is `distance_mm`: the truth's parameters plus a
/// random direction (uniform on the sphere in scaled units) scaled by bisection. Deterministic for a seed.
inline Eigen::Isometry3d startPose(const RegistrationCase& registrationCase, const Eigen::Isometry3d& T_truth,
                                   double distance_mm, std::uint32_t seed) {
  const BoneSurface& bone = *registrationCase.bone();
  const PoseVector truth = RigidPose::fromTransform(T_truth, registrationCase.rotationCentre_ct_mm()).value().asVector();
  SeededRandom random(seed);
  PoseVector direction;
  for (int k = 0; k < 6; ++k) direction[k] = random.normal();
  direction = direction.normalized().cwiseProduct(registrationCase.scales());
  auto at = [&](double s) { return registrationCase.poseTransform(truth + s * direction); };
  double lo = 0.0, hi = 1.0;
  while (bone.meanDistance_mm(at(hi), T_truth) < distance_mm) hi *= 2.0;
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (lo + hi);
    (bone.meanDistance_mm(at(mid), T_truth) < distance_mm ? lo : hi) = mid;
  }
  return at(0.5 * (lo + hi));
}

}  // namespace fct::test
