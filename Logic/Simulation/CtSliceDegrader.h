#pragma once
// CtSliceDegrader: makes the lower-quality CT a registration would get from a clinical scan with thick slices: the
// CT is resampled along its slice axis (k) to spacing Δh, each new slice being the mean of the (linearly
// interpolated) original over a box of width Δh around it — the slice-sensitivity profile of a contiguous
// acquisition with slice thickness = spacing. The paper's scenarios: "realistic" Δh = 2.4 mm, "bad" Δh = 4.2 mm.

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// Thick-slice degradation of a CT.
class CtSliceDegrader {
 public:
  /// The CT resampled to `sliceSpacing_mm` along k with a box slice profile of that width. Voxel (i,j,0) keeps its
  /// position (same origin, direction, in-plane spacing); the new slice count is floor((n − 1) · s / Δh) + 1, so the
  /// covered extent shrinks by less than Δh. Fails on an empty CT or a spacing that is not finite and positive or is
  /// below the current slice spacing.
  static Result<Volume> degrade(const Volume& ct, double sliceSpacing_mm);
};

}  // namespace fct
