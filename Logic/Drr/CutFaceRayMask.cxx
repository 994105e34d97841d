#include "Drr/CutFaceRayMask.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

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

/// Nearest index of a coordinate x >= -0.5 (the ray is clipped to the volume's prism), as std::lround.
int nearest(double x) { return static_cast<int>(std::floor(x + 0.5)); }

/// Narrows [qFirst, qLast] (sample indices; sample q at t0 + step·q) to the samples whose coordinate a + d·t along
/// one axis lies in [low, high]; the result stays inside the given range (empty: qLast < qFirst).
void narrowToSlab(double a, double d, double t0, double step, double low, double high, int& qFirst, int& qLast) {
  const double slope = d * step;  // coordinate change per sample
  const double start = a + d * t0;
  if (slope == 0.0) {
    if (start < low || start > high) qLast = qFirst - 1;
    return;
  }
  double q0 = (low - start) / slope, q1 = (high - start) / slope;
  if (q0 > q1) std::swap(q0, q1);
  // Clamped to the current range before the conversion, which a nearly parallel ray would overflow.
  qFirst = static_cast<int>(std::clamp(std::floor(q0), double(qFirst), double(qLast) + 1.0));
  qLast = static_cast<int>(std::clamp(std::ceil(q1), double(qFirst) - 1.0, double(qLast)));
}

}  // namespace

Result<CutFaceRayMask> CutFaceRayMask::create(const DrrVolume& volume, double margin_mm) {
  if (!(std::isfinite(margin_mm) && margin_mm >= 0.0 && margin_mm <= 500.0)) {
    return fail(fmt::format("cut-face margin must be 0..500 mm, got {}", margin_mm));
  }
  CutFaceRayMask mask;
  mask.m_T_ijk_from_ct = volume.T_ijk_from_ct();
  mask.m_dims = volume.values().dims();
  mask.m_margin_ijk = margin_mm * volume.values().spacing_mm().cwiseInverse();
  const Eigen::Vector2i grow(static_cast<int>(std::ceil(mask.m_margin_ijk.x())),
                             static_cast<int>(std::ceil(mask.m_margin_ijk.y())));
  for (auto [face, k] : {std::make_pair(&mask.m_low, 0), std::make_pair(&mask.m_high, mask.m_dims.z() - 1)}) {
    face->footprint = sliceFootprint(volume, k, grow);
    face->iMin = mask.m_dims.x();
    face->jMin = mask.m_dims.y();
    face->blockCols = (mask.m_dims.x() + kBlock - 1) / kBlock;
    face->blocks.assign(static_cast<std::size_t>(face->blockCols) * ((mask.m_dims.y() + kBlock - 1) / kBlock), 0);
    for (int j = 0; j < mask.m_dims.y(); ++j)
      for (int i = 0; i < mask.m_dims.x(); ++i) {
        if (!face->footprint[static_cast<std::size_t>(j) * mask.m_dims.x() + i]) continue;
        face->blocks[static_cast<std::size_t>(j / kBlock) * face->blockCols + i / kBlock] = 1;
        face->iMin = std::min(face->iMin, i);
        face->iMax = std::max(face->iMax, i);
        face->jMin = std::min(face->jMin, j);
        face->jMax = std::max(face->jMax, j);
      }
  }
  return mask;
}

bool CutFaceRayMask::crosses(const Face& face, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double t0,
                             double t1) const {
  if (!(t1 > t0) || face.iMax < face.iMin) return false;
  const int ni = m_dims.x(), nj = m_dims.y();
  const double inPlane = d.head<2>().norm() * (t1 - t0);
  const int samples = std::max(2, static_cast<int>(std::ceil(2.0 * inPlane)) + 1);
  const double step = (t1 - t0) / (samples - 1);
  // Only samples within a voxel of the footprint's bounding box can round into it (the clamp to the volume maps
  // nothing from outside the box into it either).
  int qFirst = 0, qLast = samples - 1;
  narrowToSlab(a.x(), d.x(), t0, step, face.iMin - 1.0, face.iMax + 1.0, qFirst, qLast);
  narrowToSlab(a.y(), d.y(), t0, step, face.jMin - 1.0, face.jMax + 1.0, qFirst, qLast);
  // An empty block: every sample whose coordinates round into it is off the footprint, so the walk jumps to the last
  // sample surely still in it (its range shrunk by kInside against rounding; clamped blocks reach on without end),
  // then on by one. A sample's coordinate along an axis is start + slope * q.
  constexpr double kInside = 1e-6;
  const int lastBlockI = (ni - 1) / kBlock, lastBlockJ = (nj - 1) / kBlock;
  const double startI = a.x() + d.x() * t0, slopeI = d.x() * step;
  const double startJ = a.y() + d.y() * t0, slopeJ = d.y() * step;
  const auto exitAlong = [](double start, double slope, int block, int lastBlock) {
    if (slope > 0.0 && block < lastBlock) return ((block + 1) * kBlock - 0.5 - kInside - start) / slope;
    if (slope < 0.0 && block > 0) return (block * kBlock - 0.5 + kInside - start) / slope;
    return std::numeric_limits<double>::infinity();
  };
  for (int q = qFirst; q <= qLast;) {
    const Eigen::Vector3d p = a + d * (t0 + (t1 - t0) * q / (samples - 1));
    const int i = std::clamp(nearest(p.x()), 0, ni - 1);
    const int j = std::clamp(nearest(p.y()), 0, nj - 1);
    const int bi = i / kBlock, bj = j / kBlock;
    if (face.blocks[static_cast<std::size_t>(bj) * face.blockCols + bi]) {
      if (face.footprint[static_cast<std::size_t>(j) * ni + i]) return true;
      ++q;
      continue;
    }
    const double qExit = std::min(exitAlong(startI, slopeI, bi, lastBlockI), exitAlong(startJ, slopeJ, bj, lastBlockJ));
    q = qExit >= qLast ? qLast + 1 : std::max(q, static_cast<int>(std::floor(qExit))) + 1;
  }
  return false;
}

ValidMask CutFaceRayMask::compute(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct) const {
  const DrrRayGeometry geometry(camera, T_world_from_ct, m_T_ijk_from_ct);
  constexpr double kEndless = 1e12;  // the in-plane box continues along k without end
  const Eigen::Vector3d prismLow(-0.5, -0.5, -kEndless);
  const Eigen::Vector3d prismHigh(m_dims.x() - 0.5, m_dims.y() - 0.5, kEndless);
  const double kLow = -0.5 + m_margin_ijk.z(), kHigh = m_dims.z() - 0.5 - m_margin_ijk.z();
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
      if (crosses(m_low, a, d, lowFrom, lowTo) || crosses(m_high, a, d, highFrom, highTo)) {
        mask.valid[static_cast<std::size_t>(row) * geometry.cols() + col] = 0;
      }
    }
  });
  return mask;
}

}  // namespace fct
