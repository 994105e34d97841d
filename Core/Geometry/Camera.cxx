#include "Geometry/Camera.h"

#include <fmt/core.h>

#include <cmath>

namespace fct {

namespace {
bool isProperRotation(const Eigen::Matrix3d& R, double* orthoError) {
  *orthoError = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  return *orthoError < 1e-6 && std::abs(R.determinant() - 1.0) < 1e-6;
}
}  // namespace

Result<Camera> Camera::create(const CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_from_camera) {
  if (intrinsics.cols <= 0 || intrinsics.rows <= 0) {
    return fail(fmt::format("detector size must be positive, got {} x {} pixels", intrinsics.cols, intrinsics.rows));
  }
  if (!intrinsics.pixelSpacing_mm.allFinite() || (intrinsics.pixelSpacing_mm.array() <= 0.0).any()) {
    return fail(fmt::format("detector pixel spacing must be positive, got {} x {} mm", intrinsics.pixelSpacing_mm.x(),
                            intrinsics.pixelSpacing_mm.y()));
  }
  if (!std::isfinite(intrinsics.sourceToDetector_mm) || intrinsics.sourceToDetector_mm <= 0.0) {
    return fail(fmt::format("source-to-detector distance must be positive, got {} mm", intrinsics.sourceToDetector_mm));
  }
  if (!intrinsics.principalPoint_px.allFinite()) return fail("principal point contains NaN or infinity");
  const Eigen::Vector2d size(intrinsics.cols, intrinsics.rows);
  if ((intrinsics.principalPoint_px.array() < -size.array()).any() ||
      (intrinsics.principalPoint_px.array() > 2.0 * size.array()).any()) {
    return fail(fmt::format("principal point ({}, {}) px is implausibly far outside the {} x {} detector",
                            intrinsics.principalPoint_px.x(), intrinsics.principalPoint_px.y(), intrinsics.cols,
                            intrinsics.rows));
  }
  if (!T_world_from_camera.matrix().allFinite()) return fail("T_world_from_camera contains NaN or infinity");
  const Eigen::Matrix4d& M = T_world_from_camera.matrix();
  if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) {
    return fail("T_world_from_camera's last row must be [0, 0, 0, 1]");
  }
  double orthoError = 0.0;
  if (!isProperRotation(T_world_from_camera.linear(), &orthoError)) {
    return fail(fmt::format("T_world_from_camera's 3x3 part is not a rotation (orthonormality error {:.3g}, det {:.4f})",
                            orthoError, T_world_from_camera.linear().determinant()));
  }
  Camera camera;
  camera.m_intrinsics = intrinsics;
  camera.m_T_world_from_camera = T_world_from_camera;
  return camera;
}

Result<Camera> Camera::fromProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P_px_from_world, int cols, int rows,
                                            const Eigen::Vector2d& pixelSpacing_mm) {
  if (!P_px_from_world.allFinite()) return fail("projection matrix contains NaN or infinity");
  Eigen::Matrix3d M = P_px_from_world.leftCols<3>();
  if (std::abs(M.determinant()) < 1e-12 * std::pow(M.norm(), 3)) {
    return fail("projection matrix is singular: its left 3x3 block has no inverse");
  }
  // Normalize scale and sign so that det(M) > 0 (camera looks along +z).
  double scale = M.row(2).norm();
  if (M.determinant() < 0) scale = -scale;
  const Eigen::Matrix<double, 3, 4> P = P_px_from_world / scale;
  M = P.leftCols<3>();
  // RQ decomposition M = K R with K upper triangular with positive diagonal, via QR of the flipped transpose.
  Eigen::Matrix3d flip;
  flip << 0, 0, 1, 0, 1, 0, 1, 0, 0;
  Eigen::HouseholderQR<Eigen::Matrix3d> qr((flip * M).transpose());
  Eigen::Matrix3d Q = qr.householderQ();
  Eigen::Matrix3d Rr = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d K = flip * Rr.transpose() * flip;
  Eigen::Matrix3d R = flip * Q.transpose();
  Eigen::Matrix3d S = Eigen::Vector3d(K(0, 0) < 0 ? -1 : 1, K(1, 1) < 0 ? -1 : 1, K(2, 2) < 0 ? -1 : 1).asDiagonal();
  K = K * S;
  R = S * R;
  if (R.determinant() < 0) return fail("projection matrix has a mirrored (left-handed) camera frame");
  K /= K(2, 2);
  const double fx = K(0, 0), fy = K(1, 1);
  if (std::abs(K(0, 1)) > 1e-6 * fx) {
    return fail(fmt::format("projection matrix has a skewed detector (K01 = {:.4g}); FluoroCT needs square axes", K(0, 1)));
  }
  if (!pixelSpacing_mm.allFinite() || (pixelSpacing_mm.array() <= 0.0).any()) {
    return fail("detector pixel spacing must be positive to interpret a projection matrix");
  }
  const double f_u_mm = fx * pixelSpacing_mm.x();
  const double f_v_mm = fy * pixelSpacing_mm.y();
  if (std::abs(f_u_mm - f_v_mm) > 0.01 * std::max(f_u_mm, f_v_mm)) {
    return fail(fmt::format("projection matrix and pixel spacing disagree: f/du*du = {:.2f} mm but f/dv*dv = {:.2f} mm; "
                            "check pixel_spacing_mm",
                            f_u_mm, f_v_mm));
  }
  const Eigen::Vector3d t = K.inverse() * P.col(3);
  Eigen::Isometry3d T_camera_from_world = Eigen::Isometry3d::Identity();
  T_camera_from_world.linear() = R;
  T_camera_from_world.translation() = t;
  CameraIntrinsics intrinsics;
  intrinsics.cols = cols;
  intrinsics.rows = rows;
  intrinsics.pixelSpacing_mm = pixelSpacing_mm;
  intrinsics.sourceToDetector_mm = 0.5 * (f_u_mm + f_v_mm);
  intrinsics.principalPoint_px = Eigen::Vector2d(K(0, 2), K(1, 2));
  return create(intrinsics, T_camera_from_world.inverse());
}

Camera Camera::lookingAt(const Eigen::Vector3d& isocentre_world_mm, const Eigen::Matrix3d& R_world_from_camera,
                         double sourceToPatient_mm, double sourceToDetector_mm, int cols, int rows,
                         double pixelSpacing_mm) {
  Camera camera;
  camera.m_intrinsics.cols = cols;
  camera.m_intrinsics.rows = rows;
  camera.m_intrinsics.pixelSpacing_mm = Eigen::Vector2d(pixelSpacing_mm, pixelSpacing_mm);
  camera.m_intrinsics.sourceToDetector_mm = sourceToDetector_mm;
  camera.m_intrinsics.principalPoint_px = Eigen::Vector2d(0.5 * (cols - 1), 0.5 * (rows - 1));
  camera.m_T_world_from_camera = Eigen::Isometry3d::Identity();
  camera.m_T_world_from_camera.linear() = R_world_from_camera;
  camera.m_T_world_from_camera.translation() =
      isocentre_world_mm - sourceToPatient_mm * R_world_from_camera.col(2);
  return camera;
}

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = m_intrinsics.sourceToDetector_mm / m_intrinsics.pixelSpacing_mm.x();
  K(1, 1) = m_intrinsics.sourceToDetector_mm / m_intrinsics.pixelSpacing_mm.y();
  K(0, 2) = m_intrinsics.principalPoint_px.x();
  K(1, 2) = m_intrinsics.principalPoint_px.y();
  return K;
}

Eigen::Matrix<double, 3, 4> Camera::P_px_from_world() const {
  const Eigen::Isometry3d T = T_camera_from_world();
  Eigen::Matrix<double, 3, 4> Rt;
  Rt.leftCols<3>() = T.linear();
  Rt.col(3) = T.translation();
  return K() * Rt;
}

Eigen::Vector2d Camera::project(const Eigen::Vector3d& p_world_mm, bool* inFront) const {
  const Eigen::Vector3d p_camera_mm = T_camera_from_world() * p_world_mm;
  if (inFront) *inFront = p_camera_mm.z() > 0.0;
  const Eigen::Vector3d h = K() * p_camera_mm;
  return h.head<2>() / h.z();
}

Eigen::Vector3d Camera::detectorPoint_world_mm(const Eigen::Vector2d& uv_px) const {
  const auto& in = m_intrinsics;
  const Eigen::Vector3d p_camera_mm((uv_px.x() - in.principalPoint_px.x()) * in.pixelSpacing_mm.x(),
                                    (uv_px.y() - in.principalPoint_px.y()) * in.pixelSpacing_mm.y(),
                                    in.sourceToDetector_mm);
  return m_T_world_from_camera * p_camera_mm;
}

Ray Camera::backProject(const Eigen::Vector2d& uv_px) const {
  const Eigen::Vector3d source = sourcePosition_world_mm();
  return Ray{source, (detectorPoint_world_mm(uv_px) - source).normalized()};
}

Camera Camera::downsampled(int level) const {
  Camera camera = *this;
  if (level <= 0) return camera;
  const double factor = static_cast<double>(1 << level);
  auto& in = camera.m_intrinsics;
  in.cols = m_intrinsics.cols >> level;
  in.rows = m_intrinsics.rows >> level;
  in.pixelSpacing_mm = m_intrinsics.pixelSpacing_mm * factor;
  in.principalPoint_px = (m_intrinsics.principalPoint_px.array() + 0.5) / factor - 0.5;
  return camera;
}

}  // namespace fct
