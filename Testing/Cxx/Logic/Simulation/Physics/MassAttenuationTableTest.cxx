#include <gtest/gtest.h>

#include "Simulation/Physics/MassAttenuationTable.h"

TEST(MassAttenuationTable, ReturnsNistValuesAtTabulatedEnergiesAndInterpolatesBetween) {
  using fct::Material;
  using fct::MassAttenuationTable;
  EXPECT_DOUBLE_EQ(MassAttenuationTable::massAttenuation_cm2_per_g(Material::CorticalBone, 40.0).value(), 0.6655);
  EXPECT_DOUBLE_EQ(MassAttenuationTable::massAttenuation_cm2_per_g(Material::Water, 60.0).value(), 0.2059);
  const double between = MassAttenuationTable::massAttenuation_cm2_per_g(Material::Iron, 45.0).value();
  EXPECT_LT(between, 3.629);
  EXPECT_GT(between, 1.958);
  // Metal attenuates far more than bone, bone more than soft tissue, at fluoroscopy energies.
  for (double e : {30.0, 50.0, 70.0}) {
    const double soft = MassAttenuationTable::massAttenuation_cm2_per_g(Material::SoftTissue, e).value() *
                        MassAttenuationTable::density_g_per_cm3(Material::SoftTissue);
    const double bone = MassAttenuationTable::massAttenuation_cm2_per_g(Material::CorticalBone, e).value() *
                        MassAttenuationTable::density_g_per_cm3(Material::CorticalBone);
    const double iron = MassAttenuationTable::massAttenuation_cm2_per_g(Material::Iron, e).value() *
                        MassAttenuationTable::density_g_per_cm3(Material::Iron);
    EXPECT_LT(soft, bone);
    EXPECT_LT(bone, iron);
  }
}

TEST(MassAttenuationTable, RejectsEnergiesOutsideTheTable) {
  EXPECT_FALSE(fct::MassAttenuationTable::massAttenuation_cm2_per_g(fct::Material::Water, 5.0).ok());
  EXPECT_FALSE(fct::MassAttenuationTable::massAttenuation_cm2_per_g(fct::Material::Water, 200.0).ok());
}
