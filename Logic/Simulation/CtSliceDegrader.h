#pragma once
// CtSliceDegrader: makes the lower-quality CT a registration would get from a clinical scan with thick slices. The
// original CT is taken as what its voxels are — boxes of one spacing around their centres — and covers the slab
// [−s/2, (n − ½)·s] along its slice axis (k), s its slice spacing and n its slice count. The degraded CT covers
// exactly that slab with m = round(n·s / Δh) slices at spacing n·s / m (within Δh / (2m) of the asked Δh); each new
// slice is the mean of the original over a box slice profile of the asked thickness Δh centred on it (the exact
// overlap of the profile with every original slice box), and the part of a profile beyond the original's end faces
// sees air (−1000 HU). The paper's scenarios: "realistic" Δh = 2.4 mm, "bad" Δh = 4.2 mm.

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// Thick-slice degradation of a CT.
class CtSliceDegrader {
 public:
  /// HU of the air beyond the original CT's end faces.
  static constexpr float kAir_hu = -1000.0f;

  /// The CT resampled along k to about `sliceThickness_mm` (see the file comment: the same slab, same in-plane grid,
  /// direction and i/j origin; the origin moves along k to the first new slice's centre). Fails on an empty CT or a
  /// thickness that is not finite and positive or is below the current slice spacing.
  static Result<Volume> degrade(const Volume& ct, double sliceThickness_mm);
};

}  // namespace fct
