#include <gtest/gtest.h>

#include <fstream>

#include "IO/Xray/ImageFileWriter.h"
#include "IO/Xray/XrayLoader.h"
#include "TestSupport.h"

TEST(XrayLoader, DispatchesPngAndDicomByExtension) {
  fct::FloatImage image = fct::FloatImage::filled(8, 6, 0.0f);
  image.at(3, 2) = 1.0f;
  const auto png = fct::test::scratchDir() / "shot.PNG";
  ASSERT_TRUE(fct::ImageFileWriter::writePng16(image, png, 0.0f, 1.0f).ok());
  const auto loaded = fct::XrayLoader::load(png);
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  EXPECT_EQ(loaded.value().cols, 8);
  EXPECT_GT(loaded.value().at(3, 2), loaded.value().at(0, 0));
  EXPECT_FALSE(fct::XrayLoader::load(png, 1).ok());

  FCT_REQUIRE_DATA("xray/rf_shoulder_kwire.dcm");
  const auto rf = fct::XrayLoader::load(fct::test::dataDir() / "xray/rf_shoulder_kwire.dcm");
  ASSERT_TRUE(rf.ok()) << rf.error();
  EXPECT_EQ(rf.value().modality, "RF");
}

TEST(XrayLoader, MissingFileAndNonImageSayWhatIsWrong) {
  EXPECT_NE(fct::XrayLoader::load("/nonexistent/shot.dcm").error().find("no such file"), std::string::npos);
  const auto text = fct::test::scratchDir() / "notes.dcm";
  { std::ofstream(text) << "not a DICOM file"; }
  const auto result = fct::XrayLoader::load(text);
  EXPECT_FALSE(result.ok());
  EXPECT_FALSE(result.error().empty());
}
