#include <gtest/gtest.h>

#include "MassAttenuationTable.h"
#include "XraySpectrum.h"

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

TEST(XraySpectrum, BinsSumToOneBelowThePeakVoltageAndHardenWithFiltration) {
  fct::SpectrumOptions options;
  options.tubeVoltage_kvp = 80.0;
  auto soft = fct::XraySpectrum::create(options);
  ASSERT_TRUE(soft.ok()) << soft.error();
  double sum = 0.0;
  for (const fct::SpectrumBin& bin : soft.value().bins()) {
    sum += bin.photonFraction;
    EXPECT_LT(bin.energy_keV, 80.0);
    EXPECT_GE(bin.energy_keV, 10.0);
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_GE(soft.value().bins().size(), 10u);
  options.filtration_mmAl = 6.0;
  EXPECT_GT(fct::XraySpectrum::create(options).value().meanEnergy_keV(), soft.value().meanEnergy_keV());
  options.tubeVoltage_kvp = 90.0;
  options.filtration_mmAl = 2.5;
  EXPECT_GT(fct::XraySpectrum::create(options).value().meanEnergy_keV(), soft.value().meanEnergy_keV());
  fct::SpectrumOptions mono;
  mono.monochromatic_keV = 60.0;
  ASSERT_EQ(fct::XraySpectrum::create(mono).value().bins().size(), 1u);
  EXPECT_DOUBLE_EQ(fct::XraySpectrum::create(mono).value().meanEnergy_keV(), 60.0);
}

TEST(XraySpectrum, RejectsBadSettings) {
  for (auto change : {+[](fct::SpectrumOptions& o) { o.tubeVoltage_kvp = 30.0; },
                      +[](fct::SpectrumOptions& o) { o.tubeVoltage_kvp = 200.0; },
                      +[](fct::SpectrumOptions& o) { o.filtration_mmAl = -1.0; },
                      +[](fct::SpectrumOptions& o) { o.binWidth_keV = 0.0; },
                      +[](fct::SpectrumOptions& o) { o.monochromatic_keV = 500.0; }}) {
    fct::SpectrumOptions options;
    change(options);
    EXPECT_FALSE(fct::XraySpectrum::create(options).ok());
  }
}
