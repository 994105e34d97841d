#include "Simulation/CtSliceDegrader.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace fct {

Result<Volume> CtSliceDegrader::degrade(const Volume& ct, double sliceThickness_mm) {
  if (ct.voxelCount() == 0) return fail("cannot degrade an empty CT");
  const double s = ct.spacing_mm().z();
  if (!(std::isfinite(sliceThickness_mm) && sliceThickness_mm > 0.0)) {
    return fail(fmt::format("slice thickness must be a positive number of mm, got {}", sliceThickness_mm));
  }
  if (sliceThickness_mm < s - 1e-9) {
    return fail(fmt::format("slice thickness {} mm is finer than the CT's {} mm slices; degradation only makes slices "
                            "thicker", sliceThickness_mm, s));
  }
  const Eigen::Vector3i& dims = ct.dims();
  const int n = dims.z();
  // Slab coordinate z (mm along k from the centre of original slice 0): the original covers [−s/2, n·s − s/2].
  const double slab_mm = n * s;
  const int nNew = std::max(1, static_cast<int>(std::lround(slab_mm / sliceThickness_mm)));
  const double spacing_mm = slab_mm / nNew;
  const double halfThickness_mm = 0.5 * sliceThickness_mm;

  // Per new slice: the weight of every original slice (the overlap of the profile with its box, over Δh) and the
  // weight of the air beyond the original's faces.
  std::vector<std::vector<std::pair<int, double>>> weights(nNew);
  std::vector<double> airWeight(nNew, 0.0);
  for (int m = 0; m < nNew; ++m) {
    const double centre_mm = -0.5 * s + (m + 0.5) * spacing_mm;
    const double low_mm = centre_mm - halfThickness_mm, high_mm = centre_mm + halfThickness_mm;
    const int kLow = std::max(0, static_cast<int>(std::floor(low_mm / s + 0.5)));
    const int kHigh = std::min(n - 1, static_cast<int>(std::floor(high_mm / s + 0.5)));
    double inside = 0.0;
    for (int k = kLow; k <= kHigh; ++k) {
      const double overlap_mm = std::min(high_mm, (k + 0.5) * s) - std::max(low_mm, (k - 0.5) * s);
      if (overlap_mm <= 0.0) continue;
      weights[m].emplace_back(k, overlap_mm / sliceThickness_mm);
      inside += overlap_mm / sliceThickness_mm;
    }
    airWeight[m] = std::max(0.0, 1.0 - inside);
  }

  const Eigen::Vector3d origin_lps_mm =
      ct.origin_lps_mm() + ct.direction_lps().col(2) * (-0.5 * s + 0.5 * spacing_mm);
  auto created = Volume::create(Eigen::Vector3i(dims.x(), dims.y(), nNew),
                                Eigen::Vector3d(ct.spacing_mm().x(), ct.spacing_mm().y(), spacing_mm), origin_lps_mm,
                                ct.direction_lps());
  if (!created.ok()) return fail(created.error());
  Volume out = std::move(created).value();
  const std::size_t sliceSize = static_cast<std::size_t>(dims.x()) * dims.y();
  tbb::parallel_for(0, nNew, [&](int m) {
    float* target = out.voxels().data() + m * sliceSize;
    std::vector<double> sum(sliceSize, airWeight[m] * kAir_hu);
    for (const auto& [k, w] : weights[m]) {
      const float* source = ct.voxels().data() + k * sliceSize;
      for (std::size_t v = 0; v < sliceSize; ++v) sum[v] += w * source[v];
    }
    for (std::size_t v = 0; v < sliceSize; ++v) target[v] = static_cast<float>(sum[v]);
  });
  out.description = fmt::format("{}; degraded to {:.4g} mm slices with a {:g} mm box slice profile over the same "
                                "{:g} mm slab", ct.description, spacing_mm, sliceThickness_mm, slab_mm);
  return out;
}

}  // namespace fct
