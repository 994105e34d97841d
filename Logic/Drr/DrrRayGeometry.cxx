#include "Drr/DrrRayGeometry.h"

namespace fct {

DrrRayGeometry::DrrRayGeometry(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                               const Eigen::Affine3d& T_ijk_from_ct) {
  const CameraIntrinsics& in = camera.intrinsics();
  m_cols = in.cols;
  m_rows = in.rows;
  m_principalPoint_px = in.principalPoint_px;
  m_pixelSpacing_mm = in.pixelSpacing_mm;
  m_sourceToDetector_mm = in.sourceToDetector_mm;
  const Eigen::Affine3d T_ijk_from_world = T_ijk_from_ct * T_world_from_ct.inverse();
  const Eigen::Matrix3d R_world_from_camera = camera.T_world_from_camera().linear();
  m_source_ijk = T_ijk_from_world * camera.sourcePosition_world_mm();
  m_detector00_ijk = T_ijk_from_world * camera.detectorPoint_world_mm(Eigen::Vector2d::Zero());
  m_colStep_ijk = T_ijk_from_world.linear() * (R_world_from_camera.col(0) * in.pixelSpacing_mm.x());
  m_rowStep_ijk = T_ijk_from_world.linear() * (R_world_from_camera.col(1) * in.pixelSpacing_mm.y());
}

}  // namespace fct
