#pragma once
// PhantomBuilder: a procedural CT of a lumbar-spine region with realistic HU, for demos, tests and simulation.

#include <Eigen/Core>
#include <cstdint>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// Size and randomness of the built-in phantom.
struct PhantomOptions {
  Eigen::Vector3i dims{160, 160, 120};  ///< voxels along i (LPS x), j (LPS y), k (LPS z)
  double spacing_mm = 1.0;              ///< isotropic voxel size
  std::uint32_t seed = 7;               ///< drives trabecular texture, tissue variation and noise
};

/// Builds the phantom: air (-1000 HU) around an elliptic water-equivalent body (soft tissue ~5-35 HU) with a
/// subcutaneous fat layer (~-100 HU); three stacked lumbar-like vertebrae (body, pedicles, lamina, spinous,
/// transverse and articular processes, discs) and a tilted femur-like shaft on the patient's left. Bone has a
/// cortical shell (~1350-1750 HU) and trabecular cancellous bone (~200-400 HU); left/right, anterior/posterior and
/// superior/inferior features all differ, so no mirror or rotation maps the phantom onto itself.
/// Geometry: identity direction, centre of the grid at LPS (0,0,0); the anatomy is scaled to fill the field of view
/// (life size at the default 160 x 160 x 120 mm).
class PhantomBuilder {
 public:
  /// The phantom for the options; deterministic for a given seed. Fails for non-positive or huge dims or a
  /// non-positive or non-finite spacing.
  static Result<Volume> build(const PhantomOptions& options = {});
};

}  // namespace fct
