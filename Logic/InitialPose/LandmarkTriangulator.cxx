#include "InitialPose/LandmarkTriangulator.h"

#include <fmt/core.h>

#include <Eigen/Cholesky>

#include <cmath>

namespace fct {

Eigen::Vector2d LandmarkTriangulator::projectWithJacobian(const Camera& camera, const Eigen::Vector3d& p_world_mm,
                                                          Eigen::Matrix<double, 2, 3>* J_px_per_mm) {
  const Eigen::Isometry3d T_camera_from_world = camera.T_camera_from_world();
  const Eigen::Vector3d p = T_camera_from_world * p_world_mm;
  const Eigen::Matrix3d K = camera.K();
  const double fx = K(0, 0), fy = K(1, 1);
  const double invZ = 1.0 / p.z();
  if (J_px_per_mm) {
    Eigen::Matrix<double, 2, 3> J_camera;
    J_camera << fx * invZ, 0.0, -fx * p.x() * invZ * invZ, 0.0, fy * invZ, -fy * p.y() * invZ * invZ;
    *J_px_per_mm = J_camera * T_camera_from_world.linear();
  }
  return Eigen::Vector2d(fx * p.x() * invZ + K(0, 2), fy * p.y() * invZ + K(1, 2));
}

Result<Eigen::Vector3d> LandmarkTriangulator::triangulate(const std::string& name,
                                                          const std::vector<LandmarkClick>& clicks) {
  if (clicks.size() < 2) {
    return fail(fmt::format("landmark '{}' is clicked only in {}; triangulation needs it in at least 2 views", name,
                            clicks.empty() ? std::string("no view") : fmt::format("view '{}'", clicks[0].view)));
  }
  for (const auto& click : clicks) {
    if (!click.uv_px.allFinite()) {
      return fail(fmt::format("landmark '{}' has a NaN or infinite click in view '{}'", name, click.view));
    }
  }
  // Widest angle between two of the rays: below kMinRayAngle_deg the depth is undetermined.
  std::vector<Ray> rays;
  for (const auto& click : clicks) rays.push_back(click.camera.backProject(click.uv_px));
  double widest_deg = 0.0;
  for (size_t i = 0; i < rays.size(); ++i) {
    for (size_t j = i + 1; j < rays.size(); ++j) {
      const double c = std::clamp(rays[i].direction_world.dot(rays[j].direction_world), -1.0, 1.0);
      widest_deg = std::max(widest_deg, std::acos(c) * 180.0 / M_PI);
    }
  }
  if (widest_deg < kMinRayAngle_deg) {
    return fail(fmt::format("landmark '{}' is seen from nearly the same direction in all its views (rays {:.2f} deg "
                            "apart); triangulation needs views at least {} deg apart",
                            name, widest_deg, kMinRayAngle_deg));
  }
  // Linear: the point closest to all rays (lines), sum (I - d d^T)(x - o) = 0.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& ray : rays) {
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - ray.direction_world * ray.direction_world.transpose();
    A += P;
    b += P * ray.origin_world_mm;
  }
  Eigen::Vector3d x = A.ldlt().solve(b);
  // Gauss–Newton on the reprojection error (pixels).
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const auto& click : clicks) {
      Eigen::Matrix<double, 2, 3> J;
      const Eigen::Vector2d r = projectWithJacobian(click.camera, x, &J) - click.uv_px;
      H += J.transpose() * J;
      g += J.transpose() * r;
    }
    const Eigen::Vector3d step = -H.ldlt().solve(g);
    if (!step.allFinite()) break;
    x += step;
    if (step.norm() < 1e-12 * (1.0 + x.norm())) break;
  }
  for (const auto& click : clicks) {
    bool inFront = false;
    click.camera.project(x, &inFront);
    if (!inFront) {
      return fail(fmt::format("landmark '{}' triangulates behind the X-ray source of view '{}'; check its clicks and "
                              "the view geometry",
                              name, click.view));
    }
  }
  return x;
}

}  // namespace fct
