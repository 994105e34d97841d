#pragma once
// CutFaceRayMask: a CT covers a slab of the patient, cut at its first and last slice; an X-ray shows the anatomy
// beyond those cut faces, the DRR does not. This mask marks the detector pixels whose rays the DRR can explain. The
// patient beyond a face is taken to continue the face's own cross-section: the footprint of an end slice is its
// tissue (above −500 HU) grown in-plane by the margin; a face with no tissue cuts nothing. A pixel is excluded when
// its ray, within the margin of an end face along k or beyond it, passes over that face's footprint. The footprints
// are made once (create); each mask then only walks the rays, only over the footprints' bounding boxes, and steps over
// the kBlock x kBlock voxel blocks that hold no footprint voxel in one jump.

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

#include "Base/Result.h"
#include "Drr/DrrVolume.h"
#include "Geometry/Camera.h"
#include "Image/ValidMask.h"

namespace fct {

/// The pixels whose rays stay clear of a CT's cut faces.
class CutFaceRayMask {
 public:
  /// The cut faces of `volume`'s CT with a margin of margin_mm (footprints of the end slices grown by it). Fails on a
  /// margin that is not finite and in 0..500 mm.
  static Result<CutFaceRayMask> create(const DrrVolume& volume, double margin_mm);

  /// Mask over `camera`'s detector: 1 = the ray stays clear of the cut faces of the CT at T_world_from_ct by at least
  /// the margin, 0 = it crosses the patient beyond them or passes near them.
  ValidMask compute(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct) const;

 private:
  /// Side of the square voxel blocks a ray steps over when they hold no footprint voxel.
  static constexpr int kBlock = 8;
  /// The grown footprint of one end slice, in voxel indices (i fastest), its bounding box (empty: iMax < iMin) and
  /// its kBlock x kBlock blocks (1: the block holds a footprint voxel; block (bi, bj) at bj * blockCols + bi).
  struct Face {
    std::vector<std::uint8_t> footprint;
    int iMin = 0, iMax = -1, jMin = 0, jMax = -1;
    std::vector<std::uint8_t> blocks;
    int blockCols = 0;
  };
  /// True when the ray a + t·d, t in [t0, t1] (ijk), passes over a pixel of `face` (sampled every half voxel).
  bool crosses(const Face& face, const Eigen::Vector3d& a, const Eigen::Vector3d& d, double t0, double t1) const;

  Eigen::Affine3d m_T_ijk_from_ct = Eigen::Affine3d::Identity();
  Eigen::Vector3i m_dims = Eigen::Vector3i::Zero();
  Eigen::Vector3d m_margin_ijk = Eigen::Vector3d::Zero();
  Face m_low, m_high;  ///< slice 0 and slice n-1
};

}  // namespace fct
