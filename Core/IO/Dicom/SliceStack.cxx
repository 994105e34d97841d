#include "IO/Dicom/SliceStack.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "Base/LargePages.h"

namespace fct {

namespace {

/// Rounds x to the nearest integer when it is within rounding noise of it, so that unshifted slices copy exactly.
double snapToInteger(double x) {
  const double r = std::round(x);
  return std::abs(x - r) < 1e-6 ? r : x;
}

/// Adds weight × the bilinear sample of a cols×rows slice at (fi0 + i, fj) to out[i] for i in [0, n); taps outside
/// the slice read outside_value.
void accumulateRow(const float* slice, int cols, int rows, double fi0, double fj, float outside_value, float weight,
                   float* out, int n) {
  const int j0 = static_cast<int>(std::floor(fj));
  const float wj = static_cast<float>(fj - j0);
  const float* row0 = (j0 >= 0 && j0 < rows) ? slice + static_cast<std::size_t>(j0) * cols : nullptr;
  const float* row1 = (j0 + 1 >= 0 && j0 + 1 < rows) ? slice + static_cast<std::size_t>(j0 + 1) * cols : nullptr;
  const int i0 = static_cast<int>(std::floor(fi0));
  const float wi = static_cast<float>(fi0 - i0);
  const auto tap = [&](const float* row, int i) { return (row && i >= 0 && i < cols) ? row[i] : outside_value; };
  for (int i = 0; i < n; ++i) {
    const int ii = i0 + i;
    const float top = (1.0f - wi) * tap(row0, ii) + wi * tap(row0, ii + 1);
    const float bottom = wj > 0.0f ? (1.0f - wi) * tap(row1, ii) + wi * tap(row1, ii + 1) : top;
    out[i] += weight * ((1.0f - wj) * top + wj * bottom);
  }
}

}  // namespace

Result<SliceStack> SliceStack::create(const Eigen::Vector2i& size_px, const Eigen::Vector2d& pixelSpacing_mm,
                                      const Eigen::Vector3d& rowCosine_lps, const Eigen::Vector3d& columnCosine_lps,
                                      std::vector<Eigen::Vector3d> sliceOrigins_lps_mm) {
  if (sliceOrigins_lps_mm.size() < 2) {
    return fail(fmt::format("a slice stack needs at least 2 slices, got {}", sliceOrigins_lps_mm.size()));
  }
  if ((size_px.array() <= 0).any()) {
    return fail(fmt::format("slice size must be positive, got {}x{} pixels", size_px.x(), size_px.y()));
  }
  if (!pixelSpacing_mm.allFinite() || (pixelSpacing_mm.array() <= 0.0).any()) {
    return fail(fmt::format("pixel spacing must be positive, got {} x {} mm", pixelSpacing_mm.x(), pixelSpacing_mm.y()));
  }
  if (!rowCosine_lps.allFinite() || !columnCosine_lps.allFinite() || std::abs(rowCosine_lps.norm() - 1.0) > 1e-3 ||
      std::abs(columnCosine_lps.norm() - 1.0) > 1e-3 || std::abs(rowCosine_lps.dot(columnCosine_lps)) > 1e-3) {
    return fail("slice row and column cosines are not orthonormal unit vectors (ImageOrientationPatient is invalid)");
  }
  SliceStack stack;
  stack.m_size_px = size_px;
  stack.m_pixelSpacing_mm = pixelSpacing_mm;
  stack.m_rowCosine_lps = rowCosine_lps.normalized();
  // Re-orthogonalize against rounding in the file's cosines so that the volume direction is a rotation.
  stack.m_columnCosine_lps =
      (columnCosine_lps - columnCosine_lps.dot(stack.m_rowCosine_lps) * stack.m_rowCosine_lps).normalized();
  const Eigen::Vector3d normal = stack.normal_lps();
  for (std::size_t m = 0; m + 1 < sliceOrigins_lps_mm.size(); ++m) {
    if (!sliceOrigins_lps_mm[m].allFinite()) return fail(fmt::format("slice {} origin is not finite", m));
    const double gap_mm = normal.dot(sliceOrigins_lps_mm[m + 1] - sliceOrigins_lps_mm[m]);
    if (!(gap_mm >= kMinGap_mm)) {
      return fail(fmt::format("slices {} and {} are {:.4f} mm apart along the normal; slices must be sorted by "
                              "strictly increasing position", m, m + 1, gap_mm));
    }
  }
  stack.m_origins_lps_mm = std::move(sliceOrigins_lps_mm);
  assignWithLargePages(stack.m_pixels, stack.sliceOffset(stack.sliceCount()), 0.0f);
  return stack;
}

std::pair<float, float> SliceStack::valueRange() const {
  if (m_pixels.empty()) return {0.0f, 0.0f};
  const auto [lo, hi] = std::minmax_element(m_pixels.begin(), m_pixels.end());
  return {*lo, *hi};
}

SliceStackLayout SliceStack::layout() const {
  SliceStackLayout layout;
  const Eigen::Vector3d normal = normal_lps();
  const Eigen::Vector3d& first = m_origins_lps_mm.front();
  layout.minGap_mm = std::numeric_limits<double>::max();
  for (int m = 0; m < sliceCount(); ++m) {
    const Eigen::Vector3d step = m_origins_lps_mm[m] - first;
    const Eigen::Vector3d inPlane = step - normal.dot(step) * normal;
    layout.maxInPlaneShift_mm = std::max(layout.maxInPlaneShift_mm, inPlane.norm());
    if (m + 1 < sliceCount()) {
      const double gap_mm = normal.dot(m_origins_lps_mm[m + 1] - m_origins_lps_mm[m]);
      layout.minGap_mm = std::min(layout.minGap_mm, gap_mm);
      layout.maxGap_mm = std::max(layout.maxGap_mm, gap_mm);
    }
  }
  const Eigen::Vector3d span = m_origins_lps_mm.back() - first;
  const double along_mm = normal.dot(span);
  layout.meanGap_mm = along_mm / (sliceCount() - 1);
  layout.tilt_deg = std::atan2((span - along_mm * normal).norm(), along_mm) * 180.0 / std::numbers::pi;
  layout.uniformSpacing = layout.maxGap_mm - layout.minGap_mm <= std::max(0.01 * layout.meanGap_mm, 0.01);
  layout.alongNormal = layout.maxInPlaneShift_mm <= 0.1 * m_pixelSpacing_mm.minCoeff();
  return layout;
}

Result<Volume> SliceStack::toVolume() && {
  const SliceStackLayout layout = this->layout();
  if (!layout.isRegular()) {
    return fail(fmt::format("slices are not on a regular grid (gaps {:.3f}–{:.3f} mm, tilt {:.2f}°); resample them",
                            layout.minGap_mm, layout.maxGap_mm, layout.tilt_deg));
  }
  Eigen::Matrix3d direction;
  direction << m_rowCosine_lps, m_columnCosine_lps, normal_lps();
  auto volume = Volume::fromVoxels({m_size_px.x(), m_size_px.y(), sliceCount()},
                                   {m_pixelSpacing_mm.x(), m_pixelSpacing_mm.y(), layout.meanGap_mm},
                                   m_origins_lps_mm.front(), direction, std::move(m_pixels));
  m_pixels.clear();
  m_origins_lps_mm.clear();
  return volume;
}

Result<Volume> SliceStack::resampled(double sliceSpacing_mm, float outside_value) const {
  if (!std::isfinite(sliceSpacing_mm) || sliceSpacing_mm <= 0.0) {
    return fail(fmt::format("resampling slice spacing must be positive, got {} mm", sliceSpacing_mm));
  }
  const int count = sliceCount();
  const Eigen::Vector3d normal = normal_lps();
  const Eigen::Vector3d& first = m_origins_lps_mm.front();
  // Each slice's position along the normal (w) and in-plane offset (a along i, b along j) relative to the first.
  std::vector<double> w(count), a(count), b(count);
  for (int m = 0; m < count; ++m) {
    const Eigen::Vector3d step = m_origins_lps_mm[m] - first;
    w[m] = normal.dot(step);
    a[m] = m_rowCosine_lps.dot(step);
    b[m] = m_columnCosine_lps.dot(step);
  }
  const double du = m_pixelSpacing_mm.x();
  const double dv = m_pixelSpacing_mm.y();
  const double aMin = *std::min_element(a.begin(), a.end());
  const double bMin = *std::min_element(b.begin(), b.end());
  const double aMax = *std::max_element(a.begin(), a.end()) + (m_size_px.x() - 1) * du;
  const double bMax = *std::max_element(b.begin(), b.end()) + (m_size_px.y() - 1) * dv;
  const double ni = std::ceil((aMax - aMin) / du - 1e-6) + 1.0;
  const double nj = std::ceil((bMax - bMin) / dv - 1e-6) + 1.0;
  const double nk = std::floor(w.back() / sliceSpacing_mm + 1e-6) + 1.0;
  if (ni * nj * nk > 2e9) {
    return fail(fmt::format("resampled grid {}x{}x{} at {} mm slice spacing is too large; choose a larger spacing", ni,
                            nj, nk, sliceSpacing_mm));
  }
  // Tilt and gaps enlarge a real series' grid a few times at most; far more means implausible slice positions (a
  // damaged file) or a spacing far below the slice gaps, and would only fill memory with empty voxels.
  constexpr double kMaxGrowth = 64.0;
  const double stackVoxels = static_cast<double>(m_size_px.x()) * m_size_px.y() * count;
  if (ni * nj * nk > kMaxGrowth * stackVoxels) {
    return fail(fmt::format("resampled grid {}x{}x{} at {} mm slice spacing would hold {:.0f} times the {} slices' "
                            "voxels; the slice origins spread {:.1f} mm in-plane and {:.1f} mm along the normal, "
                            "which looks damaged, or the spacing is far too small; check ImagePositionPatient or "
                            "choose a larger spacing",
                            ni, nj, nk, sliceSpacing_mm, ni * nj * nk / stackVoxels, count,
                            std::hypot(aMax - aMin - (m_size_px.x() - 1) * du, bMax - bMin - (m_size_px.y() - 1) * dv),
                            w.back()));
  }
  Eigen::Matrix3d direction;
  direction << m_rowCosine_lps, m_columnCosine_lps, normal;
  const Eigen::Vector3d origin = first + aMin * m_rowCosine_lps + bMin * m_columnCosine_lps;
  auto result = Volume::create(Eigen::Vector3i(static_cast<int>(ni), static_cast<int>(nj), static_cast<int>(nk)),
                               Eigen::Vector3d(du, dv, sliceSpacing_mm), origin, direction, 0.0f);
  if (!result) return result;
  Volume& volume = result.value();
  const Eigen::Vector3i dims = volume.dims();
  int m = 0;
  for (int k = 0; k < dims.z(); ++k) {
    const double wk = k * sliceSpacing_mm;
    while (m + 2 < count && w[m + 1] <= wk) ++m;
    const float t = static_cast<float>(std::clamp((wk - w[m]) / (w[m + 1] - w[m]), 0.0, 1.0));
    for (int j = 0; j < dims.y(); ++j) {
      float* out = &volume.at(0, j, k);
      for (int s = m; s <= m + 1; ++s) {
        const float weight = s == m ? 1.0f - t : t;
        if (weight == 0.0f) continue;
        // Pixel coordinates in slice s of output voxel (0, j, k).
        const double fi0 = snapToInteger((aMin - a[s]) / du);
        const double fj = snapToInteger(j + (bMin - b[s]) / dv);
        accumulateRow(slice(s), m_size_px.x(), m_size_px.y(), fi0, fj, outside_value, weight, out, dims.x());
      }
    }
  }
  return result;
}

}  // namespace fct
