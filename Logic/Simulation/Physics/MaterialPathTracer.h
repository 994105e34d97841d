#pragma once
// MaterialPathTracer: the fluoroscopy simulator's own CT traversal, independent of the registration's DRR path.
// Walks a ray through the ORIGINAL CT voxels (each voxel the box of one spacing around its centre) with the
// voxel-stepping algorithm of J. Amanatides and A. Woo ("A fast voxel traversal algorithm for ray tracing",
// Eurographics 1987), taking the exact length of the ray inside every voxel it crosses, and accumulates in one pass
// the mass per area of every material (HuMaterialModel): Σ ρ_m(HU_v) · L_v. No interpolation, no resampling.

#include <Eigen/Geometry>

#include "Base/Result.h"
#include "Image/Volume.h"
#include "Simulation/Physics/HuMaterialModel.h"

namespace fct {

/// Exact per-material path integrals through a CT.
class MaterialPathTracer {
 public:
  /// A tracer over `ct` (HU), which must outlive it. Fails on an empty volume, non-finite voxels or a bad model.
  static Result<MaterialPathTracer> create(const Volume& ct, const HuMaterialModel& model);

  /// Mass per area in g/cm² per material along the ray from `origin_ct_mm` (CT LPS mm) in the unit direction
  /// `direction_ct`, over the part of the ray at t >= 0 inside the CT's voxel boxes; all zero if it misses.
  MassPaths trace(const Eigen::Vector3d& origin_ct_mm, const Eigen::Vector3d& direction_ct) const;

 private:
  const Volume* m_ct = nullptr;
  HuMaterialModel m_model;
  Eigen::Affine3d m_T_ijk_from_ct = Eigen::Affine3d::Identity();
};

}  // namespace fct
