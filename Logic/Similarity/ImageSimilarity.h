#pragma once
// ImageSimilarity: the common interface of the similarity metrics between one view's X-ray (fixed, prepared once
// when the metric is created) and a DRR of the same size (evaluated for every pose). Higher is more similar; every
// metric is in [-1, 1] and invariant to a gain and offset of either image.

#include <string>

#include "Base/Result.h"
#include "Image/FloatImage.h"

namespace fct {

/// A similarity measure against a fixed X-ray.
class ImageSimilarity {
 public:
  virtual ~ImageSimilarity() = default;

  /// Similarity of `drr` (same size as the X-ray) to the X-ray, in [-1, 1]. Fails on a size mismatch or a DRR
  /// with non-finite values in the compared pixels.
  virtual Result<double> evaluate(const FloatImage& drr) const = 0;
  /// Short name for reports ("NCC", "VLNC", "GC").
  virtual std::string name() const = 0;
};

}  // namespace fct
