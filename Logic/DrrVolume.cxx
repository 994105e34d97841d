#include "DrrVolume.h"

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <functional>

namespace fct {

Result<DrrVolume> DrrVolume::create(const Volume& ct, const DrrValueOptions& options) {
  if (ct.voxelCount() == 0) return fail("the CT volume is empty; load a CT before rendering DRRs");
  if (options.kind == DrrValueKind::Attenuation &&
      (!std::isfinite(options.waterAttenuation_per_mm) || options.waterAttenuation_per_mm <= 0.0)) {
    return fail(fmt::format("water attenuation must be positive and finite, got {} /mm", options.waterAttenuation_per_mm));
  }
  DrrVolume volume;
  volume.m_values = ct;
  volume.m_options = options;
  volume.m_T_ct_from_ijk = ct.T_lps_from_ijk();
  volume.m_T_ijk_from_ct = ct.T_ijk_from_lps();

  std::vector<float>& voxels = volume.m_values.voxels();
  const float mu_water = static_cast<float>(options.waterAttenuation_per_mm);
  const bool attenuation = options.kind == DrrValueKind::Attenuation;
  const std::size_t nonFinite = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, voxels.size(), 1 << 16), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& range, std::size_t count) {
        for (std::size_t n = range.begin(); n != range.end(); ++n) {
          const float value = voxels[n];
          if (!std::isfinite(value)) {
            ++count;
            voxels[n] = 0.0f;
          } else if (attenuation) {
            voxels[n] = value <= -1000.0f ? 0.0f : mu_water * (1.0f + value * 0.001f);
          }
        }
        return count;
      },
      std::plus<>());
  if (nonFinite > 0) {
    return fail(fmt::format("the CT has {} voxels that are NaN or infinite; repair or re-export the volume", nonFinite));
  }
  return volume;
}

Result<DrrValueKind> DrrVolume::parseValueKind(std::string_view name) {
  if (name == "attenuation") return DrrValueKind::Attenuation;
  if (name == "raw") return DrrValueKind::Raw;
  return fail(fmt::format("unknown DRR values '{}'; use 'attenuation' or 'raw'", name));
}

std::string_view DrrVolume::valueKindName(DrrValueKind kind) {
  return kind == DrrValueKind::Raw ? "raw" : "attenuation";
}

}  // namespace fct
