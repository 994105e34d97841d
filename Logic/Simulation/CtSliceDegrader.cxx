#include "Simulation/CtSliceDegrader.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace fct {

Result<Volume> CtSliceDegrader::degrade(const Volume& ct, double sliceSpacing_mm) {
  if (ct.voxelCount() == 0) return fail("cannot degrade an empty CT");
  const double s = ct.spacing_mm().z();
  if (!(std::isfinite(sliceSpacing_mm) && sliceSpacing_mm > 0.0)) {
    return fail(fmt::format("slice spacing must be a positive number of mm, got {}", sliceSpacing_mm));
  }
  if (sliceSpacing_mm < s - 1e-9) {
    return fail(fmt::format("slice spacing {} mm is finer than the CT's {} mm; degradation only makes slices thicker",
                            sliceSpacing_mm, s));
  }
  const Eigen::Vector3i& dims = ct.dims();
  const int n = dims.z();
  const int nNew = static_cast<int>(std::floor((n - 1) * s / sliceSpacing_mm + 1e-9)) + 1;

  // Weights of the original slices in each new slice: the box [z - Δh/2, z + Δh/2] averaged over the linear
  // interpolation between slice centres (constant beyond the first and last slice), by the midpoint rule.
  const int samples = std::max(16, static_cast<int>(std::ceil(8.0 * sliceSpacing_mm / s)));
  std::vector<std::vector<std::pair<int, double>>> weights(nNew);
  for (int m = 0; m < nNew; ++m) {
    std::map<int, double> w;
    for (int q = 0; q < samples; ++q) {
      const double z_mm = m * sliceSpacing_mm + ((q + 0.5) / samples - 0.5) * sliceSpacing_mm;
      const double k = std::clamp(z_mm / s, 0.0, double(n - 1));
      const int k0 = std::min(static_cast<int>(std::floor(k)), n - 1);
      const int k1 = std::min(k0 + 1, n - 1);
      const double f = k - k0;
      w[k0] += (1.0 - f) / samples;
      if (f > 0.0) w[k1] += f / samples;
    }
    weights[m].assign(w.begin(), w.end());
  }

  auto created = Volume::create(Eigen::Vector3i(dims.x(), dims.y(), nNew),
                                Eigen::Vector3d(ct.spacing_mm().x(), ct.spacing_mm().y(), sliceSpacing_mm),
                                ct.origin_lps_mm(), ct.direction_lps());
  if (!created.ok()) return fail(created.error());
  Volume out = std::move(created).value();
  const std::size_t sliceSize = static_cast<std::size_t>(dims.x()) * dims.y();
  tbb::parallel_for(0, nNew, [&](int m) {
    float* target = out.voxels().data() + m * sliceSize;
    std::vector<double> sum(sliceSize, 0.0);
    for (const auto& [k, w] : weights[m]) {
      const float* source = ct.voxels().data() + k * sliceSize;
      for (std::size_t v = 0; v < sliceSize; ++v) sum[v] += w * source[v];
    }
    for (std::size_t v = 0; v < sliceSize; ++v) target[v] = static_cast<float>(sum[v]);
  });
  out.description = fmt::format("{}; degraded to {} mm slices with a {} mm box slice profile", ct.description,
                                sliceSpacing_mm, sliceSpacing_mm);
  return out;
}

}  // namespace fct
