#include "Drr/Transgraph.h"

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>

#include "Geometry/RigidPose.h"

namespace fct {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Rotation samples per axis when the extents are scanned; the gaps are covered by one extra sample on each side.
constexpr int kRotationSamples = 7;
// Rays closer than this (as w over the direction length) to the planes are too oblique for the two-plane table.
constexpr double kMinDirectionCosine = 0.1;
// Default offset step over plane step (see Transgraph.h).
constexpr double kDefaultOffsetFactor = 3.0;

Eigen::Matrix3d rotationZYX_deg(const Eigen::Vector3d& angles_deg) {
  const Eigen::Vector3d a = angles_deg * (kPi / 180.0);
  return (Eigen::AngleAxisd(a.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(a.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(a.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::vector<double> symmetricSamples(double halfRange, int count) {
  if (halfRange <= 0.0) return {0.0};
  std::vector<double> samples(count);
  for (int k = 0; k < count; ++k) samples[k] = -halfRange + 2.0 * halfRange * k / (count - 1);
  return samples;
}

Status validateCamera(const Camera& camera, const char* what) {
  auto checked = Camera::create(camera.intrinsics(), camera.T_world_from_camera());
  if (!checked) return fail(fmt::format("{} is not a valid camera: {}", what, checked.error()));
  return Ok{};
}

}  // namespace

std::size_t TransgraphLayout::rayCount() const {
  std::size_t n = 1;
  for (int c : counts) n *= static_cast<std::size_t>(std::max(c, 0));
  return n;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> TransgraphLayout::rayEndpoints_ct_mm(int is, int it, int ids,
                                                                                int idt) const {
  const double s = min_mm[0] + step_mm[0] * is;
  const double t = min_mm[1] + step_mm[1] * it;
  const double ds = min_mm[2] + step_mm[2] * ids;
  const double dt = min_mm[3] + step_mm[3] * idt;
  return {origin_ct_mm + R_ct_from_plane * Eigen::Vector3d(s - 0.5 * ds, t - 0.5 * dt, front_w_mm),
          origin_ct_mm + R_ct_from_plane * Eigen::Vector3d(s + 0.5 * ds, t + 0.5 * dt, back_w_mm)};
}

Result<TransgraphLayout> Transgraph::plan(const Volume& ct, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
                                          const TransgraphParameters& parameters) {
  if (ct.voxelCount() == 0) {
    return fail("the CT volume is empty (0 voxels); load a CT before building a Transgraph");
  }
  if (!std::isfinite(parameters.spacing_mm) || parameters.spacing_mm <= 0.0) {
    return fail(fmt::format("Transgraph plane spacing must be a positive number of mm, got {}", parameters.spacing_mm));
  }
  if (!std::isfinite(parameters.offsetSpacing_mm) || parameters.offsetSpacing_mm < 0.0) {
    return fail(fmt::format("Transgraph offset spacing must be >= 0 mm (0: 3x the plane spacing), got {}",
                            parameters.offsetSpacing_mm));
  }
  if (!std::isfinite(parameters.range.rotation_deg) || parameters.range.rotation_deg < 0.0 ||
      parameters.range.rotation_deg > 60.0 || !std::isfinite(parameters.range.translation_mm) ||
      parameters.range.translation_mm < 0.0) {
    return fail(fmt::format("Transgraph validity range must be 0..60 deg and >= 0 mm, got ±{} deg, ±{} mm",
                            parameters.range.rotation_deg, parameters.range.translation_mm));
  }
  if (!std::isfinite(parameters.planeMargin_mm) || parameters.planeMargin_mm < 0.0) {
    return fail(fmt::format("Transgraph plane margin must be >= 0 mm, got {}", parameters.planeMargin_mm));
  }
  if (auto ok = validateCamera(view, "the Transgraph view"); !ok) return fail(ok.error());
  auto pose = RigidPose::validated(T_world_from_ct.matrix(), "expected pose T_world_from_ct");
  if (!pose) return fail(pose.error());

  TransgraphLayout layout;
  const double offsetSpacing_mm =
      parameters.offsetSpacing_mm > 0.0 ? parameters.offsetSpacing_mm : kDefaultOffsetFactor * parameters.spacing_mm;
  layout.step_mm = Eigen::Vector4d(parameters.spacing_mm, parameters.spacing_mm, offsetSpacing_mm, offsetSpacing_mm);
  layout.origin_ct_mm = ct.centre_lps_mm();
  layout.R_ct_from_plane = T_world_from_ct.linear().transpose() * view.T_world_from_camera().linear();
  const Eigen::Matrix3d R_plane_from_ct = layout.R_ct_from_plane.transpose();

  // Slab of the CT's bounding box (voxel edges) along the principal direction.
  const Eigen::Vector3d dims = ct.dims().cast<double>();
  double wMin = std::numeric_limits<double>::infinity(), wMax = -wMin;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? dims.x() - 0.5 : -0.5, (corner & 2) ? dims.y() - 0.5 : -0.5,
                              (corner & 4) ? dims.z() - 0.5 : -0.5);
    const double w = (R_plane_from_ct * (ct.lpsFromIjk(ijk) - layout.origin_ct_mm)).z();
    wMin = std::min(wMin, w);
    wMax = std::max(wMax, w);
  }
  layout.front_w_mm = wMin - parameters.planeMargin_mm;
  layout.back_w_mm = wMax + parameters.planeMargin_mm;
  const double slab_mm = layout.back_w_mm - layout.front_w_mm;
  const double mid_w_mm = 0.5 * (layout.front_w_mm + layout.back_w_mm);

  // Scan the poses of the range (rotation grid x translation corners; the plane coordinates are affine in the
  // translation) and the four detector corners (the maps from the detector to (s, t) and to (ds, dt) are
  // projective, so their extremes over the detector are at its corners).
  const auto& in = view.intrinsics();
  Eigen::Isometry3d T_plane_from_ct = Eigen::Isometry3d::Identity();
  T_plane_from_ct.linear() = R_plane_from_ct;
  T_plane_from_ct.translation() = -R_plane_from_ct * layout.origin_ct_mm;
  const Eigen::Vector3d source_world_mm = view.sourcePosition_world_mm();
  const Eigen::Vector3d centre_world_mm = T_world_from_ct * layout.origin_ct_mm;
  const std::vector<double> angles = symmetricSamples(parameters.range.rotation_deg, kRotationSamples);
  const std::vector<double> shifts = symmetricSamples(parameters.range.translation_mm, 2);
  Eigen::Vector4d lo = Eigen::Vector4d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector4d hi = -lo;
  for (double rx : angles) {
    for (double ry : angles) {
      for (double rz : angles) {
        const Eigen::Matrix3d R_delta = rotationZYX_deg(Eigen::Vector3d(rx, ry, rz));
        for (double tx : shifts) {
          for (double ty : shifts) {
            for (double tz : shifts) {
              Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
              D.linear() = R_delta;
              D.translation() = centre_world_mm - R_delta * centre_world_mm + Eigen::Vector3d(tx, ty, tz);
              const Eigen::Isometry3d T_plane_from_world = T_plane_from_ct * (D * T_world_from_ct).inverse();
              const Eigen::Vector3d S = T_plane_from_world * source_world_mm;
              if (S.z() >= layout.front_w_mm) {
                return fail(fmt::format(
                    "the X-ray source comes within {:.1f} mm of the CT's far side for poses in the Transgraph range "
                    "(source at w = {:.1f} mm, front plane at {:.1f} mm); the source must stay outside the CT — check "
                    "the view geometry or narrow the range",
                    layout.back_w_mm - S.z(), S.z(), layout.front_w_mm));
              }
              for (int corner = 0; corner < 4; ++corner) {
                const Eigen::Vector2d uv((corner & 1) ? in.cols - 0.5 : -0.5, (corner & 2) ? in.rows - 0.5 : -0.5);
                const Eigen::Vector3d d = T_plane_from_world.linear() * (view.detectorPoint_world_mm(uv) - source_world_mm);
                if (d.z() < kMinDirectionCosine * d.norm()) {
                  return fail(fmt::format("detector corner ray ({}, {}) px runs nearly parallel to the Transgraph "
                                          "planes for poses in the range; narrow the range or check the view",
                                          uv.x(), uv.y()));
                }
                const double r = d.x() / d.z(), q = d.y() / d.z();
                const Eigen::Vector4d c(S.x() + (mid_w_mm - S.z()) * r, S.y() + (mid_w_mm - S.z()) * q,
                                        slab_mm * r, slab_mm * q);
                lo = lo.cwiseMin(c);
                hi = hi.cwiseMax(c);
              }
            }
          }
        }
      }
    }
  }

  double rays = 1.0;
  for (int a = 0; a < 4; ++a) {
    const double h = layout.step_mm[a];
    layout.min_mm[a] = lo[a] - h;
    const double n = std::ceil((hi[a] + h - layout.min_mm[a]) / h) + 1.0;
    rays *= n;
    layout.counts[a] = n < 2e9 ? static_cast<int>(n) : std::numeric_limits<int>::max();
  }
  if (rays > static_cast<double>(parameters.maxRays)) {
    const double scale = std::pow(rays / parameters.maxRays, 0.25);
    return fail(fmt::format("a Transgraph at {} mm spacing ({} mm offsets) for ±{} deg, ±{} mm would hold {:.0f} M rays "
                            "({:.1f} GB), more than the limit of {} M; use a spacing of about {:.1f} mm or a narrower "
                            "range",
                            layout.step_mm[0], layout.step_mm[2], parameters.range.rotation_deg,
                            parameters.range.translation_mm, rays / 1e6, rays * sizeof(float) / 1e9,
                            parameters.maxRays / 1'000'000, std::ceil(10.0 * layout.step_mm[0] * scale) / 10.0));
  }
  return layout;
}

Result<Transgraph> Transgraph::build(const Volume& ct, const Camera& view, const Eigen::Isometry3d& T_world_from_ct,
                                     const TransgraphParameters& parameters, RayIntegrator integrator,
                                     const ProgressMonitor& monitor) {
  if (!integrator) return fail("Transgraph build needs a ray integrator, got none");
  auto planned = plan(ct, view, T_world_from_ct, parameters);
  if (!planned) return fail(planned.error());
  const TransgraphLayout& layout = planned.value();
  const auto start = std::chrono::steady_clock::now();

  std::vector<float> table(layout.rayCount());
  // Named copies, not a structured binding: the lambda below captures them (clang 14 cannot capture bindings).
  const int n_s = layout.counts[0], n_t = layout.counts[1], n_ds = layout.counts[2], n_dt = layout.counts[3];
  const std::size_t rows = static_cast<std::size_t>(n_s) * n_t;
  const std::size_t raysPerRow = static_cast<std::size_t>(n_ds) * n_dt;
  std::atomic<std::size_t> rowsDone{0};
  std::mutex reportMutex;
  int lastPercent = -1;
  monitor.report("Transgraph", 0.0, fmt::format("filling {} rays", table.size()));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t row = range.begin(); row != range.end(); ++row) {
      if (monitor.cancelled()) return;
      const int is = static_cast<int>(row / n_t), it = static_cast<int>(row % n_t);
      float* out = table.data() + row * raysPerRow;
      for (int ids = 0; ids < n_ds; ++ids) {
        for (int idt = 0; idt < n_dt; ++idt) {
          const auto [front, back] = layout.rayEndpoints_ct_mm(is, it, ids, idt);
          *out++ = static_cast<float>(integrator(front, back));
        }
      }
      const std::size_t done = rowsDone.fetch_add(1, std::memory_order_relaxed) + 1;
      const int percent = static_cast<int>(100 * done / rows);
      std::unique_lock lock(reportMutex, std::try_to_lock);
      if (lock.owns_lock() && percent > lastPercent) {
        lastPercent = percent;
        monitor.report("Transgraph", static_cast<double>(done) / rows,
                       fmt::format("{} of {} rays", done * raysPerRow, table.size()));
      }
    }
  });
  if (monitor.cancelled()) return fail("Transgraph build cancelled");
  monitor.report("Transgraph", 1.0, fmt::format("filled {} rays", table.size()));

  TransgraphBuildInfo info;
  info.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fromTable(layout, std::move(table), std::move(integrator), info);
}

Result<Transgraph> Transgraph::fromTable(const TransgraphLayout& layout, std::vector<float> table,
                                         RayIntegrator integrator, TransgraphBuildInfo buildInfo) {
  if (!integrator) return fail("a Transgraph needs a ray integrator for rays outside its table, got none");
  for (int a = 0; a < 4; ++a) {
    if (layout.counts[a] < 2) {
      return fail(fmt::format("Transgraph layout needs at least 2 samples per axis, axis {} has {}", a,
                              layout.counts[a]));
    }
  }
  if (!(layout.step_mm.minCoeff() > 0.0) || !(layout.back_w_mm > layout.front_w_mm)) {
    return fail(fmt::format("Transgraph layout is degenerate (steps {} mm, planes at {} and {} mm)",
                            layout.step_mm.minCoeff(), layout.front_w_mm, layout.back_w_mm));
  }
  if (table.size() != layout.rayCount()) {
    return fail(fmt::format("Transgraph table holds {} values but its layout needs {}", table.size(),
                            layout.rayCount()));
  }
  Transgraph transgraph;
  transgraph.m_layout = layout;
  transgraph.m_table = std::move(table);
  transgraph.m_integrator = std::move(integrator);
  transgraph.m_buildInfo = std::move(buildInfo);
  return transgraph;
}

// Everything a render needs per pixel, precomputed once per (camera, pose, level): the source and the detector
// mapping in the plane frame, so that a pixel costs one 3x3 product, two divisions and 16 table reads.
struct Transgraph::PixelSampler {
  const Transgraph* transgraph = nullptr;
  int cols = 0;
  Eigen::Vector3d source_ct_mm;
  Eigen::Matrix3d R_ct_from_camera;
  Eigen::Vector3d source_plane_mm;
  Eigen::Matrix3d R_plane_from_camera;
  Eigen::Vector2d principalPoint_px, pixelSpacing_mm;
  double sourceToDetector_mm = 0.0;
  bool sourceInFront = false;

  Eigen::Vector3d detector_camera_mm(int col, int row) const {
    return {(col - principalPoint_px.x()) * pixelSpacing_mm.x(), (row - principalPoint_px.y()) * pixelSpacing_mm.y(),
            sourceToDetector_mm};
  }

  float value(int col, int row, std::size_t& fallbacks) const {
    const Eigen::Vector3d p_camera_mm = detector_camera_mm(col, row);
    if (sourceInFront) {
      const float v = transgraph->interpolate(source_plane_mm, R_plane_from_camera * p_camera_mm);
      if (!std::isnan(v)) return v;
    }
    ++fallbacks;
    return static_cast<float>(
        transgraph->m_integrator(source_ct_mm, source_ct_mm + R_ct_from_camera * p_camera_mm));
  }
};

float Transgraph::interpolate(const Eigen::Vector3d& source_plane_mm, const Eigen::Vector3d& direction_plane) const {
  const TransgraphLayout& L = m_layout;
  if (!(direction_plane.z() > kMinDirectionCosine * direction_plane.norm())) return std::nanf("");
  const double r = direction_plane.x() / direction_plane.z();
  const double q = direction_plane.y() / direction_plane.z();
  const double toMid = 0.5 * (L.front_w_mm + L.back_w_mm) - source_plane_mm.z();
  const double slab = L.back_w_mm - L.front_w_mm;
  const double coordinates[4] = {source_plane_mm.x() + toMid * r, source_plane_mm.y() + toMid * q, slab * r,
                                 slab * q};
  int index[4];
  double frac[4];
  for (int a = 0; a < 4; ++a) {
    const double g = (coordinates[a] - L.min_mm[a]) / L.step_mm[a];
    if (!(g >= 0.0 && g <= L.counts[a] - 1)) return std::nanf("");
    index[a] = std::min(static_cast<int>(g), L.counts[a] - 2);
    frac[a] = g - index[a];
  }
  const std::size_t stride3 = 1;
  const std::size_t stride2 = static_cast<std::size_t>(L.counts[3]);
  const std::size_t stride1 = stride2 * L.counts[2];
  const std::size_t stride0 = stride1 * L.counts[1];
  const float* base = m_table.data() + index[0] * stride0 + index[1] * stride1 + index[2] * stride2 + index[3];
  // Bilinear in (ds, dt) at each of the four (s, t) corners, then bilinear in (s, t).
  const auto directional = [&](const float* p) {
    const double a = p[0] + frac[3] * (p[stride3] - p[0]);
    const double b = p[stride2] + frac[3] * (p[stride2 + stride3] - p[stride2]);
    return a + frac[2] * (b - a);
  };
  const double v00 = directional(base), v01 = directional(base + stride1);
  const double v10 = directional(base + stride0), v11 = directional(base + stride0 + stride1);
  const double v0 = v00 + frac[1] * (v01 - v00), v1 = v10 + frac[1] * (v11 - v10);
  const double sum = v0 + frac[0] * (v1 - v0);
  return static_cast<float>(sum);
}

float Transgraph::integrate(const Eigen::Vector3d& source_ct_mm, const Eigen::Vector3d& end_ct_mm,
                            bool* usedFallback) const {
  const Eigen::Matrix3d R_plane_from_ct = m_layout.R_ct_from_plane.transpose();
  const Eigen::Vector3d source_plane_mm = R_plane_from_ct * (source_ct_mm - m_layout.origin_ct_mm);
  float v = std::nanf("");
  if (!m_table.empty() && source_plane_mm.z() < m_layout.front_w_mm) {
    v = interpolate(source_plane_mm, R_plane_from_ct * (end_ct_mm - source_ct_mm));
  }
  if (usedFallback) *usedFallback = std::isnan(v);
  if (std::isnan(v) && m_integrator) v = static_cast<float>(m_integrator(source_ct_mm, end_ct_mm));
  return v;
}

Transgraph::PixelSampler Transgraph::sampler(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct) const {
  const auto& in = levelCamera.intrinsics();
  PixelSampler s;
  s.transgraph = this;
  s.cols = in.cols;
  const Eigen::Isometry3d T_ct_from_camera = T_world_from_ct.inverse() * levelCamera.T_world_from_camera();
  s.source_ct_mm = T_ct_from_camera.translation();
  s.R_ct_from_camera = T_ct_from_camera.linear();
  const Eigen::Matrix3d R_plane_from_ct = m_layout.R_ct_from_plane.transpose();
  s.source_plane_mm = R_plane_from_ct * (s.source_ct_mm - m_layout.origin_ct_mm);
  s.R_plane_from_camera = R_plane_from_ct * s.R_ct_from_camera;
  s.principalPoint_px = in.principalPoint_px;
  s.pixelSpacing_mm = in.pixelSpacing_mm;
  s.sourceToDetector_mm = in.sourceToDetector_mm;
  s.sourceInFront = !m_table.empty() && s.source_plane_mm.z() < m_layout.front_w_mm;
  return s;
}

std::size_t Transgraph::integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                                        const std::int32_t* pixels, std::size_t count, float* values) const {
  const PixelSampler s = sampler(levelCamera, T_world_from_ct);
  std::atomic<std::size_t> fallbacks{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 256), [&](const tbb::blocked_range<std::size_t>& range) {
    std::size_t local = 0;
    for (std::size_t n = range.begin(); n != range.end(); ++n) {
      const std::int64_t index = pixels ? pixels[n] : static_cast<std::int64_t>(n);
      const int row = static_cast<int>(index / s.cols);
      const int col = static_cast<int>(index - static_cast<std::int64_t>(row) * s.cols);
      values[n] = s.value(col, row, local);
    }
    fallbacks.fetch_add(local, std::memory_order_relaxed);
  });
  return fallbacks.load();
}

}  // namespace fct
