#include "Image/Volume.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace fct {

Result<Volume> Volume::create(const Eigen::Vector3i& dims, const Eigen::Vector3d& spacing_mm,
                              const Eigen::Vector3d& origin_lps_mm, const Eigen::Matrix3d& direction_lps,
                              float fill_value) {
  if ((dims.array() <= 0).any()) {
    return fail(fmt::format("volume dimensions must be positive, got {}x{}x{}", dims.x(), dims.y(), dims.z()));
  }
  if (!spacing_mm.allFinite() || (spacing_mm.array() <= 0.0).any()) {
    return fail(fmt::format("voxel spacing must be positive and finite, got {} x {} x {} mm", spacing_mm.x(),
                            spacing_mm.y(), spacing_mm.z()));
  }
  if (!origin_lps_mm.allFinite() || !direction_lps.allFinite()) {
    return fail("volume origin or direction contains NaN or infinity");
  }
  const double orthoError = (direction_lps.transpose() * direction_lps - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthoError > 1e-4 || std::abs(std::abs(direction_lps.determinant()) - 1.0) > 1e-4) {
    return fail(fmt::format("volume direction cosines are not orthonormal (error {:.2g}); the file's orientation is invalid",
                            orthoError));
  }
  const std::size_t count = static_cast<std::size_t>(dims.x()) * dims.y() * dims.z();
  Volume volume;
  volume.m_dims = dims;
  volume.m_spacing_mm = spacing_mm;
  volume.m_origin_lps_mm = origin_lps_mm;
  volume.m_direction_lps = direction_lps;
  volume.m_voxels.assign(count, fill_value);
  return volume;
}

Eigen::Affine3d Volume::T_lps_from_ijk() const {
  Eigen::Affine3d T = Eigen::Affine3d::Identity();
  T.linear() = m_direction_lps * m_spacing_mm.asDiagonal();
  T.translation() = m_origin_lps_mm;
  return T;
}

Eigen::Affine3d Volume::T_ijk_from_lps() const { return T_lps_from_ijk().inverse(); }

Eigen::Vector3d Volume::ijkFromLps(const Eigen::Vector3d& p_lps_mm) const {
  return m_spacing_mm.cwiseInverse().asDiagonal() * (m_direction_lps.transpose() * (p_lps_mm - m_origin_lps_mm));
}

Eigen::Vector3d Volume::lpsFromIjk(const Eigen::Vector3d& ijk) const {
  return m_origin_lps_mm + m_direction_lps * (m_spacing_mm.asDiagonal() * ijk);
}

Eigen::Vector3d Volume::centre_lps_mm() const {
  return lpsFromIjk(0.5 * (m_dims.cast<double>() - Eigen::Vector3d::Ones()));
}

std::pair<float, float> Volume::valueRange() const {
  if (m_voxels.empty()) return {0.0f, 0.0f};
  const auto [lo, hi] = std::minmax_element(m_voxels.begin(), m_voxels.end());
  return {*lo, *hi};
}

}  // namespace fct
