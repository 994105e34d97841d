#include "Drr/CutFaceRayMask.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "Drr/DrrRayGeometry.h"

namespace fct {

namespace {

/// In-plane footprint of slice k of `volume`: 1 where its value is tissue (above −500 HU), grown by `grow` voxels
/// along i and j (square).
std::vector<std::uint8_t> sliceFootprint(const DrrVolume& volume, int k, const Eigen::Vector2i& grow) {
  const Volume& values = volume.values();
  const int ni = values.dims().x(), nj = values.dims().y();
  const double threshold = volume.options().kind == DrrValueKind::Attenuation
                               ? 0.5 * volume.options().waterAttenuation_per_mm
                               : -500.0;
  std::vector<std::uint8_t> tissue(static_cast<std::size_t>(ni) * nj, 0), rows(tissue.size(), 0);
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i < ni; ++i) tissue[static_cast<std::size_t>(j) * ni + i] = values.at(i, j, k) > threshold;
  for (int j = 0; j < nj; ++j)  // grow along i
    for (int i = 0; i < ni; ++i) {
      if (!tissue[static_cast<std::size_t>(j) * ni + i]) continue;
      for (int q = std::max(0, i - grow.x()); q <= std::min(ni - 1, i + grow.x()); ++q) rows[static_cast<std::size_t>(j) * ni + q] = 1;
    }
  std::fill(tissue.begin(), tissue.end(), 0);
  for (int j = 0; j < nj; ++j)  // then along j
    for (int i = 0; i < ni; ++i) {
      if (!rows[static_cast<std::size_t>(j) * ni + i]) continue;
      for (int q = std::max(0, j - grow.y()); q <= std::min(nj - 1, j + grow.y()); ++q) tissue[static_cast<std::size_t>(q) * ni + i] = 1;
    }
  return tissue;
}

/// True when the segment a + t·d, t in [t0, t1] (ijk), passes over a footprint pixel (sampled every half voxel).
bool crossesFootprint(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double t0, double t1,
                      const std::vector<std::uint8_t>& footprint, int ni, int nj) {
  if (!(t1 > t0)) return false;
  const double inPlane = d.head<2>().norm() * (t1 - t0);
  const int samples = std::max(2, static_cast<int>(std::ceil(2.0 * inPlane)) + 1);
  for (int q = 0; q < samples; ++q) {
    const Eigen::Vector3d p = a + d * (t0 + (t1 - t0) * q / (samples - 1));
    const int i = std::clamp(static_cast<int>(std::lround(p.x())), 0, ni - 1);
    const int j = std::clamp(static_cast<int>(std::lround(p.y())), 0, nj - 1);
    if (footprint[static_cast<std::size_t>(j) * ni + i]) return true;
  }
  return false;
}

}  // namespace

Result<ValidMask> CutFaceRayMask::compute(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                                          const DrrVolume& volume, double margin_mm) {
  if (!(std::isfinite(margin_mm) && margin_mm >= 0.0 && margin_mm <= 500.0)) {
    return fail(fmt::format("cut-face margin must be 0..500 mm, got {}", margin_mm));
  }
  const DrrRayGeometry geometry(camera, T_world_from_ct, volume.T_ijk_from_ct());
  const Eigen::Vector3i& dims = volume.values().dims();
  const Eigen::Vector3d margin_ijk = margin_mm * volume.values().spacing_mm().cwiseInverse();
  const Eigen::Vector2i grow(static_cast<int>(std::ceil(margin_ijk.x())), static_cast<int>(std::ceil(margin_ijk.y())));
  const std::vector<std::uint8_t> lowFace = sliceFootprint(volume, 0, grow);
  const std::vector<std::uint8_t> highFace = sliceFootprint(volume, dims.z() - 1, grow);
  constexpr double kEndless = 1e12;  // the in-plane box continues along k without end
  const Eigen::Vector3d prismLow(-0.5, -0.5, -kEndless);
  const Eigen::Vector3d prismHigh(dims.x() - 0.5, dims.y() - 0.5, kEndless);
  const double kLow = -0.5 + margin_ijk.z(), kHigh = dims.z() - 0.5 - margin_ijk.z();
  ValidMask mask = ValidMask::allValid(geometry.cols(), geometry.rows());
  tbb::parallel_for(0, geometry.rows(), [&](int row) {
    for (int col = 0; col < geometry.cols(); ++col) {
      const Eigen::Vector3d& a = geometry.source_ijk();
      const Eigen::Vector3d d = geometry.detectorPoint_ijk(col, row) - a;
      double t0 = 0.0, t1 = 1.0;
      if (!DrrRayGeometry::clipToBox(a, d, prismLow, prismHigh, t0, t1)) continue;
      // The parts of [t0, t1] at k < kLow and at k > kHigh.
      double lowFrom = t0, lowTo = t0, highFrom = t0, highTo = t0;
      if (d.z() == 0.0) {
        if (a.z() < kLow) lowTo = t1;
        if (a.z() > kHigh) highTo = t1;
      } else {
        const double tAtLow = (kLow - a.z()) / d.z(), tAtHigh = (kHigh - a.z()) / d.z();
        if (d.z() > 0.0) {
          lowTo = std::min(t1, tAtLow);
          highFrom = std::max(t0, tAtHigh);
          highTo = t1;
        } else {
          lowFrom = std::max(t0, tAtLow);
          lowTo = t1;
          highTo = std::min(t1, tAtHigh);
        }
      }
      if (crossesFootprint(a, d, lowFrom, lowTo, lowFace, dims.x(), dims.y()) ||
          crossesFootprint(a, d, highFrom, highTo, highFace, dims.x(), dims.y())) {
        mask.valid[static_cast<std::size_t>(row) * geometry.cols() + col] = 0;
      }
    }
  });
  return mask;
}

}  // namespace fct
