#pragma once
// GradientCorrelationSimilarity: gradient correlation (Penney et al., IEEE TMI 1998) over a pixel set P:
//     GC = (NCC_P(Gx x, Gx d) + NCC_P(Gy x, Gy d)) / 2,
// Gx, Gy the 3x3 Sobel derivatives along columns and rows of the X-ray x and the DRR d. Pixels on the image border
// (no full 3x3 neighbourhood) are left out of P. In [-1, 1], invariant to gain and offset; a direction in which
// either image has a constant gradient contributes 0.

#include <cstddef>
#include <vector>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Similarity/ImageSimilarity.h"

namespace fct {

/// Gradient correlation over a fixed pixel set of one view.
class GradientCorrelationSimilarity final : public ImageSimilarity {
 public:
  /// Prepares the X-ray gradients over `pixels` (linear indices into `xray`). Fails on an index outside the image or
  /// when no pixel with a full 3x3 neighbourhood remains.
  static Result<GradientCorrelationSimilarity> create(const FloatImage& xray, const PixelIndexList& pixels);

  std::string name() const override { return "GC"; }
  /// Number of compared pixels (border pixels left out).
  std::size_t pixelCount() const { return m_pixels.size(); }

 private:
  GradientCorrelationSimilarity(int xrayCols, int xrayRows) : ImageSimilarity(xrayCols, xrayRows) {}
  double compare(const FloatImage& drr) const override;

  PixelIndexList m_pixels;
  std::vector<float> m_gxCentred;  ///< X-ray Sobel x-gradient at m_pixels minus its mean
  std::vector<float> m_gyCentred;
  double m_gxNorm = 0.0;
  double m_gyNorm = 0.0;
};

}  // namespace fct
