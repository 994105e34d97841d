#include "Evaluation/PoseOffset.h"

#include <fmt/core.h>

#include <cmath>

#include "Base/SeededRandom.h"
#include "Search/PoseOptimizer.h"

namespace fct {

Eigen::Isometry3d PoseOffset::apply(const BoneSurface& bone, const Eigen::Isometry3d& T_reference,
                                    const PoseParameters& offset) {
  const Eigen::Vector3d centre_world_mm = T_reference * bone.centroid_ct_mm();
  return RigidPose::toTransform(offset, centre_world_mm) * T_reference;
}

Result<Eigen::Isometry3d> PoseOffset::randomAtSurfaceDistance(const BoneSurface& bone,
                                                              const Eigen::Isometry3d& T_reference, double distance_mm,
                                                              std::uint32_t seed) {
  if (!std::isfinite(distance_mm) || distance_mm < 0.0 || distance_mm > 500.0) {
    return fail(fmt::format("offset distance must be between 0 and 500 mm, got {} mm", distance_mm));
  }
  const auto scales = PoseOptimizer::scalesForBoneRadius(std::max(bone.radius_mm(), 1.0));
  if (!scales.ok()) return fail(scales.error());
  SeededRandom random(seed);
  PoseVector direction;
  for (int k = 0; k < 6; ++k) direction[k] = random.normal();
  direction = direction.normalized().cwiseProduct(scales.value());
  const auto at = [&](double s) { return apply(bone, T_reference, PoseParameters::fromVector(s * direction)); };
  // The mean surface distance grows monotonically with s along a ray from 0 for the offsets of interest: bisection.
  double lo = 0.0, hi = 1.0;
  while (bone.meanDistance_mm(at(hi), T_reference) < distance_mm && hi < 1e4) hi *= 2.0;
  for (int i = 0; i < 60 && hi - lo > 1e-9; ++i) {
    const double mid = 0.5 * (lo + hi);
    (bone.meanDistance_mm(at(mid), T_reference) < distance_mm ? lo : hi) = mid;
  }
  return at(0.5 * (lo + hi));
}

}  // namespace fct
