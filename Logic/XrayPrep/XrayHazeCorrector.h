#pragma once
// XrayHazeCorrector: removes a smooth additive haze (scatter, veiling glare) and a smooth gain from an X-ray once a DRR
// of the CT at a pose near the truth is known. In the log domain a haze is not an offset: it compresses the dark
// pixels (behind dense bone) toward -ln(haze), and a local NCC then pulls edges there toward the bright side.
//
// Model, in the X-ray's relative intensities I = exp(-p) (p: its line integrals):
//     I(u) = g(u) exp(-h(d(u) - dmin)) + s(u),   h(x) = c x / (1 + b x),
// d the DRR's line integrals and dmin their smallest valid value. h is the view's beam-hardening curve: c scales the
// DRR's attenuation to the X-ray's (the CT's calibration and the beam's mean energy), b >= 0 lets the effective
// attenuation fall as the beam hardens along thick rays (a polychromatic beam is not one exponential of the line
// integral). c and b come from a global least-squares fit I ~ g0 exp(-h(d - dmin)) + s0(u), s0 a quadratic surface
// over the detector, on an even subsample of the valid pixels: a grid over c (log-spaced, kMinFactor..kMaxFactor)
// and b (b (dmax - dmin) in 0..kMaxHardening), refined by coordinate descent. g(u), s(u) are smooth: a
// Gaussian-weighted local linear regression of I on exp(-h) (Gaussian sigma `sigma_px`, normalized over the valid
// pixels), with g pulled toward the global g0 where exp(-h) hardly varies (ridge weight kRidge times its median local
// variance). The corrected X-ray (I - s) / g is taken back to line integrals by XrayIntensityModel (its reference
// level and floor) and through h's inverse to the DRR's scale, so that a local NCC compares two images that differ
// only by noise and what the CT lacks.
// The haze and gain are smooth, so the fit needs the DRR near the truth only to within their smoothness, not to within
// the registration's accuracy (docs/evaluation.md, "Haze removal").

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// A corrected X-ray and the fit that made it.
struct HazeCorrection {
  FloatImage lineIntegrals;           ///< the X-ray with the haze and gain removed, on the DRR's scale, >= 0
  double attenuationFactor = 1.0;     ///< c of the model (DRR line integrals to the X-ray's, on thin rays)
  double hardening = 0.0;             ///< b (dmax - dmin): how much the attenuation falls over the view's range, >= 0
  double globalGain = 0.0;            ///< g0 of the global fit
  double meanHazeFraction = 0.0;      ///< mean of |s| / I over the valid pixels: the share of the signal changed
};

/// Removes a smooth additive haze from an X-ray given a DRR near the truth.
class XrayHazeCorrector {
 public:
  /// Attenuation factors c searched: kFactorGrid log-spaced values from kMinFactor to kMaxFactor.
  static constexpr double kMinFactor = 0.25;
  static constexpr double kMaxFactor = 8.0;
  static constexpr int kFactorGrid = 36;
  /// Hardening searched: b (dmax - dmin) in kHardeningGrid steps from 0 to kMaxHardening.
  static constexpr double kMaxHardening = 1.5;
  static constexpr int kHardeningGrid = 16;
  /// Weight of the pull of the local gain toward the global one, times the median local variance of the DRR term.
  static constexpr double kRidge = 0.1;

  /// `xrayLineIntegrals`: the X-ray (p = -ln(I/I0)); `drrLineIntegrals`: the DRR of the same detector at a pose near
  /// the truth; `mask`: the pixels to fit on (field, no metal, clear of the CT's cut faces); `sigma_px`: the haze's
  /// smoothness (Gaussian sigma, pixels). Fails on size mismatches, sigma_px <= 0, fewer than 100 valid pixels, a DRR
  /// without contrast over them, a fit whose gain is not positive (the DRR does not explain the X-ray: the pose
  /// is far off), or an attenuation factor at the edge of the searched range.
  static Result<HazeCorrection> correct(const FloatImage& xrayLineIntegrals, const FloatImage& drrLineIntegrals,
                                        const ValidMask& mask, double sigma_px);
};

}  // namespace fct
