#pragma once
// Analytic phantoms for the DRR tests: solids of known value voxelized with supersampled partial volumes,
// their exact chord lengths, and the cameras that look at them.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include "Drr/DrrVolume.h"
#include "Geometry/Camera.h"
#include "Image/Volume.h"

namespace fct::test {

/// A solid described in the CT frame (mm) by an inside test and an exact chord length along a line.
struct AnalyticSolid {
  std::function<bool(const Eigen::Vector3d& p_ct_mm)> inside;
  /// Length in mm of the line p + s·u (u unit) inside the solid, and the smallest normalized "depth" of the line
  /// (0 through the centre, 1 grazing), used to select rays through the interior.
  std::function<double(const Eigen::Vector3d& p_ct_mm, const Eigen::Vector3d& u, double* grazing)> chord_mm;
};

/// An ellipsoid with semi-axes `radii_mm` along the columns of R, centred at c_ct_mm (a ball when the radii are equal).
inline AnalyticSolid ellipsoid(const Eigen::Vector3d& c_ct_mm, const Eigen::Vector3d& radii_mm,
                               const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  const Eigen::Matrix3d toUnit = radii_mm.cwiseInverse().asDiagonal() * R.transpose();
  AnalyticSolid solid;
  solid.inside = [=](const Eigen::Vector3d& p) { return (toUnit * (p - c_ct_mm)).squaredNorm() <= 1.0; };
  solid.chord_mm = [=](const Eigen::Vector3d& p, const Eigen::Vector3d& u, double* grazing) {
    const Eigen::Vector3d y0 = toUnit * (p - c_ct_mm);
    const Eigen::Vector3d dy = toUnit * u;
    const double a = dy.squaredNorm(), b = y0.dot(dy), c = y0.squaredNorm() - 1.0;
    const double closest = (y0 - (b / a) * dy).norm();
    *grazing = closest;
    const double disc = b * b - a * c;
    return disc <= 0.0 ? 0.0 : 2.0 * std::sqrt(disc) / a;
  };
  return solid;
}

/// An axis-aligned box [lo, hi] in the CT frame (mm); `grazing` is 1 - (distance of the entry/exit points from the
/// nearest box edge) / 1.5 mm, so values <= 0 mean both crossings are at least 1.5 mm from every edge.
inline AnalyticSolid box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  AnalyticSolid solid;
  solid.inside = [=](const Eigen::Vector3d& p) { return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all(); };
  solid.chord_mm = [=](const Eigen::Vector3d& p, const Eigen::Vector3d& u, double* grazing) {
    double t0 = -1e9, t1 = 1e9;
    for (int a = 0; a < 3; ++a) {
      if (u[a] == 0.0) continue;
      double tn = (lo[a] - p[a]) / u[a], tf = (hi[a] - p[a]) / u[a];
      if (tn > tf) std::swap(tn, tf);
      t0 = std::max(t0, tn);
      t1 = std::min(t1, tf);
    }
    if (t1 <= t0) {
      *grazing = 2.0;
      return 0.0;
    }
    double edgeDistance = 1e9;
    for (const double t : {t0, t1}) {
      const Eigen::Vector3d q = p + t * u;
      // Distance to the nearest edge: second-smallest distance to a face plane.
      Eigen::Vector3d faceDistance = (q - lo).cwiseAbs().cwiseMin((hi - q).cwiseAbs());
      std::sort(faceDistance.data(), faceDistance.data() + 3);
      edgeDistance = std::min(edgeDistance, faceDistance[1]);
    }
    *grazing = 1.0 - edgeDistance / 1.5;
    return t1 - t0;
  };
  return solid;
}

/// Voxelizes `solid` with value `value` into `ct` (raw values): voxels wholly inside or outside by their corners get
/// value or 0, boundary voxels the fraction of 8^3 sub-samples inside.
inline void voxelize(const AnalyticSolid& solid, float value, Volume& ct) {
  const Eigen::Vector3i n = ct.dims();
  constexpr int kSub = 8;
  for (int k = 0; k < n.z(); ++k)
    for (int j = 0; j < n.y(); ++j)
      for (int i = 0; i < n.x(); ++i) {
        int corners = 0;
        for (int c = 0; c < 8; ++c) {
          const Eigen::Vector3d ijk(i + ((c & 1) ? 0.5 : -0.5), j + ((c & 2) ? 0.5 : -0.5), k + ((c & 4) ? 0.5 : -0.5));
          corners += solid.inside(ct.lpsFromIjk(ijk)) ? 1 : 0;
        }
        // Convex solids: all corners inside means the voxel is inside. With no corner inside, the solid can still poke
        // a cap through a face near its extreme points; for these radii (> 10 voxels) such caps are < 0.02 voxel thick.
        if (corners == 8) {
          ct.at(i, j, k) = value;
          continue;
        }
        if (corners == 0) {
          ct.at(i, j, k) = 0.0f;
          continue;
        }
        int count = 0;
        for (int c = 0; c < kSub; ++c)
          for (int b = 0; b < kSub; ++b)
            for (int a = 0; a < kSub; ++a) {
              const Eigen::Vector3d ijk(i - 0.5 + (a + 0.5) / kSub, j - 0.5 + (b + 0.5) / kSub, k - 0.5 + (c + 0.5) / kSub);
              count += solid.inside(ct.lpsFromIjk(ijk)) ? 1 : 0;
            }
        ct.at(i, j, k) = value * static_cast<float>(count) / (kSub * kSub * kSub);
      }
}

/// A 64^3 CT with slightly anisotropic voxels centred at the origin of the CT frame, all zeros.
inline Volume emptyPhantomCt(const Eigen::Matrix3d& direction = Eigen::Matrix3d::Identity()) {
  const Eigen::Vector3i dims(64, 64, 64);
  const Eigen::Vector3d spacing_mm(1.0, 0.9, 1.1);
  Volume ct = Volume::create(dims, spacing_mm, Eigen::Vector3d::Zero(), direction).value();
  const Eigen::Vector3d offset = ct.centre_lps_mm();
  return Volume::create(dims, spacing_mm, -offset, direction).value();
}

/// The raw-value DrrVolume of a CT.
inline std::shared_ptr<const DrrVolume> rawDrrVolume(const Volume& ct) {
  DrrValueOptions options;
  options.kind = DrrValueKind::Raw;
  return std::make_shared<const DrrVolume>(DrrVolume::create(ct, options).value());
}

/// A C-arm view of the world origin from direction R (source 600 mm from the isocentre, SID 1000 mm).
inline Camera phantomCamera(const Eigen::Matrix3d& R_world_from_camera, int cols = 96, int rows = 80,
                            double pixelSpacing_mm = 1.2) {
  return Camera::lookingAt(Eigen::Vector3d::Zero(), R_world_from_camera, 600.0, 1000.0, cols, rows, pixelSpacing_mm);
}

/// A fixed oblique camera orientation.
inline Eigen::Matrix3d obliqueRotation() {
  return (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(-0.35, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

}  // namespace fct::test
