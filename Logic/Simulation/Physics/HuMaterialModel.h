#pragma once
// HuMaterialModel: splits a CT voxel's Hounsfield value into the mass densities of the simulator's materials.
//
//   HU < airBelow_hu                      air, 0.001205 g/cm³ (NIST dry air)
//   airBelow_hu <= HU <= boneFrom_hu      soft tissue (ICRU-44 µ/ρ), ρ = 1 + HU/1000 g/cm³ (water scale: fat 0.9, lung 0.2)
//   boneFrom_hu < HU < metalFrom_hu       mixture: bone fraction w = (HU - boneFrom) / (corticalBone - boneFrom);
//                                         soft tissue ρ = ρ_soft(boneFrom) · (1 - w) (for w < 1), cortical bone
//                                         (ICRU-44) ρ = 1.92 · w g/cm³ (w may exceed 1 for very dense bone)
//   HU >= metalFrom_hu                    iron (stainless steel) at 7.874 g/cm³
// The mixture makes trabecular bone a partial volume of cortical bone in soft tissue, continuous in HU. Densities
// from HU are a simplification of stoichiometric calibration (Schneider et al., Phys. Med. Biol. 45:459, 2000).

#include <array>

#include "Base/Result.h"
#include "Simulation/Physics/MassAttenuationTable.h"

namespace fct {

/// Mass per area (g/cm²) crossed by a ray, per Material (index = static_cast<int>(Material)).
using MassPaths = std::array<double, kMaterialCount>;

/// HU thresholds of the material split.
struct HuMaterialModel {
  double airBelow_hu = -950.0;       ///< below: air
  double boneFrom_hu = 100.0;        ///< above: soft tissue / cortical bone mixture
  double corticalBone_hu = 1500.0;   ///< pure cortical bone (bone fraction 1)
  double metalFrom_hu = 3000.0;      ///< at or above: iron

  /// Checks airBelow < boneFrom < corticalBone < metalFrom, all finite, boneFrom > -1000. Names the bad value.
  Status validate() const;

  /// Adds a voxel of value `hu` crossed over `length_cm` to `paths` (g/cm² per material). Hot loop: no checks.
  void accumulate(float hu, double length_cm, MassPaths& paths) const {
    constexpr int kAir = static_cast<int>(Material::Air), kSoft = static_cast<int>(Material::SoftTissue);
    constexpr int kBone = static_cast<int>(Material::CorticalBone), kIron = static_cast<int>(Material::Iron);
    constexpr double kAirDensity = MassAttenuationTable::density_g_per_cm3(Material::Air);
    constexpr double kBoneDensity = MassAttenuationTable::density_g_per_cm3(Material::CorticalBone);
    constexpr double kIronDensity = MassAttenuationTable::density_g_per_cm3(Material::Iron);
    if (hu < airBelow_hu) {
      paths[kAir] += kAirDensity * length_cm;
    } else if (hu <= boneFrom_hu) {
      paths[kSoft] += (1.0 + hu * 1e-3) * length_cm;
    } else if (hu < metalFrom_hu) {
      const double w = (hu - boneFrom_hu) / (corticalBone_hu - boneFrom_hu);
      if (w < 1.0) paths[kSoft] += (1.0 + boneFrom_hu * 1e-3) * (1.0 - w) * length_cm;
      paths[kBone] += kBoneDensity * w * length_cm;
    } else {
      paths[kIron] += kIronDensity * length_cm;
    }
  }
};

}  // namespace fct
