#pragma once
// CutFaceRayMask: a CT covers a slab of the patient, cut at its first and last slice; an X-ray shows the anatomy
// beyond those cut faces, the DRR does not. This mask marks the detector pixels whose rays the DRR can explain. The
// patient beyond a face is taken to continue the face's own cross-section: the footprint of an end slice is its
// tissue (above −500 HU) grown in-plane by the margin; a face with no tissue cuts nothing. A pixel is excluded when
// its ray, within the margin of an end face along k or beyond it, passes over that face's footprint.

#include <Eigen/Geometry>

#include "Base/Result.h"
#include "Drr/DrrVolume.h"
#include "Geometry/Camera.h"
#include "Image/ValidMask.h"

namespace fct {

/// The pixels whose rays stay clear of a CT's cut faces.
class CutFaceRayMask {
 public:
  /// Mask over `camera`'s detector (1 = the ray stays clear of the cut faces of `volume`'s CT at T_world_from_ct by at
  /// least margin_mm, 0 = it crosses the patient beyond them or passes near them). Fails on a margin that is not
  /// finite and in 0..500 mm.
  static Result<ValidMask> compute(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                                   const DrrVolume& volume, double margin_mm);
};

}  // namespace fct
