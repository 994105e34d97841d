#pragma once
// MassAttenuationTable: photon mass attenuation coefficients µ/ρ (cm²/g, total with coherent scattering) and nominal
// densities of the materials of the fluoroscopy simulator, from the NIST tables of J. H. Hubbell and S. M. Seltzer,
// "Tables of X-Ray Mass Attenuation Coefficients and Mass Energy-Absorption Coefficients", NISTIR 5632 / NIST
// Standard Reference Database 126 (https://physics.nist.gov/PhysRefData/XrayMassCoef/), Table 3 (elements: Al, Ti,
// Fe) and Table 4 (mixtures: Air, Dry; Water, Liquid; Tissue, Soft (ICRU-44); Bone, Cortical (ICRU-44)), at the
// tabulated energies 10, 15, 20, 30, 40, 50, 60, 80, 100 and 150 keV. Between them µ/ρ is interpolated linearly in
// log(µ/ρ) against log(E), as NIST recommends away from absorption edges (none of these materials has an edge in
// 10–150 keV). Stainless steel is approximated by iron and Ti-6Al-4V by titanium. The numbers were typed in by hand;
// the Fe, Al and cortical-bone rows were checked digit by digit against copies of the NIST tables, the soft-tissue and
// water rows at 40–100 keV, and the Ti row only against published linear coefficients (within ~3 %).

#include <array>
#include <string_view>

#include "Base/Result.h"

namespace fct {

/// The materials the simulator knows.
enum class Material { Air, Water, SoftTissue, CorticalBone, Aluminium, Titanium, Iron };

/// Number of Material values.
inline constexpr int kMaterialCount = 7;

/// NIST mass attenuation coefficients and nominal densities.
class MassAttenuationTable {
 public:
  /// µ/ρ of `material` at `energy_keV` in cm²/g. Fails outside the tabulated 10–150 keV.
  static Result<double> massAttenuation_cm2_per_g(Material material, double energy_keV);
  /// Nominal density in g/cm³ (NIST Table 2 / Table 1: air 0.001205, water 1, soft tissue 1.06, cortical bone 1.92,
  /// aluminium 2.699, titanium 4.54, iron 7.874).
  static constexpr double density_g_per_cm3(Material material) {
    constexpr std::array<double, kMaterialCount> kDensity_g_per_cm3 = {0.001205, 1.0, 1.06, 1.92, 2.699, 4.54, 7.874};
    return kDensity_g_per_cm3[static_cast<int>(material)];
  }
  /// The material's name as written in simulation.json ("soft_tissue", ...).
  static std::string_view name(Material material);
  /// Lowest and highest tabulated energy in keV.
  static constexpr double kMinEnergy_keV = 10.0;
  static constexpr double kMaxEnergy_keV = 150.0;
};

}  // namespace fct
