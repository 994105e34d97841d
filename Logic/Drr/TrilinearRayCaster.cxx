#include "Drr/TrilinearRayCaster.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "Drr/DrrRayGeometry.h"

namespace fct {

TrilinearRayCaster::TrilinearRayCaster(std::shared_ptr<const DrrVolume> volume, double step_mm)
    : IndexSpaceRayCaster(std::move(volume)),
      m_step_mm(std::isfinite(step_mm) && step_mm > 0.0 ? step_mm : defaultStep_mm(this->volume())) {
  const DrrVolume& vol = this->volume();
  m_clipMin_ijk = (vol.contentBoxMin_ijk().array() - 0.5).max(vol.boxMin_ijk().array());
  m_clipMax_ijk = (vol.contentBoxMax_ijk().array() + 0.5).min(vol.boxMax_ijk().array());
}

double TrilinearRayCaster::defaultStep_mm(const DrrVolume& volume) {
  return 0.5 * volume.values().spacing_mm().minCoeff();
}

double TrilinearRayCaster::integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk,
                                               double length_mm) const {
  const DrrVolume& vol = volume();
  const Eigen::Vector3d d = b_ijk - a_ijk;
  double t0 = 0.0;
  double t1 = 1.0;
  if (!vol.hasContent() || !DrrRayGeometry::clipToBox(a_ijk, d, m_clipMin_ijk, m_clipMax_ijk, t0, t1)) return 0.0;

  const double inside_mm = (t1 - t0) * length_mm;
  const long sampleCount = std::max(1L, static_cast<long>(std::ceil(inside_mm / m_step_mm - 1e-9)));
  const double dt = (t1 - t0) / static_cast<double>(sampleCount);

  const Eigen::Vector3i& n = vol.dims();
  const double maxCoord[3] = {n.x() - 1.0, n.y() - 1.0, n.z() - 1.0};
  const int maxLow[3] = {std::max(n.x() - 2, 0), std::max(n.y() - 2, 0), std::max(n.z() - 2, 0)};
  // Neighbour offsets along i, j, k (0 along an axis with a single voxel).
  const std::ptrdiff_t di = n.x() > 1 ? 1 : 0;
  const std::ptrdiff_t dj = n.y() > 1 ? n.x() : 0;
  const std::ptrdiff_t dk = n.z() > 1 ? static_cast<std::ptrdiff_t>(n.x()) * n.y() : 0;
  const std::ptrdiff_t sj = n.x();
  const std::ptrdiff_t sk = static_cast<std::ptrdiff_t>(n.x()) * n.y();
  const float* data = vol.data();

  Eigen::Vector3d p = a_ijk + (t0 + 0.5 * dt) * d;
  const Eigen::Vector3d dp = dt * d;
  double sum = 0.0;
  for (long m = 0; m < sampleCount; ++m, p += dp) {
    const double x = std::clamp(p.x(), 0.0, maxCoord[0]);
    const double y = std::clamp(p.y(), 0.0, maxCoord[1]);
    const double z = std::clamp(p.z(), 0.0, maxCoord[2]);
    const int i = std::min(static_cast<int>(x), maxLow[0]);
    const int j = std::min(static_cast<int>(y), maxLow[1]);
    const int k = std::min(static_cast<int>(z), maxLow[2]);
    const float fx = static_cast<float>(x - i);
    const float fy = static_cast<float>(y - j);
    const float fz = static_cast<float>(z - k);
    const float* v = data + (i + j * sj + k * sk);
    const float c00 = v[0] + fx * (v[di] - v[0]);
    const float c10 = v[dj] + fx * (v[dj + di] - v[dj]);
    const float c01 = v[dk] + fx * (v[dk + di] - v[dk]);
    const float c11 = v[dk + dj] + fx * (v[dk + dj + di] - v[dk + dj]);
    const float c0 = c00 + fy * (c10 - c00);
    const float c1 = c01 + fy * (c11 - c01);
    sum += c0 + fz * (c1 - c0);
  }
  return sum * dt * length_mm;
}

}  // namespace fct
