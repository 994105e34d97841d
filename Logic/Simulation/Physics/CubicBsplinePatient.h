#pragma once
// CubicBsplinePatient: the fluoroscopy simulator's continuous patient. The CT's samples (HU at the voxel centres) are
// turned into the coefficients of the cubic B-spline that interpolates them (the recursive prefilter of M. Unser,
// "Splines: a perfect fit for signal and image processing", IEEE Signal Processing Magazine 16(6), 1999, with
// mirror-symmetric boundaries), so the patient is a C² function of position with no voxel edges. Along the slice axis
// the patient continues `extension_mm` beyond each end face of the CT as the mirror image of its end slab (a patient
// is longer than the slab that was scanned); in-plane it ends at the CT's box faces. A ray is integrated by the
// midpoint rule at a step of half the smallest voxel spacing, the HU at each sample split into materials
// (HuMaterialModel). Shares no grid, DRR or interpolation code with registration.

#include <Eigen/Geometry>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"
#include "Simulation/Physics/HuMaterialModel.h"

namespace fct {

/// A CT as a continuous, optionally lengthened patient for the physical simulator.
class CubicBsplinePatient {
 public:
  /// The interpolant of `ct` (HU; copied, so `ct` need not outlive it), continued `extension_mm` (0..1000) beyond
  /// both end faces along k. Fails on an empty CT, non-finite voxels, a bad model or a bad extension.
  static Result<CubicBsplinePatient> create(const Volume& ct, const HuMaterialModel& model, double extension_mm);

  /// HU of the patient at p_ct_mm (CT LPS mm); air (−1000) outside the patient's box.
  double value_hu(const Eigen::Vector3d& p_ct_mm) const;

  /// Mass per area in g/cm² per material along the ray from `origin_ct_mm` (CT LPS mm) in the unit direction
  /// `direction_ct`, over the part of the ray at t >= 0 inside the patient's box; all zero if it misses.
  MassPaths trace(const Eigen::Vector3d& origin_ct_mm, const Eigen::Vector3d& direction_ct) const;

  /// The integration step along a ray, in mm.
  double step_mm() const { return m_step_mm; }

 private:
  /// The interpolant at continuous voxel index `ijk` (mirror-continued coefficients beyond the grid).
  double valueAtIjk(const Eigen::Vector3d& ijk) const;

  std::vector<float> m_coefficients;
  Eigen::Vector3i m_dims = Eigen::Vector3i::Zero();
  Eigen::Vector3d m_boxLow_ijk = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_boxHigh_ijk = Eigen::Vector3d::Zero();
  Eigen::Affine3d m_T_ijk_from_ct = Eigen::Affine3d::Identity();
  HuMaterialModel m_model;
  double m_step_mm = 1.0;
};

}  // namespace fct
