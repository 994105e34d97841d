#pragma once
// StandardViews: the cameras of standard C-arm views around an isocentre, for simulation and demos.
// Angles: the C-arm rotates about the patient's superior axis (LPS +z); 0° is the AP view (source anterior,
// detector posterior, image columns toward the patient's left, rows toward the feet), 90° the left-lateral view
// (source on the patient's left). Oblique views are also tilted about the image's column axis (cranial for +tilt:
// the beam heads toward the patient's head), which gives the set out-of-plane diversity.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "IO/Project/ViewFile.h"

namespace fct {

/// Geometry of the simulated C-arm views.
struct StandardViewOptions {
  int count = 3;                         ///< number of views, 1..5: AP, lateral, oblique45, oblique30, oblique60
  double sourceToDetector_mm = 1500.0;   ///< SID
  double sourceToIsocentre_mm = 1000.0;  ///< SAD; must be below the SID
  int cols = 800;                        ///< detector width in pixels
  int rows = 600;                        ///< detector height in pixels
  double pixelSpacing_mm = 0.4;          ///< square detector pixel size
  double obliqueTilt_deg = 10.0;         ///< tilt of the oblique views (oblique30 gets the opposite sign)
};

/// One standard view: its name and its C-arm angles.
struct StandardViewAngles {
  std::string name;
  double rotation_deg = 0.0;  ///< about the patient's superior axis; 0 = AP, 90 = left lateral
  double tilt_deg = 0.0;      ///< cranial tilt about the image's column axis
};

/// Builds standard C-arm views.
class StandardViews {
 public:
  /// The first `count` (1..5) standard views' names and angles, in order: ap (0°), lateral (90°), oblique45 (45°),
  /// oblique30 (30°), oblique60 (60°); oblique45 and oblique60 tilted by +obliqueTilt_deg, oblique30 by -obliqueTilt_deg. Empty for a count outside 1..5.
  static std::vector<StandardViewAngles> angles(int count, double obliqueTilt_deg);

  /// Cameras of the standard views looking at isocentre_world_mm (LPS mm), without image paths. Fails on a count
  /// outside 1..5, SAD >= SID or non-positive distances, a non-positive detector size or pixel spacing, or
  /// non-finite numbers, naming the bad value.
  static Result<std::vector<ViewSpec>> build(const Eigen::Vector3d& isocentre_world_mm,
                                             const StandardViewOptions& options = {});
};

}  // namespace fct
