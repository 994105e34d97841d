#include "InitialPose/SetupPose.h"

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include <cmath>

namespace fct {

Result<Eigen::Vector3d> SetupPose::isocentre_world_mm(const std::vector<Camera>& cameras) {
  if (cameras.empty()) return fail("the setup pose needs at least one calibrated view; none is loaded");
  // Sum over rays of (I - d d^T) (x - o) = 0: the point closest to every ray in the least-squares sense.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Camera& camera : cameras) {
    const Ray ray = camera.backProject(camera.intrinsics().principalPoint_px);
    const Eigen::Matrix3d projector = Eigen::Matrix3d::Identity() - ray.direction_world * ray.direction_world.transpose();
    A += projector;
    b += projector * ray.origin_world_mm;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(A);
  // With rays within ~1 degree of parallel the smallest eigenvalue is about sin^2(angle) or less: ill-posed.
  const double minAngle_rad = 1.0 * M_PI / 180.0;
  if (cameras.size() >= 2 && eigen.eigenvalues()(0) > std::sin(minAngle_rad) * std::sin(minAngle_rad)) {
    return Eigen::Vector3d(A.ldlt().solve(b));
  }
  const Camera& first = cameras.front();
  const Ray ray = first.backProject(first.intrinsics().principalPoint_px);
  return Eigen::Vector3d(ray.origin_world_mm + kSingleViewIsocentreFraction *
                                                   first.intrinsics().sourceToDetector_mm * ray.direction_world);
}

Result<Eigen::Isometry3d> SetupPose::supineAtIsocentre(const Eigen::Vector3d& centre_ct_mm,
                                                       const std::vector<Camera>& cameras) {
  if (!centre_ct_mm.allFinite()) {
    return fail(fmt::format("the CT centre for the setup pose is not finite ({}, {}, {}); check the CT geometry",
                            centre_ct_mm.x(), centre_ct_mm.y(), centre_ct_mm.z()));
  }
  auto isocentre = isocentre_world_mm(cameras);
  if (!isocentre) return fail(isocentre.error());
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  T_world_from_ct.translation() = isocentre.value() - centre_ct_mm;
  return T_world_from_ct;
}

}  // namespace fct
