#pragma once
// VlncSimilarity: variance-weighted local NCC (Knaan & Joskowicz 2003). Over windows W (e.g. the dynamic ROIs):
//     VLNC = sum_w  omega_w * NCC_w,     omega_w = var_x(w) / sum_v var_x(v),
// NCC_w the NCC of X-ray and DRR over the pixels of window w, var_x(w) the population variance of the X-ray in w.
// Windows where the X-ray is constant have weight 0 and are skipped; a window where the DRR is constant has
// NCC_w = 0. VLNC is in [-1, 1] and invariant to a gain and offset of either image (and to a different offset per
// window). If every window's X-ray is constant, VLNC is 0 for every DRR.
//
// The weights may instead come from another image of the same detector (`weightSource`): var_x(w) is then that
// image's variance in w. A noise-free DRR near the truth gives each window the structure the CT predicts there, where
// an X-ray's own variance also counts its noise, and a haze-corrected X-ray's dark windows carry much amplified noise
// (docs/evaluation.md, "Window weights").
//
// Both images are line integrals p (the DRR's sense). VLNC compares them as they are (the paper's: each window is
// also invariant to a contrast scale, a first-order beam hardening), or as detector intensities exp(-p): each window
// is then invariant to an added constant (a scatter haze, which in the line-integral sense bends dark windows'
// edges), and the weights, variances of intensities, favour the bright windows, which have the most photons.

#include <cstddef>
#include <vector>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Similarity/DynamicRoiSelector.h"
#include "Similarity/ImageSimilarity.h"

namespace fct {

/// The values VLNC compares.
enum class VlncDomain {
  LineIntegral,  ///< the line integrals p = -ln(I / I0) (the paper's)
  Intensity,     ///< the detector intensities exp(-p), relative to I0
};

/// VLNC over fixed windows of one view.
class VlncSimilarity final : public ImageSimilarity {
 public:
  /// Prepares the X-ray side (line integrals) over the windows of `selection` (their position and size; weights are
  /// recomputed in `domain` from `weightSource`, line integrals of the same size, or from `xray` when it is null).
  /// Windows constant in the X-ray or the weight source weigh nothing. Fails on no window, a window not inside the
  /// image, or a weight source of another size or with non-finite values in a window. All-constant windows give a
  /// warning.
  static Result<VlncSimilarity> create(const FloatImage& xray, const RoiSelection& selection,
                                       VlncDomain domain = VlncDomain::LineIntegral,
                                       const FloatImage* weightSource = nullptr);

  std::string name() const override { return "VLNC"; }
  /// Number of windows with a nonzero weight.
  std::size_t windowCount() const { return m_weights.size(); }

 private:
  VlncSimilarity(int xrayCols, int xrayRows) : ImageSimilarity(xrayCols, xrayRows) {}
  double compare(const FloatImage& drr) const override;

  VlncDomain m_domain = VlncDomain::LineIntegral;
  std::size_t m_windowPixels = 0;    ///< w*w
  PixelIndexList m_pixels;           ///< window by window, m_windowPixels each
  std::vector<float> m_xrayCentred;  ///< X-ray values (in m_domain) minus their window's mean, same layout
  std::vector<double> m_xrayNorms;   ///< per window
  std::vector<double> m_weights;     ///< per window, summing to 1
};

}  // namespace fct
