#include "Image/Volume.h"

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

#include "Base/LargePages.h"

namespace fct {

Status Volume::checkGeometry(const Eigen::Vector3i& dims, const Eigen::Vector3d& spacing_mm,
                             const Eigen::Vector3d& origin_lps_mm, const Eigen::Matrix3d& direction_lps) {
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
  return Ok{};
}

Result<Volume> Volume::create(const Eigen::Vector3i& dims, const Eigen::Vector3d& spacing_mm,
                              const Eigen::Vector3d& origin_lps_mm, const Eigen::Matrix3d& direction_lps,
                              float fill_value) {
  if (Status checked = checkGeometry(dims, spacing_mm, origin_lps_mm, direction_lps); !checked) {
    return fail(checked.error());
  }
  Volume volume;
  volume.m_dims = dims;
  volume.m_spacing_mm = spacing_mm;
  volume.m_origin_lps_mm = origin_lps_mm;
  volume.m_direction_lps = direction_lps;
  assignWithLargePages(volume.m_voxels, static_cast<std::size_t>(dims.x()) * dims.y() * dims.z(), fill_value);
  return volume;
}

Result<Volume> Volume::fromVoxels(const Eigen::Vector3i& dims, const Eigen::Vector3d& spacing_mm,
                                  const Eigen::Vector3d& origin_lps_mm, const Eigen::Matrix3d& direction_lps,
                                  std::vector<float> voxels) {
  if (Status checked = checkGeometry(dims, spacing_mm, origin_lps_mm, direction_lps); !checked) {
    return fail(checked.error());
  }
  const std::size_t count = static_cast<std::size_t>(dims.x()) * dims.y() * dims.z();
  if (voxels.size() != count) {
    return fail(fmt::format("{} voxel values given for a {}x{}x{} volume ({} voxels)", voxels.size(), dims.x(),
                            dims.y(), dims.z(), count));
  }
  Volume volume;
  volume.m_dims = dims;
  volume.m_spacing_mm = spacing_mm;
  volume.m_origin_lps_mm = origin_lps_mm;
  volume.m_direction_lps = direction_lps;
  volume.m_voxels = std::move(voxels);
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
  // Branch-free running minimum and maximum in parallel chunks (std::minmax_element branches on every voxel).
  using Range = std::pair<float, float>;
  const Range range = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, m_voxels.size(), 1 << 16), Range{INFINITY, -INFINITY},
      [&](const tbb::blocked_range<std::size_t>& chunk, Range r) {
        float lo = r.first, hi = r.second;
        for (std::size_t n = chunk.begin(); n != chunk.end(); ++n) {
          const float v = m_voxels[n];
          lo = v < lo ? v : lo;  // false for NaN: NaN voxels are skipped
          hi = v > hi ? v : hi;
        }
        return Range{lo, hi};
      },
      [](const Range& a, const Range& b) { return Range{std::min(a.first, b.first), std::max(a.second, b.second)}; });
  return range.first <= range.second ? range : Range{NAN, NAN};
}

}  // namespace fct
