#include "SiddonRayCaster.h"

#include <cmath>
#include <cstddef>
#include <limits>

#include "DrrRayGeometry.h"

namespace fct {

SiddonRayCaster::SiddonRayCaster(std::shared_ptr<const DrrVolume> volume) : DrrRenderer(std::move(volume)) {}

inline double SiddonRayCaster::integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk,
                                            double length_mm) const {
  const DrrVolume& vol = volume();
  const Eigen::Vector3d d = b_ijk - a_ijk;
  double t0 = 0.0;
  double t1 = 1.0;
  if (!DrrRayGeometry::clipToBox(a_ijk, d, vol.boxMin_ijk(), vol.boxMax_ijk(), t0, t1)) return 0.0;

  // Grid coordinates: voxel m covers [m, m+1) along each axis, the volume covers [0, n).
  const Eigen::Vector3i& n = vol.dims();
  const std::ptrdiff_t stride[3] = {1, n.x(), static_cast<std::ptrdiff_t>(n.x()) * n.y()};
  int index[3];
  int step[3];
  std::ptrdiff_t offsetStep[3];
  double tNext[3];
  double tDelta[3];
  std::ptrdiff_t offset = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double g = a_ijk[axis] + 0.5;
    const double entry = g + t0 * d[axis];
    index[axis] = std::clamp(static_cast<int>(std::floor(entry)), 0, n[axis] - 1);
    offset += index[axis] * stride[axis];
    if (d[axis] > 0.0) {
      step[axis] = 1;
      tDelta[axis] = 1.0 / d[axis];
      tNext[axis] = (index[axis] + 1 - g) * tDelta[axis];
    } else if (d[axis] < 0.0) {
      step[axis] = -1;
      tDelta[axis] = -1.0 / d[axis];
      tNext[axis] = (g - index[axis]) * tDelta[axis];
    } else {
      step[axis] = 0;
      tDelta[axis] = 0.0;
      tNext[axis] = std::numeric_limits<double>::infinity();
    }
    offsetStep[axis] = step[axis] * stride[axis];
  }

  const float* data = vol.data();
  double sum = 0.0;
  double t = t0;
  for (;;) {
    const int axis = tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    const double tEnd = std::min(tNext[axis], t1);
    sum += (tEnd - t) * data[offset];
    if (tEnd >= t1) break;
    t = tEnd;
    index[axis] += step[axis];
    if (static_cast<unsigned>(index[axis]) >= static_cast<unsigned>(n[axis])) break;
    offset += offsetStep[axis];
    tNext[axis] += tDelta[axis];
  }
  return sum * length_mm;
}

double SiddonRayCaster::integrate(const Eigen::Vector3d& from_ct_mm, const Eigen::Vector3d& to_ct_mm) const {
  const Eigen::Affine3d& T = volume().T_ijk_from_ct();
  return integrateIjk(T * from_ct_mm, T * to_ct_mm, (to_ct_mm - from_ct_mm).norm());
}

void SiddonRayCaster::integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                                      const std::int32_t* pixels, std::size_t count, float* values) const {
  const DrrRayGeometry geometry(levelCamera, T_world_from_ct, volume().T_ijk_from_ct());
  geometry.integratePixels(pixels, count, values,
                           [this](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double length_mm) {
                             return integrateIjk(a, b, length_mm);
                           });
}

}  // namespace fct
