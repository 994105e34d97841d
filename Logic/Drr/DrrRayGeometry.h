#pragma once
// DrrRayGeometry: the rays of one DRR render expressed in the CT voxel index frame, so that ray casters
// transform nothing per sample. Built once per render from the (level) camera, the pose and the volume.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "Geometry/Camera.h"

namespace fct {

/// Source and detector pixel positions of a camera in continuous voxel index coordinates (ijk) of a volume.
class DrrRayGeometry {
 public:
  /// Rays of `camera` for a CT at pose T_world_from_ct, in the index frame given by T_ijk_from_ct (CT mm -> ijk).
  DrrRayGeometry(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct, const Eigen::Affine3d& T_ijk_from_ct);

  /// Detector width and height in pixels.
  int cols() const { return m_cols; }
  int rows() const { return m_rows; }
  /// X-ray source in ijk.
  const Eigen::Vector3d& source_ijk() const { return m_source_ijk; }
  /// Centre of detector pixel (col,row) in ijk.
  Eigen::Vector3d detectorPoint_ijk(int col, int row) const {
    return m_detector00_ijk + static_cast<double>(col) * m_colStep_ijk + static_cast<double>(row) * m_rowStep_ijk;
  }
  /// Source-to-pixel distance in mm (the physical length of the segment source -> detectorPoint_ijk(col,row)).
  double rayLength_mm(int col, int row) const {
    const double x = (col - m_principalPoint_px.x()) * m_pixelSpacing_mm.x();
    const double y = (row - m_principalPoint_px.y()) * m_pixelSpacing_mm.y();
    return std::sqrt(x * x + y * y + m_sourceToDetector_mm * m_sourceToDetector_mm);
  }

  /// Clips the segment a + t·d, t in [t0, t1], to the box [boxMin, boxMax] (slab method). Returns false (and leaves
  /// t0 >= t1) when the segment misses the box; axes with d = 0 are tested against the slab directly.
  static bool clipToBox(const Eigen::Vector3d& a, const Eigen::Vector3d& d, const Eigen::Vector3d& boxMin,
                        const Eigen::Vector3d& boxMax, double& t0, double& t1) {
    for (int axis = 0; axis < 3; ++axis) {
      if (d[axis] == 0.0) {
        if (a[axis] < boxMin[axis] || a[axis] > boxMax[axis]) return false;
        continue;
      }
      const double inv = 1.0 / d[axis];
      double tNear = (boxMin[axis] - a[axis]) * inv;
      double tFar = (boxMax[axis] - a[axis]) * inv;
      if (tNear > tFar) std::swap(tNear, tFar);
      t0 = std::max(t0, tNear);
      t1 = std::min(t1, tFar);
    }
    return t0 < t1;
  }

  /// Computes values[n] = integrate(source_ijk, detectorPoint_ijk, rayLength_mm) for pixel pixels[n] (linear index
  /// row*cols+col) or, when `pixels` is null, for pixel n, n < count; indices must be valid. Parallel over chunks of
  /// pixels with oneTBB; each value depends only on its pixel, so the result is the same for any thread count.
  template <typename IntegrateFn>
  void integratePixels(const std::int32_t* pixels, std::size_t count, float* values, const IntegrateFn& integrate) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 256), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t n = range.begin(); n != range.end(); ++n) {
        const std::int64_t index = pixels ? pixels[n] : static_cast<std::int64_t>(n);
        const int row = static_cast<int>(index / m_cols);
        const int col = static_cast<int>(index - static_cast<std::int64_t>(row) * m_cols);
        values[n] = static_cast<float>(integrate(m_source_ijk, detectorPoint_ijk(col, row), rayLength_mm(col, row)));
      }
    });
  }

 private:
  int m_cols = 0;
  int m_rows = 0;
  Eigen::Vector3d m_source_ijk;
  Eigen::Vector3d m_detector00_ijk;
  Eigen::Vector3d m_colStep_ijk;
  Eigen::Vector3d m_rowStep_ijk;
  Eigen::Vector2d m_principalPoint_px;
  Eigen::Vector2d m_pixelSpacing_mm;
  double m_sourceToDetector_mm = 0.0;
};

}  // namespace fct
