#include <gtest/gtest.h>

#include "Simulation/Physics/XraySpectrum.h"

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
