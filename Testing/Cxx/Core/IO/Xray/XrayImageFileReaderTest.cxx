#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "IO/Xray/XrayImageFileReader.h"
#include "TestSupport.h"
#include "TinyTiff.h"

using fct::XrayImageFileReader;
using fct::test::put;
using fct::test::tinyTiff;

namespace {

/// A cols x rows gradient of the given OpenCV type with values spread over `maxValue`.
cv::Mat gradient(int cols, int rows, int type, double maxValue) {
  cv::Mat m(rows, cols, type);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double v = maxValue * (r * cols + c) / (rows * cols - 1);
      if (type == CV_8U) m.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(v);
      else m.at<std::uint16_t>(r, c) = static_cast<std::uint16_t>(v);
    }
  }
  return m;
}

void expectSamePixels(const fct::XrayImage& image, const cv::Mat& expected) {
  ASSERT_EQ(image.cols, expected.cols);
  ASSERT_EQ(image.rows, expected.rows);
  cv::Mat asFloat;
  expected.convertTo(asFloat, CV_32F);
  for (int r = 0; r < expected.rows; ++r) {
    for (int c = 0; c < expected.cols; ++c) ASSERT_EQ(image.at(c, r), asFloat.at<float>(r, c)) << c << "," << r;
  }
}

}  // namespace

TEST(XrayImageFileReader, RoundTripsEightBitPng) {
  const cv::Mat original = gradient(37, 21, CV_8U, 255);
  const auto path = fct::test::scratchDir() / "grey8.png";
  ASSERT_TRUE(cv::imwrite(path.string(), original));
  auto image = XrayImageFileReader::read(path);
  ASSERT_TRUE(image) << image.error();
  EXPECT_EQ(image.value().modality, "PNG");
  EXPECT_EQ(image.value().bitsStored, 8);
  EXPECT_EQ(image.value().photometric, "MONOCHROME2");
  EXPECT_FALSE(image.value().camera.has_value());
  EXPECT_TRUE(image.warnings().empty());
  expectSamePixels(image.value(), original);
}

TEST(XrayImageFileReader, KeepsSixteenBitValuesInTiffAndPng) {
  const cv::Mat original = gradient(40, 30, CV_16U, 65535);
  const auto dir = fct::test::scratchDir();
  for (const char* name : {"grey16.tif", "grey16.png"}) {
    ASSERT_TRUE(cv::imwrite((dir / name).string(), original));
    auto image = XrayImageFileReader::read(dir / name);
    ASSERT_TRUE(image) << image.error();
    EXPECT_EQ(image.value().bitsStored, 16) << name;
    EXPECT_FLOAT_EQ(image.value().at(39, 29), 65535.0f) << name;  // above 255: 16 bits survived
    expectSamePixels(image.value(), original);
  }
  EXPECT_EQ(XrayImageFileReader::read(dir / "grey16.tif").value().modality, "TIFF");
}

TEST(XrayImageFileReader, ConvertsColourToGreyWithWarning) {
  cv::Mat colour(8, 8, CV_8UC3, cv::Scalar(10, 200, 30));  // B, G, R
  const auto dir = fct::test::scratchDir();
  ASSERT_TRUE(cv::imwrite((dir / "colour.png").string(), colour));
  auto image = XrayImageFileReader::read(dir / "colour.png");
  ASSERT_TRUE(image) << image.error();
  ASSERT_EQ(image.warnings().size(), 1u);
  EXPECT_NE(image.warnings()[0].find("colour"), std::string::npos);
  EXPECT_NEAR(image.value().at(3, 3), 0.299 * 30 + 0.587 * 200 + 0.114 * 10, 1.0);

  cv::Mat greyAsRgb(8, 8, CV_8UC3, cv::Scalar(77, 77, 77));
  ASSERT_TRUE(cv::imwrite((dir / "greyrgb.png").string(), greyAsRgb));
  auto grey = XrayImageFileReader::read(dir / "greyrgb.png");
  ASSERT_TRUE(grey) << grey.error();
  EXPECT_TRUE(grey.warnings().empty());
  EXPECT_EQ(grey.value().at(0, 0), 77.0f);
}

TEST(XrayImageFileReader, RejectsUnknownExtensionCorruptAndMissingFiles) {
  const auto dir = fct::test::scratchDir();
  auto jpeg = XrayImageFileReader::read(dir / "x.jpg");
  ASSERT_FALSE(jpeg);
  EXPECT_NE(jpeg.error().find("not a PNG or TIFF"), std::string::npos) << jpeg.error();

  EXPECT_NE(XrayImageFileReader::read(dir / "absent.png").error().find("does not exist"), std::string::npos);

  const std::string brokenTiff("II*\0garbage that is not a TIFF directory", 41);
  std::ofstream(dir / "broken.tif", std::ios::binary) << brokenTiff;
  auto broken = XrayImageFileReader::read(dir / "broken.tif");
  ASSERT_FALSE(broken);
  EXPECT_NE(broken.error().find("cannot"), std::string::npos) << broken.error();

  ASSERT_TRUE(cv::imwrite((dir / "signed.tif").string(), cv::Mat(4, 4, CV_16S, cv::Scalar(-5))));
  auto signedImage = XrayImageFileReader::read(dir / "signed.tif");
  ASSERT_FALSE(signedImage);
  EXPECT_NE(signedImage.error().find("unsupported pixel type"), std::string::npos) << signedImage.error();
}

TEST(XrayImageFileReader, RejectsAFileWhoseBytesAreNotItsFormat) {
  // OpenCV chooses its decoder from the bytes; DICOM bytes named .png once reached GDCM, which aborted on them
  // (Testing/Fuzz/regressions/xray_png).
  const auto dir = fct::test::scratchDir();
  const std::string dicomLike = std::string(128, '\0') + "DICM" + std::string(64, '&');
  std::ofstream(dir / "dicom.png", std::ios::binary) << dicomLike;
  auto png = XrayImageFileReader::read(dir / "dicom.png");
  ASSERT_FALSE(png);
  EXPECT_NE(png.error().find("'dicom.png' is not a PNG file: it does not start with the PNG signature"), std::string::npos)
      << png.error();

  ASSERT_TRUE(cv::imwrite((dir / "real.png").string(), cv::Mat(4, 4, CV_8U, cv::Scalar(7))));
  std::filesystem::copy_file(dir / "real.png", dir / "png_named.tif", std::filesystem::copy_options::overwrite_existing);
  auto tif = XrayImageFileReader::read(dir / "png_named.tif");
  ASSERT_FALSE(tif);
  EXPECT_NE(tif.error().find("is not a TIFF file"), std::string::npos) << tif.error();
  EXPECT_TRUE(XrayImageFileReader::read(dir / "real.png").ok());
}

TEST(XrayImageFileReader, RefusesAnImageWhoseHeaderDeclaresMoreThanAnyDetectorBeforeDecodingIt) {
  // OpenCV allocates the image its header declares before it decodes: a 900-byte TIFF once asked for over 2 GB.
  const auto dir = fct::test::scratchDir();
  for (const bool bigEndian : {false, true}) {
    for (const bool bigTiff : {false, true}) {
      const std::string name = std::string(bigEndian ? "mm" : "ii") + (bigTiff ? "_bigtiff" : "_classic");
      std::ofstream(dir / (name + ".tif"), std::ios::binary) << tinyTiff(2, 2, bigEndian, bigTiff);
      const auto small = XrayImageFileReader::read(dir / (name + ".tif"));
      ASSERT_TRUE(small.ok()) << name << ": " << small.error();
      EXPECT_EQ(small.value().cols, 2);
      EXPECT_EQ(small.value().rows, 2);
      EXPECT_EQ(small.value().at(1, 1), 50.0f) << name;

      std::ofstream(dir / (name + "_huge.tif"), std::ios::binary) << tinyTiff(60000, 40000, bigEndian, bigTiff);
      const auto huge = XrayImageFileReader::read(dir / (name + "_huge.tif"));
      ASSERT_FALSE(huge.ok()) << name;
      EXPECT_NE(huge.error().find("declares an image of 60000 x 40000 pixels"), std::string::npos) << huge.error();
    }
  }
  // Each side within the limit, the whole beyond it: 16000 x 16000 is 256 million pixels.
  std::ofstream(dir / "square.tif", std::ios::binary) << tinyTiff(16000, 16000, false, false);
  const auto square = XrayImageFileReader::read(dir / "square.tif");
  ASSERT_FALSE(square.ok());
  EXPECT_NE(square.error().find("16000 x 16000"), std::string::npos) << square.error();

  // A PNG: width and height are the first fields of its IHDR chunk (bytes 16 to 23, big-endian).
  ASSERT_TRUE(cv::imwrite((dir / "small.png").string(), cv::Mat(3, 5, CV_8U, cv::Scalar(9))));
  std::ifstream in(dir / "small.png", std::ios::binary);
  std::string png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string size;
  put(size, 70000, 4, true);
  put(size, 3, 4, true);
  png.replace(16, 8, size);
  std::ofstream(dir / "wide.png", std::ios::binary) << png;
  const auto wide = XrayImageFileReader::read(dir / "wide.png");
  ASSERT_FALSE(wide.ok());
  EXPECT_NE(wide.error().find("'wide.png' declares an image of 70000 x 3 pixels"), std::string::npos) << wide.error();
}

TEST(XrayImageFileReader, RefusesAFileLargerThanAnyAcceptedImageBeforeReadingIt) {
  // A 2 GiB file (sparse: no disk is used) that starts as a valid TIFF whose directory cannot be found.
  const auto path = fct::test::scratchDir() / "huge.tif";
  std::ofstream(path, std::ios::binary) << std::string("II*\0\xff\xff\xff\x7f", 8);
  std::filesystem::resize_file(path, std::uintmax_t{1} << 31);
  const auto huge = XrayImageFileReader::read(path);
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.error().find("'huge.tif' is 2147483648 bytes, more than any X-ray image"), std::string::npos)
      << huge.error();
  std::filesystem::remove(path);
}
