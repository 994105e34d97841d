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
  // Per axis: current voxel index, its step (+1, -1, 0), the matching offset step in the voxel array, the parameter
  // t of the next voxel boundary and the t between boundaries. Kept in scalars so the loop runs in registers.
  const Eigen::Vector3i& n = vol.dims();
  const std::ptrdiff_t stride[3] = {1, n.x(), static_cast<std::ptrdiff_t>(n.x()) * n.y()};
  struct Axis {
    int index, step, size;
    std::ptrdiff_t offsetStep;
    double tNext, tDelta;
  };
  Axis axes[3];
  std::ptrdiff_t offset = 0;
  for (int a = 0; a < 3; ++a) {
    Axis& axis = axes[a];
    const double g = a_ijk[a] + 0.5;
    axis.size = n[a];
    axis.index = std::clamp(static_cast<int>(std::floor(g + t0 * d[a])), 0, n[a] - 1);
    offset += axis.index * stride[a];
    if (d[a] > 0.0) {
      axis.step = 1;
      axis.tDelta = 1.0 / d[a];
      axis.tNext = (axis.index + 1 - g) * axis.tDelta;
    } else if (d[a] < 0.0) {
      axis.step = -1;
      axis.tDelta = -1.0 / d[a];
      axis.tNext = (g - axis.index) * axis.tDelta;
    } else {
      axis.step = 0;
      axis.tDelta = 0.0;
      axis.tNext = std::numeric_limits<double>::infinity();
    }
    axis.offsetStep = axis.step * stride[a];
  }

  const float* data = vol.data();
  double sum = 0.0;
  double t = t0;
  Axis x = axes[0], y = axes[1], z = axes[2];
  // Crosses the next boundary of `axis`: adds the path in the current voxel and moves to the neighbour. Returns false
  // when the ray ends first (t1) or leaves the grid.
  const auto cross = [&](Axis& axis) {
    if (axis.tNext >= t1) return false;
    sum += (axis.tNext - t) * data[offset];
    t = axis.tNext;
    axis.index += axis.step;
    if (static_cast<unsigned>(axis.index) >= static_cast<unsigned>(axis.size)) {
      t = t1;  // left the grid within rounding of t1: nothing remains
      return false;
    }
    offset += axis.offsetStep;
    axis.tNext += axis.tDelta;
    return true;
  };
  for (;;) {
    if (x.tNext < y.tNext) {
      if (!(x.tNext < z.tNext ? cross(x) : cross(z))) break;
    } else if (!(y.tNext < z.tNext ? cross(y) : cross(z))) {
      break;
    }
  }
  if (t < t1) sum += (t1 - t) * data[offset];
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
