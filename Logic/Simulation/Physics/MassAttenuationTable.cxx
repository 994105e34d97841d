#include "Simulation/Physics/MassAttenuationTable.h"

#include <fmt/core.h>

#include <cmath>

namespace fct {

namespace {

constexpr int kEnergyCount = 10;
constexpr std::array<double, kEnergyCount> kEnergies_keV = {10, 15, 20, 30, 40, 50, 60, 80, 100, 150};

// µ/ρ in cm²/g at kEnergies_keV, transcribed from NISTIR 5632 (see the header); rows in Material order.
constexpr std::array<std::array<double, kEnergyCount>, kMaterialCount> kMassAttenuation_cm2_per_g = {{
    // Air, Dry (near sea level)
    {5.120, 1.614, 0.7779, 0.3538, 0.2485, 0.2080, 0.1875, 0.1662, 0.1541, 0.1356},
    // Water, Liquid
    {5.329, 1.673, 0.8096, 0.3756, 0.2683, 0.2269, 0.2059, 0.1837, 0.1707, 0.1505},
    // Tissue, Soft (ICRU-44)
    {5.379, 1.691, 0.8205, 0.3783, 0.2688, 0.2264, 0.2048, 0.1823, 0.1693, 0.1492},
    // Bone, Cortical (ICRU-44)
    {28.51, 9.032, 4.001, 1.331, 0.6655, 0.4242, 0.3148, 0.2229, 0.1855, 0.1480},
    // Aluminium (Z = 13)
    {26.23, 7.955, 3.441, 1.128, 0.5685, 0.3681, 0.2778, 0.2018, 0.1704, 0.1378},
    // Titanium (Z = 22)
    {110.7, 35.87, 15.85, 4.972, 2.214, 1.213, 0.7661, 0.4052, 0.2721, 0.1649},
    // Iron (Z = 26)
    {170.6, 57.08, 25.68, 8.176, 3.629, 1.958, 1.205, 0.5952, 0.3717, 0.1964},
}};

constexpr std::array<std::string_view, kMaterialCount> kNames = {"air",       "water",    "soft_tissue", "cortical_bone",
                                                                 "aluminium", "titanium", "iron"};

}  // namespace

Result<double> MassAttenuationTable::massAttenuation_cm2_per_g(Material material, double energy_keV) {
  if (!(energy_keV >= kMinEnergy_keV && energy_keV <= kMaxEnergy_keV)) {
    return fail(fmt::format("photon energy {} keV is outside the attenuation table's {}-{} keV", energy_keV,
                            kMinEnergy_keV, kMaxEnergy_keV));
  }
  const auto& row = kMassAttenuation_cm2_per_g[static_cast<int>(material)];
  int upper = 1;
  while (upper < kEnergyCount - 1 && kEnergies_keV[upper] < energy_keV) ++upper;
  const double t = std::log(energy_keV / kEnergies_keV[upper - 1]) / std::log(kEnergies_keV[upper] / kEnergies_keV[upper - 1]);
  return std::exp(std::log(row[upper - 1]) + t * std::log(row[upper] / row[upper - 1]));
}

std::string_view MassAttenuationTable::name(Material material) { return kNames[static_cast<int>(material)]; }

}  // namespace fct
