#pragma once
// SetupPose: an initial bone pose from the clinical setup instead of landmarks. "Supine at the isocentre": the
// patient lies as in the CT (CT LPS axes = world LPS axes, as StandardViews assume) and the CT point of interest
// (e.g. the bone centroid) sits at the C-arm isocentre, the point closest to every view's principal ray.

#include <Eigen/Geometry>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"

namespace fct {

/// Initial poses from the clinical setup.
class SetupPose {
 public:
  /// With one view the isocentre is taken on its principal ray at this fraction of the source-to-detector distance
  /// (typical C-arms: source-to-isocentre / source-to-detector = 0.6-0.7).
  static constexpr double kSingleViewIsocentreFraction = 2.0 / 3.0;

  /// The C-arm isocentre in world LPS mm: the least-squares point closest to the views' principal rays (source to
  /// principal point); with one view, or principal rays all within 1 degree of parallel, the point on the first ray
  /// at kSingleViewIsocentreFraction of its source-to-detector distance. Fails on no camera.
  static Result<Eigen::Vector3d> isocentre_world_mm(const std::vector<Camera>& cameras);

  /// T_world_from_ct of the supine setup: identity rotation (CT LPS = world LPS) and centre_ct_mm moved to the
  /// isocentre of `cameras`. Fails on no camera or a non-finite centre.
  static Result<Eigen::Isometry3d> supineAtIsocentre(const Eigen::Vector3d& centre_ct_mm,
                                                     const std::vector<Camera>& cameras);
};

}  // namespace fct
