#include "Simulation/Physics/CubicBsplinePatient.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fct {

namespace {

constexpr double kAir_hu = -1000.0;

/// In place: the cubic B-spline interpolation coefficients of the `count` samples of `line`, mirror
/// boundaries (Unser 1999; initial causal coefficient truncated where the pole's powers fall below 1e-9).
void prefilterLine(double* line, int count) {
  if (count < 2) return;
  const double z = std::sqrt(3.0) - 2.0;
  for (int n = 0; n < count; ++n) line[n] *= 6.0;  // (1 − z)(1 − 1/z)
  const int horizon = std::min(count, static_cast<int>(std::ceil(std::log(1e-9) / std::log(std::abs(z)))));
  double sum = 0.0, zn = 1.0;
  for (int n = 0; n < horizon; ++n, zn *= z) sum += zn * line[n];
  line[0] = sum;
  for (int n = 1; n < count; ++n) line[n] += z * line[n - 1];
  line[count - 1] = (z / (z * z - 1.0)) * (z * line[count - 2] + line[count - 1]);
  for (int n = count - 2; n >= 0; --n) line[n] = z * (line[n + 1] - line[n]);
}

/// Prefilters every line of `c` (dims, x fastest) along `axis`.
void prefilterAxis(std::vector<float>& c, const Eigen::Vector3i& dims, int axis) {
  const std::ptrdiff_t stride[3] = {1, dims.x(), static_cast<std::ptrdiff_t>(dims.x()) * dims.y()};
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  tbb::parallel_for(0, dims[a2], [&](int u2) {
    std::vector<double> line(dims[axis]);
    for (int u1 = 0; u1 < dims[a1]; ++u1) {
      const std::ptrdiff_t base = u1 * stride[a1] + u2 * stride[a2];
      for (int n = 0; n < dims[axis]; ++n) line[n] = c[base + n * stride[axis]];
      prefilterLine(line.data(), dims[axis]);
      for (int n = 0; n < dims[axis]; ++n) c[base + n * stride[axis]] = static_cast<float>(line[n]);
    }
  });
}

/// Index `n` reflected into 0..count−1 (whole-sample mirror, period 2·count − 2).
int mirror(int n, int count) {
  if (count == 1) return 0;
  const int period = 2 * count - 2;
  n %= period;
  if (n < 0) n += period;
  return n < count ? n : period - n;
}

}  // namespace

Result<CubicBsplinePatient> CubicBsplinePatient::create(const Volume& ct, const HuMaterialModel& model,
                                                        double extension_mm) {
  if (ct.voxelCount() == 0) return fail("cannot simulate X-rays of an empty CT");
  if (Status valid = model.validate(); !valid) return fail(valid.error());
  if (!(extension_mm >= 0.0 && extension_mm <= 1000.0)) {
    return fail(fmt::format("patient extension beyond the CT must be 0..1000 mm, got {}", extension_mm));
  }
  const auto bad = std::find_if(ct.voxels().begin(), ct.voxels().end(), [](float v) { return !std::isfinite(v); });
  if (bad != ct.voxels().end()) {
    return fail(fmt::format("CT voxel {} is {}; every voxel must be a finite HU value", bad - ct.voxels().begin(), *bad));
  }
  CubicBsplinePatient patient;
  patient.m_dims = ct.dims();
  patient.m_coefficients = ct.voxels();
  for (int axis = 0; axis < 3; ++axis) prefilterAxis(patient.m_coefficients, patient.m_dims, axis);
  const double extension_ijk = extension_mm / ct.spacing_mm().z();
  patient.m_boxLow_ijk = Eigen::Vector3d(-0.5, -0.5, -0.5 - extension_ijk);
  patient.m_boxHigh_ijk = ct.dims().cast<double>() - Eigen::Vector3d(0.5, 0.5, 0.5 - extension_ijk);
  patient.m_T_ijk_from_ct = ct.T_ijk_from_lps();
  patient.m_model = model;
  patient.m_step_mm = 0.5 * ct.spacing_mm().minCoeff();
  return patient;
}

double CubicBsplinePatient::valueAtIjk(const Eigen::Vector3d& ijk) const {
  int index[3][4];
  double weight[3][4];
  for (int a = 0; a < 3; ++a) {
    const double floor = std::floor(ijk[a]);
    const double t = ijk[a] - floor, u = 1.0 - t, t2 = t * t, t3 = t2 * t;
    weight[a][0] = u * u * u / 6.0;
    weight[a][1] = (4.0 - 6.0 * t2 + 3.0 * t3) / 6.0;
    weight[a][2] = (1.0 + 3.0 * t + 3.0 * t2 - 3.0 * t3) / 6.0;
    weight[a][3] = t3 / 6.0;
    const int first = static_cast<int>(floor) - 1;
    for (int q = 0; q < 4; ++q) index[a][q] = mirror(first + q, m_dims[a]);
  }
  const std::ptrdiff_t sliceSize = static_cast<std::ptrdiff_t>(m_dims.x()) * m_dims.y();
  double value = 0.0;
  for (int qk = 0; qk < 4; ++qk) {
    const float* slice = m_coefficients.data() + index[2][qk] * sliceSize;
    double plane = 0.0;
    for (int qj = 0; qj < 4; ++qj) {
      const float* row = slice + static_cast<std::ptrdiff_t>(index[1][qj]) * m_dims.x();
      const double line = weight[0][0] * row[index[0][0]] + weight[0][1] * row[index[0][1]] +
                          weight[0][2] * row[index[0][2]] + weight[0][3] * row[index[0][3]];
      plane += weight[1][qj] * line;
    }
    value += weight[2][qk] * plane;
  }
  return value;
}

double CubicBsplinePatient::value_hu(const Eigen::Vector3d& p_ct_mm) const {
  const Eigen::Vector3d ijk = m_T_ijk_from_ct * p_ct_mm;
  if ((ijk.array() < m_boxLow_ijk.array()).any() || (ijk.array() > m_boxHigh_ijk.array()).any()) return kAir_hu;
  return valueAtIjk(ijk);
}

MassPaths CubicBsplinePatient::trace(const Eigen::Vector3d& origin_ct_mm, const Eigen::Vector3d& direction_ct) const {
  MassPaths paths{};
  // In index space the ray keeps its parameter t in mm: p_ijk(t) = o + t d with d = A · direction (A has 1/spacing).
  const Eigen::Vector3d o = m_T_ijk_from_ct * origin_ct_mm;
  const Eigen::Vector3d d = m_T_ijk_from_ct.linear() * direction_ct;
  double tEnter = 0.0, tExit = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < m_boxLow_ijk[a] || o[a] > m_boxHigh_ijk[a]) return paths;
      continue;
    }
    double t0 = (m_boxLow_ijk[a] - o[a]) / d[a], t1 = (m_boxHigh_ijk[a] - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    tEnter = std::max(tEnter, t0);
    tExit = std::min(tExit, t1);
  }
  if (!(tEnter < tExit)) return paths;
  const int samples = std::max(1, static_cast<int>(std::ceil((tExit - tEnter) / m_step_mm)));
  const double step = (tExit - tEnter) / samples;
  for (int q = 0; q < samples; ++q) {
    const double value = valueAtIjk(o + d * (tEnter + (q + 0.5) * step));
    m_model.accumulate(static_cast<float>(value), step * 0.1, paths);  // mm -> cm
  }
  return paths;
}

}  // namespace fct
