#pragma once
// NccSimilarity: normalized cross-correlation between the X-ray and the DRR over a pixel set P:
//     NCC = sum_P (x - mean x)(d - mean d) / sqrt(sum_P (x - mean x)^2 * sum_P (d - mean d)^2).
// 0 when either image is constant over P (defined, never NaN).

#include <cstddef>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Similarity/ImageSimilarity.h"

namespace fct {

/// NCC over a fixed pixel set of one view.
class NccSimilarity final : public ImageSimilarity {
 public:
  /// Prepares the X-ray side over `pixels` (linear indices into `xray`). Fails on an empty set or an index outside
  /// the image. A constant X-ray is accepted (with a warning): every evaluation then gives 0.
  static Result<NccSimilarity> create(const FloatImage& xray, PixelIndexList pixels);

  std::string name() const override { return "NCC"; }
  /// Number of compared pixels.
  std::size_t pixelCount() const { return m_pixels.size(); }

 private:
  NccSimilarity(int xrayCols, int xrayRows) : ImageSimilarity(xrayCols, xrayRows) {}
  double compare(const FloatImage& drr) const override;

  PixelIndexList m_pixels;
  std::vector<float> m_xrayCentred;  ///< X-ray values at m_pixels minus their mean
  double m_xrayNorm = 0.0;
};

}  // namespace fct
