#pragma once
// ProjectionShiftAligner: moves a pose by the translation that best lines up each view's DRR with its X-ray in 2D.
// A start far from the truth (tens of mm) leaves the DRR and the X-ray barely overlapping, where a local search or a
// genetic search with a few mm of spread sees a flat similarity. The 2D shift of the DRR that maximizes its normalized
// cross-correlation with the X-ray, over every shift up to a fraction of the image, is found per view at a coarse level:
// the DRR is rendered on the detector grown by that fraction on every side, so that it shows what each shift brings
// into the field (a CT longer than the field fills the whole image, and a template of its own footprint could only be
// slid off the X-ray), and the X-ray (its invalid pixels set to its valid mean) is slid over it as the template
// (OpenCV matchTemplate, TM_CCOEFF_NORMED). The bone centre's projection moved by those shifts is then triangulated
// (Gauss-Newton over a 3D translation, damped so that one view keeps the depth). Rotation errors are left to the
// search that follows.

#include <Eigen/Geometry>

#include <vector>

#include "Base/Result.h"
#include "Registration/RegistrationCase.h"

namespace fct {

/// What the alignment found.
struct ShiftAlignment {
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();  ///< the moved pose (LPS mm)
  Eigen::Vector3d translation_world_mm = Eigen::Vector3d::Zero();     ///< added to the bone's position (LPS mm)
  std::vector<Eigen::Vector2d> shift_px;   ///< per view: the DRR's best 2D shift, full-resolution pixels (col, row)
  std::vector<double> peakCorrelation;     ///< per view: the normalized cross-correlation at that shift
};

/// Finds the translation that lines up the DRRs with the X-rays in 2D.
class ProjectionShiftAligner {
 public:
  /// The alignment of `registrationCase`'s views at pyramid `level` from the pose T_world_from_ct, searching shifts up to
  /// `maxShiftFraction` (0..1) of each image's width and height (the DRR rendered on a detector that much larger). Views whose peak correlation is below
  /// `minPeakCorrelation` do not vote; with no voting view the pose is returned unmoved. With `coarsening` k > 0 the
  /// images are matched at 2^k times the level's pixel size (the level's DRR renderer on a coarser detector, the X-ray
  /// halved k times): 4^k times fewer rays, for a rough alignment. Fails on a bad level, fraction or coarsening (0..3),
  /// or a rendering error (naming the view).
  static Result<ShiftAlignment> align(RegistrationCase& registrationCase, const Eigen::Isometry3d& T_world_from_ct,
                                      int level, double maxShiftFraction = 0.5, double minPeakCorrelation = 0.2,
                                      int coarsening = 0);
};

}  // namespace fct
