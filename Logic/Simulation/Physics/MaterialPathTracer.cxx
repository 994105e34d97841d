#include "Simulation/Physics/MaterialPathTracer.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fct {

Result<MaterialPathTracer> MaterialPathTracer::create(const Volume& ct, const HuMaterialModel& model) {
  if (ct.voxelCount() == 0) return fail("cannot simulate X-rays of an empty CT");
  if (Status valid = model.validate(); !valid) return fail(valid.error());
  const auto bad = std::find_if(ct.voxels().begin(), ct.voxels().end(), [](float v) { return !std::isfinite(v); });
  if (bad != ct.voxels().end()) {
    return fail(fmt::format("CT voxel {} is {}; every voxel must be a finite HU value", bad - ct.voxels().begin(), *bad));
  }
  MaterialPathTracer tracer;
  tracer.m_ct = &ct;
  tracer.m_model = model;
  tracer.m_T_ijk_from_ct = ct.T_ijk_from_lps();
  return tracer;
}

MassPaths MaterialPathTracer::trace(const Eigen::Vector3d& origin_ct_mm, const Eigen::Vector3d& direction_ct) const {
  MassPaths paths{};
  const Eigen::Vector3i& dims = m_ct->dims();
  // In index space the ray keeps its parameter t in mm: p_ijk(t) = o + t d with d = A · direction (A has 1/spacing).
  const Eigen::Vector3d o = m_T_ijk_from_ct * origin_ct_mm;
  const Eigen::Vector3d d = m_T_ijk_from_ct.linear() * direction_ct;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double tEnter = 0.0, tExit = kInf;
  for (int a = 0; a < 3; ++a) {
    const double low = -0.5, high = dims[a] - 0.5;
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < low || o[a] > high) return paths;
      continue;
    }
    double t0 = (low - o[a]) / d[a], t1 = (high - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    tEnter = std::max(tEnter, t0);
    tExit = std::min(tExit, t1);
  }
  if (!(tEnter < tExit)) return paths;

  // Voxel containing the entry point, and the t of the next boundary crossing per axis.
  const Eigen::Vector3d entry = o + d * tEnter;
  int index[3], step[3];
  double tMax[3], tDelta[3];
  std::ptrdiff_t stride[3] = {1, dims.x(), static_cast<std::ptrdiff_t>(dims.x()) * dims.y()};
  std::ptrdiff_t offset = 0;
  for (int a = 0; a < 3; ++a) {
    index[a] = std::clamp(static_cast<int>(std::floor(entry[a] + 0.5)), 0, dims[a] - 1);
    offset += index[a] * stride[a];
    if (std::abs(d[a]) < 1e-15) {
      step[a] = 0;
      tMax[a] = kInf;
      tDelta[a] = kInf;
    } else {
      step[a] = d[a] > 0.0 ? 1 : -1;
      tMax[a] = (index[a] + 0.5 * step[a] - o[a]) / d[a];
      tDelta[a] = 1.0 / std::abs(d[a]);
    }
  }
  const float* voxels = m_ct->voxels().data();
  double t = tEnter;
  for (;;) {
    const int a = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
    const double tNext = std::min(tMax[a], tExit);
    if (tNext > t) m_model.accumulate(voxels[offset], (tNext - t) * 0.1, paths);  // mm -> cm
    if (tMax[a] >= tExit) break;
    t = tMax[a];
    index[a] += step[a];
    if (index[a] < 0 || index[a] >= dims[a]) break;
    offset += step[a] * stride[a];
    tMax[a] += tDelta[a];
  }
  return paths;
}

}  // namespace fct
