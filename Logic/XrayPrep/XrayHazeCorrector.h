#pragma once
// XrayHazeCorrector: removes a smooth additive haze (scatter, veiling glare) and a smooth gain from an X-ray once a DRR
// of the CT at a pose near the truth is known. In the log domain a haze is not an offset: it compresses the dark
// pixels (behind dense bone) toward -ln(haze), and a local NCC then pulls edges there toward the bright side.
//
// Model, in the X-ray's relative intensities I = exp(-p) (p: its line integrals):
//     I(u) = g(u) exp(-c (d(u) - dmin)) + s(u),
// d the DRR's line integrals, dmin their smallest valid value, c one effective-attenuation factor per view (the beam's
// hardening and the DRR's attenuation scale, chosen on a grid of kGainGrid values by a global least-squares fit
// I ~ g0 E_c + s0 over the valid pixels), and g(u), s(u) smooth: a Gaussian-weighted local linear regression of I on
// E_c (Gaussian sigma `sigma_px`, normalized over the valid pixels), with g pulled toward the global g0 where E_c
// hardly varies (ridge weight kRidge times the median local variance of E_c). The corrected X-ray is
// (I - s) / g, taken back to line integrals by XrayIntensityModel (its reference level and floor).
// The haze and gain are smooth, so the fit needs the DRR near the truth only to within their smoothness, not to within
// the registration's accuracy (docs/evaluation.md, "Haze removal").

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"

namespace fct {

/// A corrected X-ray and the fit that made it.
struct HazeCorrection {
  FloatImage lineIntegrals;           ///< the X-ray with the haze and gain removed, p = -ln(I / I0) >= 0
  double attenuationFactor = 1.0;     ///< c of the model (DRR line integrals to the X-ray's)
  double globalGain = 0.0;            ///< g0 of the global fit
  double meanHazeFraction = 0.0;      ///< mean of |s| / I over the valid pixels: the share of the signal changed
};

/// Removes a smooth additive haze from an X-ray given a DRR near the truth.
class XrayHazeCorrector {
 public:
  /// Candidate attenuation factors c: kGainGrid values from 0.5 to 1.5.
  static constexpr int kGainGrid = 21;
  /// Weight of the pull of the local gain toward the global one, times the median local variance of the DRR term.
  static constexpr double kRidge = 0.1;

  /// `xrayLineIntegrals`: the X-ray (p = -ln(I/I0)); `drrLineIntegrals`: the DRR of the same detector at a pose near
  /// the truth; `mask`: the pixels to fit on (field, no metal, clear of the CT's cut faces); `sigma_px`: the haze's
  /// smoothness (Gaussian sigma, pixels). Fails on size mismatches, sigma_px <= 0, fewer than 100 valid pixels, a DRR
  /// without contrast over them, or a fit whose gain is not positive (the DRR does not explain the X-ray: the pose
  /// is far off).
  static Result<HazeCorrection> correct(const FloatImage& xrayLineIntegrals, const FloatImage& drrLineIntegrals,
                                        const ValidMask& mask, double sigma_px);
};

}  // namespace fct
