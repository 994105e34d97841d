#include "Image/BoneSurface.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace fct {

namespace {

/// Linear offsets of the boundary voxels of slice k, in scan order (j, then i), appended to `out`.
void collectSliceBoundary(const Volume& ct, int k, float threshold, std::vector<std::int64_t>& out) {
  const int nx = ct.dims().x(), ny = ct.dims().y(), nz = ct.dims().z();
  const std::int64_t sx = 1, sy = nx, sz = static_cast<std::int64_t>(nx) * ny;
  const float* v = ct.voxels().data();
  for (int j = 0; j < ny; ++j) {
    const std::int64_t rowStart = static_cast<std::int64_t>(ct.offset(0, j, k));
    const bool edgeJ = j == 0 || j == ny - 1;
    const bool edgeK = k == 0 || k == nz - 1;
    for (int i = 0; i < nx; ++i) {
      const std::int64_t o = rowStart + i;
      if (!(v[o] >= threshold)) continue;
      const bool boundary = i == 0 || i == nx - 1 || edgeJ || edgeK || !(v[o - sx] >= threshold) ||
                            !(v[o + sx] >= threshold) || !(v[o - sy] >= threshold) || !(v[o + sy] >= threshold) ||
                            !(v[o - sz] >= threshold) || !(v[o + sz] >= threshold);
      if (boundary) out.push_back(o);
    }
  }
}

}  // namespace

Result<BoneSurface> BoneSurface::extract(const Volume& ct, double threshold_hu, std::size_t maxPoints) {
  if (ct.voxelCount() == 0) return fail("cannot extract a bone surface from an empty CT volume");
  if (!std::isfinite(threshold_hu)) return fail("bone threshold must be a finite HU value");
  if (maxPoints == 0) return fail("bone surface needs at least 1 point (maxPoints is 0)");

  const int nz = ct.dims().z();
  const float threshold = static_cast<float>(threshold_hu);
  std::vector<std::vector<std::int64_t>> perSlice(static_cast<std::size_t>(nz));
  tbb::parallel_for(0, nz, [&](int k) { collectSliceBoundary(ct, k, threshold, perSlice[static_cast<std::size_t>(k)]); });

  std::size_t total = 0;
  for (const auto& slice : perSlice) total += slice.size();
  if (total == 0) {
    const auto [lo, hi] = ct.valueRange();
    return fail(fmt::format("no CT voxel reaches the bone threshold {:g} HU (the CT's values span {:g}..{:g}); "
                            "lower the bone threshold or check that the CT is in Hounsfield units",
                            threshold_hu, lo, hi));
  }

  // Keep `kept` points at evenly spaced positions of the scan-ordered boundary list.
  const std::size_t kept = std::min(total, maxPoints);
  BoneSurface surface;
  surface.m_threshold_hu = threshold_hu;
  surface.m_boundaryVoxelCount = total;
  surface.m_points_ct_mm.reserve(kept);
  const Eigen::Affine3d T_lps_from_ijk = ct.T_lps_from_ijk();
  const std::int64_t nx = ct.dims().x(), nxy = nx * ct.dims().y();
  std::size_t slice = 0, sliceStart = 0;
  for (std::size_t n = 0; n < kept; ++n) {
    const std::size_t index = static_cast<std::size_t>((static_cast<std::uint64_t>(n) * total) / kept);
    while (index >= sliceStart + perSlice[slice].size()) sliceStart += perSlice[slice++].size();
    const std::int64_t o = perSlice[slice][index - sliceStart];
    const Eigen::Vector3d ijk(static_cast<double>(o % nx), static_cast<double>((o % nxy) / nx),
                              static_cast<double>(o / nxy));
    surface.m_points_ct_mm.push_back(T_lps_from_ijk * ijk);
  }

  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : surface.m_points_ct_mm) sum += p;
  surface.m_centroid_ct_mm = sum / static_cast<double>(kept);
  double sumSquares = 0.0;
  for (const auto& p : surface.m_points_ct_mm) sumSquares += (p - surface.m_centroid_ct_mm).squaredNorm();
  surface.m_radius_mm = std::sqrt(sumSquares / static_cast<double>(kept));
  return surface;
}

double BoneSurface::meanDistance_mm(const Eigen::Isometry3d& T_world_from_ct_a,
                                    const Eigen::Isometry3d& T_world_from_ct_b) const {
  const Eigen::Matrix<double, 3, 4> D = (T_world_from_ct_a.matrix() - T_world_from_ct_b.matrix()).topRows<3>();
  double sum = 0.0;
  for (const auto& p : m_points_ct_mm) sum += (D.leftCols<3>() * p + D.col(3)).norm();
  return sum / static_cast<double>(m_points_ct_mm.size());
}

double BoneSurface::maxDistance_mm(const Eigen::Isometry3d& T_world_from_ct_a,
                                   const Eigen::Isometry3d& T_world_from_ct_b) const {
  const Eigen::Matrix<double, 3, 4> D = (T_world_from_ct_a.matrix() - T_world_from_ct_b.matrix()).topRows<3>();
  double largest = 0.0;
  for (const auto& p : m_points_ct_mm) largest = std::max(largest, (D.leftCols<3>() * p + D.col(3)).norm());
  return largest;
}

}  // namespace fct
