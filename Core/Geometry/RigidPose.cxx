#include "Geometry/RigidPose.h"

#include <fmt/core.h>

#include <cmath>

namespace fct {

namespace {
constexpr double kDegFromRad = 180.0 / M_PI;
constexpr double kRadFromDeg = M_PI / 180.0;
}  // namespace

PoseVector PoseParameters::asVector() const {
  Eigen::Matrix<double, 6, 1> v;
  v << rotation_deg, translation_mm;
  return v;
}

PoseParameters PoseParameters::fromVector(const PoseVector& v) {
  return PoseParameters{v.head<3>(), v.tail<3>()};
}

Eigen::Isometry3d RigidPose::toTransform(const PoseParameters& params, const Eigen::Vector3d& centre_ct_mm) {
  const Eigen::Vector3d r = params.rotation_deg * kRadFromDeg;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = centre_ct_mm + params.translation_mm - R * centre_ct_mm;
  return T;
}

Result<PoseParameters> RigidPose::fromTransform(const Eigen::Isometry3d& T_world_from_ct,
                                                const Eigen::Vector3d& centre_ct_mm) {
  auto checked = validated(T_world_from_ct.matrix(), "T_world_from_ct");
  if (!checked) return fail(checked.error());
  const Eigen::Matrix3d R = T_world_from_ct.linear();
  // R = Rz(c) Ry(b) Rx(a): R20 = -sin b, R21 = cos b sin a, R22 = cos b cos a, R10 = sin c cos b, R00 = cos c cos b.
  PoseParameters params;
  const double sinB = std::clamp(-R(2, 0), -1.0, 1.0);
  const double b = std::asin(sinB);
  double a = 0.0, c = 0.0;
  if (std::abs(sinB) < 1.0 - 1e-12) {
    a = std::atan2(R(2, 1), R(2, 2));
    c = std::atan2(R(1, 0), R(0, 0));
  } else {  // gimbal lock: put everything into c
    c = std::atan2(-R(0, 1), R(1, 1));
  }
  params.rotation_deg = Eigen::Vector3d(a, b, c) * kDegFromRad;
  params.translation_mm = T_world_from_ct * centre_ct_mm - centre_ct_mm;
  return params;
}

Result<Eigen::Isometry3d> RigidPose::validated(const Eigen::Matrix4d& matrix, const char* what) {
  if (!matrix.allFinite()) return fail(fmt::format("{} contains NaN or infinity", what));
  if ((matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) {
    return fail(fmt::format("{}'s last row must be [0, 0, 0, 1]", what));
  }
  const Eigen::Matrix3d R = matrix.topLeftCorner<3, 3>();
  const double orthoError = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthoError > 1e-6 || std::abs(R.determinant() - 1.0) > 1e-6) {
    return fail(fmt::format("{} is not a rigid transform: its 3x3 part is not a rotation (orthonormality error {:.3g}, "
                            "det {:.4f})",
                            what, orthoError, R.determinant()));
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = matrix;
  return T;
}

}  // namespace fct
