#include <gtest/gtest.h>

#include "IO/Volume/CtLoader.h"
#include "IO/Volume/VolumeFileIO.h"
#include "TestSupport.h"

TEST(CtLoader, ReadsVolumeFileAndRoundTripsThroughNrrd) {
  auto volume = fct::Volume::create({6, 5, 4}, {0.5, 0.6, 2.0}, {10, -20, 30}).value();
  volume.at(2, 3, 1) = 1234.0f;
  const auto path = fct::test::scratchDir() / "ct.nrrd";
  ASSERT_TRUE(fct::VolumeFileIO::write(volume, path).ok());
  const auto loaded = fct::CtLoader::load(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  EXPECT_EQ(loaded.value().dims(), volume.dims());
  EXPECT_FLOAT_EQ(loaded.value().at(2, 3, 1), 1234.0f);
}

TEST(CtLoader, ReadsDicomFolderAsSeries) {
  FCT_REQUIRE_DATA("ct/head_phantom_philips_bone");
  // A folder goes to the DICOM series reader; the refuse policy is passed through (this series is regular).
  fct::DicomSeriesReadOptions options;
  options.policy = fct::IrregularSeriesPolicy::Refuse;
  const auto summary = fct::DicomSeriesReader::scan(fct::test::dataDir() / "ct/head_phantom_philips_tilted");
  ASSERT_TRUE(summary.ok()) << summary.error();
  const auto refused = fct::CtLoader::load(fct::test::dataDir() / "ct/head_phantom_philips_tilted", options);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("tilt"), std::string::npos) << refused.error();
}

TEST(CtLoader, MissingPathSaysWhatToGive) {
  const auto result = fct::CtLoader::load("/nonexistent/ct.nii.gz");
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("no such file or folder"), std::string::npos);
  EXPECT_NE(result.error().find("DICOM folder"), std::string::npos);
}
