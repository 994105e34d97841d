#pragma once
// MetalMaskReview: a second look at an X-ray's metal mask once the pose is roughly known. The metal detector
// (MetalMaskDetector) judges shapes in the X-ray alone, and some anatomy has a wire's shape: on a head seen AP at fine
// pixels, a dense midline strip below the skull base is a long, straight, two-sided ridge. The CT holds that anatomy
// and no tool, so a DRR at a pose near the truth explains the ridge and not a tool. For each connected piece of the
// mask, the review takes the residual X-ray - DRR (the DRR brought to the X-ray's scale: times the median ratio X-ray /
// DRR over the field's pixels outside the metal where the DRR is above a quarter of its largest value) at the piece's
// core pixels (those standing more than half the detector's minExcess above the X-ray around the piece) and compares it
// with the residual around the piece (a ring of kRing_mm). Metal raises the residual by its own line integral, at least
// about minExcess; anatomy seen near its pose leaves it near the surroundings'. Core pixels whose residual stands more
// than half of minExcess out are unexplained; a piece with a patch of them at least kMinUnexplainedWidth_mm thick and
// kMinUnexplained_mm2 large stays excluded whole (a tool, also when the detector's growth joined it to a bone rim), a
// piece without one is given back to the comparison. Only pixels the CT covers are judged (the DRR is empty beyond the
// CT's end faces while the X-ray shows the patient on); a piece mostly beyond them, or without a core there, stays
// excluded.

#include <cstddef>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"
#include "XrayPrep/MetalMaskDetector.h"

namespace fct {

/// What a review kept and gave back.
struct MetalMaskReviewOutcome {
  ValidMask mask;                   ///< the reviewed mask: the X-ray's, with what the DRR explains valid again
  std::size_t metalPixelCount = 0;  ///< field pixels still excluded as metal
  int piecesKept = 0;       ///< metal pieces (8-connected) that stay excluded
  int piecesGivenBack = 0;  ///< metal pieces given back to the comparison as anatomy
};

/// Reviews an X-ray's metal mask against a DRR of the CT at a pose near the truth.
class MetalMaskReview {
 public:
  /// A pixel is covered by the CT where it is valid in the covered mask and the DRR (at the X-ray's scale) is above
  /// this line integral (a few mm of soft tissue).
  static constexpr float kCoveredLineIntegral = 0.1f;
  /// Fraction of a piece's pixels the CT must cover for the review to judge it.
  static constexpr double kMinCovered = 0.25;
  /// Width of the ring around a piece that gives the surroundings' level, mm on the detector.
  static constexpr double kRing_mm = 3.0;
  /// Smallest patch of unexplained core pixels that keeps its part of a piece, mm^2 on the detector (a misaligned
  /// bone edge leaves slivers of residual, a tool a patch of its own size).
  static constexpr double kMinUnexplained_mm2 = 4.0;
  /// Unexplained pixels count only where they are at least this thick, mm on the detector (a wire's shadow is 2-4 mm).
  static constexpr double kMinUnexplainedWidth_mm = 1.5;

  /// A review with the detector settings the X-ray's mask was made with (minExcess sets the scale of "stands out").
  explicit MetalMaskReview(MetalMaskOptions options = {}) : m_options(options) {}

  /// `fieldMask`: the X-ray's valid pixels before the metal exclusion; `xrayMask`: after it (a subset);
  /// `xrayLineIntegrals`: the X-ray (p = -ln(I/I0)); `drrLineIntegrals`: the DRR (dimensionless line integrals) of the
  /// same detector at a pose near the truth; `coveredMask`: the pixels whose rays cross no patient beyond the CT's cut
  /// faces (CutFaceRayMask; all valid when unknown); `pixelSpacing_mm`: the detector pixel size (0 = unknown: the
  /// options' assumed spacing). Fails on size mismatches or an `xrayMask` valid where `fieldMask` is not.
  Result<MetalMaskReviewOutcome> review(const ValidMask& fieldMask, const ValidMask& xrayMask,
                                        const FloatImage& xrayLineIntegrals, const FloatImage& drrLineIntegrals,
                                        const ValidMask& coveredMask, double pixelSpacing_mm) const;

 private:
  MetalMaskOptions m_options;
};

}  // namespace fct
