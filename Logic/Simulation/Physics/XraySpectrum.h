#pragma once
// XraySpectrum: the photon spectrum of the X-ray tube as a few energy bins.
//
// Model (an approximation, stated honestly): the unfiltered thick-target bremsstrahlung photon spectrum of Kramers
// (H. A. Kramers, Phil. Mag. 46:836, 1923), N(E) ∝ (kVp − E) / E photons per keV, hardened by the tube's total
// aluminium filtration, exp(−(µ/ρ)_Al(E) · ρ_Al · t_Al), with µ/ρ from NIST XCOM (MassAttenuationTable). Tungsten
// K characteristic lines (59.3 / 67.2 keV, a few % of the fluence at 80 kVp), the anode heel effect and anode
// self-filtration are not modelled; compared with tabulated spectra (TASMIP, J. M. Boone and J. A. Seibert, Med.
// Phys. 24:1661, 1997) the Kramers shape is slightly too soft below 30 keV, which the filtration mostly removes.
// Each bin holds the photon fraction of its energy range and sits at the range's fluence-weighted mean energy.

#include <string>
#include <vector>

#include "Base/Result.h"

namespace fct {

/// One energy bin: its photon energy and its share of the photons.
struct SpectrumBin {
  double energy_keV = 0.0;      ///< fluence-weighted mean photon energy of the bin
  double photonFraction = 0.0;  ///< fraction of all photons (the bins sum to 1)
};

/// Settings of the tube spectrum.
struct SpectrumOptions {
  double tubeVoltage_kvp = 80.0;      ///< peak voltage, 50..120 kVp
  double filtration_mmAl = 2.5;       ///< total filtration in mm aluminium (2.5 mm: the IEC 60601-1-3 minimum above 70 kVp)
  double binWidth_keV = 5.0;          ///< width of the energy bins, 1..20 keV
  double monochromatic_keV = 0.0;     ///< > 0: a single line at this energy instead of the tube spectrum (tests)
};

/// A binned photon spectrum.
class XraySpectrum {
 public:
  /// Builds the spectrum; photons below 10 keV (absorbed by any filtration) are dropped. Fails on a kVp outside
  /// 50..120, a negative or non-finite filtration, a bin width outside 1..20 keV, or a monochromatic energy outside
  /// 10..150 keV.
  static Result<XraySpectrum> create(const SpectrumOptions& options);

  /// The bins, in increasing energy; photon fractions sum to 1.
  const std::vector<SpectrumBin>& bins() const { return m_bins; }
  /// Photon-fluence-weighted mean energy in keV.
  double meanEnergy_keV() const;
  /// One line describing the model, for simulation.json.
  std::string describe() const;

 private:
  std::vector<SpectrumBin> m_bins;
  SpectrumOptions m_options;
};

}  // namespace fct
