#include "Simulation/Physics/XraySpectrum.h"

#include <fmt/core.h>

#include <cmath>

#include "Simulation/Physics/MassAttenuationTable.h"

namespace fct {

Result<XraySpectrum> XraySpectrum::create(const SpectrumOptions& options) {
  XraySpectrum spectrum;
  spectrum.m_options = options;
  if (options.monochromatic_keV != 0.0) {
    if (!(options.monochromatic_keV >= MassAttenuationTable::kMinEnergy_keV &&
          options.monochromatic_keV <= MassAttenuationTable::kMaxEnergy_keV)) {
      return fail(fmt::format("monochromatic energy must be 10..150 keV, got {}", options.monochromatic_keV));
    }
    spectrum.m_bins.push_back({options.monochromatic_keV, 1.0});
    return spectrum;
  }
  if (!(options.tubeVoltage_kvp >= 50.0 && options.tubeVoltage_kvp <= 120.0)) {
    return fail(fmt::format("tube voltage must be 50..120 kVp (fluoroscopy), got {}", options.tubeVoltage_kvp));
  }
  if (!(options.filtration_mmAl >= 0.0 && std::isfinite(options.filtration_mmAl))) {
    return fail(fmt::format("filtration must be >= 0 mm Al, got {}", options.filtration_mmAl));
  }
  if (!(options.binWidth_keV >= 1.0 && options.binWidth_keV <= 20.0)) {
    return fail(fmt::format("spectrum bin width must be 1..20 keV, got {}", options.binWidth_keV));
  }
  const double alDensity = MassAttenuationTable::density_g_per_cm3(Material::Aluminium);
  const double kvp = options.tubeVoltage_kvp;
  constexpr double kStep_keV = 0.25;  // integration step inside a bin
  double total = 0.0;
  for (double low = MassAttenuationTable::kMinEnergy_keV; low < kvp; low += options.binWidth_keV) {
    const double high = std::min(low + options.binWidth_keV, kvp);
    double photons = 0.0, energySum = 0.0;
    for (double e = low + 0.5 * kStep_keV; e < high; e += kStep_keV) {
      const double muAl = MassAttenuationTable::massAttenuation_cm2_per_g(Material::Aluminium, e).value();
      const double n = (kvp - e) / e * std::exp(-muAl * alDensity * options.filtration_mmAl * 0.1);
      photons += n;
      energySum += n * e;
    }
    if (photons <= 0.0) continue;
    spectrum.m_bins.push_back({energySum / photons, photons});
    total += photons;
  }
  for (SpectrumBin& bin : spectrum.m_bins) bin.photonFraction /= total;
  return spectrum;
}

double XraySpectrum::meanEnergy_keV() const {
  double sum = 0.0;
  for (const SpectrumBin& bin : m_bins) sum += bin.energy_keV * bin.photonFraction;
  return sum;
}

std::string XraySpectrum::describe() const {
  if (m_options.monochromatic_keV != 0.0) return fmt::format("monochromatic {} keV", m_options.monochromatic_keV);
  return fmt::format(
      "Kramers thick-target spectrum N(E) ~ (kVp - E)/E at {} kVp, filtered by {} mm Al (NIST XCOM), {} keV bins, "
      "mean energy {:.1f} keV",
      m_options.tubeVoltage_kvp, m_options.filtration_mmAl, m_options.binWidth_keV, meanEnergy_keV());
}

}  // namespace fct
