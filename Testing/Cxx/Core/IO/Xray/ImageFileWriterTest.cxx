#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "IO/Xray/ImageFileWriter.h"
#include "IO/Xray/XrayImageFileReader.h"
#include "TestSupport.h"

using fct::FloatImage;
using fct::ImageFileWriter;

namespace {

FloatImage testImage() {
  FloatImage image = FloatImage::filled(7, 5);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) image.at(c, r) = 0.25f * c - 1.5f * r + 0.125f;
  }
  return image;
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Only `expected` in the folder: no temporary files left behind.
void expectOnlyFile(const std::filesystem::path& dir, const std::string& expected) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{expected});
}

}  // namespace

TEST(ImageFileWriter, PfmRoundTripsWithRowsBottomUp) {
  const FloatImage image = testImage();
  const auto dir = fct::test::scratchDir();
  ASSERT_TRUE(ImageFileWriter::writePfm(image, dir / "drr.pfm"));
  expectOnlyFile(dir, "drr.pfm");

  std::istringstream in(slurp(dir / "drr.pfm"));
  std::string magic;
  int cols = 0, rows = 0;
  double scale = 0;
  in >> magic >> cols >> rows >> scale;
  in.get();  // the single whitespace after the scale
  EXPECT_EQ(magic, "Pf");
  ASSERT_EQ(cols, 7);
  ASSERT_EQ(rows, 5);
  EXPECT_LT(scale, 0.0);  // little endian
  std::vector<float> data(35);
  in.read(reinterpret_cast<char*>(data.data()), 35 * sizeof(float));
  ASSERT_TRUE(in);
  for (int r = 0; r < 5; ++r) {
    for (int c = 0; c < 7; ++c) EXPECT_EQ(data[static_cast<std::size_t>((4 - r) * 7 + c)], image.at(c, r));
  }
}

TEST(ImageFileWriter, Float32TiffRoundTripsThroughOpenCvAndXrayReader) {
  FloatImage image = testImage();
  image.at(2, 3) = 12345.678f;
  const auto path = fct::test::scratchDir() / "drr.tif";
  ASSERT_TRUE(ImageFileWriter::writeTiff(image, path));
  const cv::Mat back = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.type(), CV_32FC1);
  ASSERT_EQ(back.cols, 7);
  for (int r = 0; r < 5; ++r) {
    for (int c = 0; c < 7; ++c) EXPECT_EQ(back.at<float>(r, c), image.at(c, r));
  }
  auto xray = fct::XrayImageFileReader::read(path);
  ASSERT_TRUE(xray) << xray.error();
  EXPECT_EQ(xray.value().bitsStored, 32);
  EXPECT_EQ(xray.value().pixels, image.pixels);
}

TEST(ImageFileWriter, Png16MapsWindowToFullRange) {
  FloatImage image = FloatImage::filled(4, 1);
  image.pixels = {-5.0f, 0.0f, 10.0f, std::numeric_limits<float>::quiet_NaN()};
  const auto path = fct::test::scratchDir() / "drr.png";
  ASSERT_TRUE(ImageFileWriter::writePng16(image, path, 0.0f, 20.0f));
  const cv::Mat back = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.type(), CV_16UC1);
  EXPECT_EQ(back.at<std::uint16_t>(0, 0), 0);      // clamped below the window
  EXPECT_EQ(back.at<std::uint16_t>(0, 1), 0);
  EXPECT_EQ(back.at<std::uint16_t>(0, 2), 32768);  // window centre: round(32767.5)
  EXPECT_EQ(back.at<std::uint16_t>(0, 3), 0);      // NaN
}

TEST(ImageFileWriter, Nrrd2dHeaderAndDataRoundTrip) {
  const FloatImage image = testImage();
  const auto path = fct::test::scratchDir() / "drr.nrrd";
  ASSERT_TRUE(ImageFileWriter::writeNrrd2d(image, path, Eigen::Vector2d(0.4, 0.6)));
  const std::string text = slurp(path);
  const auto end = text.find("\n\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = text.substr(0, end);
  EXPECT_EQ(header.rfind("NRRD0004", 0), 0u);
  EXPECT_NE(header.find("type: float"), std::string::npos);
  EXPECT_NE(header.find("sizes: 7 5"), std::string::npos);
  EXPECT_NE(header.find("spacings: 0.4 0.6"), std::string::npos);
  EXPECT_NE(header.find("endian: little"), std::string::npos);
  ASSERT_EQ(text.size() - (end + 2), 35 * sizeof(float));
  std::vector<float> data(35);
  std::memcpy(data.data(), text.data() + end + 2, 35 * sizeof(float));
  EXPECT_EQ(data, image.pixels);
}

TEST(ImageFileWriter, RejectsBadInputsWithoutLeavingFiles) {
  const auto dir = fct::test::scratchDir();
  const FloatImage image = testImage();
  FloatImage inconsistent = image;
  inconsistent.pixels.pop_back();
  EXPECT_FALSE(ImageFileWriter::writePfm(FloatImage{}, dir / "empty.pfm"));
  EXPECT_FALSE(ImageFileWriter::writeTiff(inconsistent, dir / "bad.tif"));
  auto window = ImageFileWriter::writePng16(image, dir / "bad.png", 5.0f, 5.0f);
  ASSERT_FALSE(window);
  EXPECT_NE(window.error().find("min < max"), std::string::npos) << window.error();
  EXPECT_FALSE(ImageFileWriter::writeNrrd2d(image, dir / "bad.nrrd", Eigen::Vector2d(0.0, 1.0)));
  auto noFolder = ImageFileWriter::writeTiff(image, dir / "missing" / "x.tif");
  ASSERT_FALSE(noFolder);
  EXPECT_NE(noFolder.error().find("does not exist"), std::string::npos) << noFolder.error();
  EXPECT_TRUE(std::filesystem::is_empty(dir));

  // An existing file is replaced whole by a successful write and kept when the write is refused.
  ASSERT_TRUE(ImageFileWriter::writePfm(image, dir / "keep.pfm"));
  const std::string before = slurp(dir / "keep.pfm");
  EXPECT_FALSE(ImageFileWriter::writePfm(FloatImage{}, dir / "keep.pfm"));
  EXPECT_EQ(slurp(dir / "keep.pfm"), before);
  expectOnlyFile(dir, "keep.pfm");
}

TEST(ImageFileWriter, RgbPngRoundTripsAndRejectsInconsistentImages) {
  fct::RgbImage image;
  image.cols = 5;
  image.rows = 3;
  for (int n = 0; n < 15; ++n) {
    image.pixels.push_back(static_cast<std::uint8_t>(10 * n));
    image.pixels.push_back(static_cast<std::uint8_t>(200 - n));
    image.pixels.push_back(static_cast<std::uint8_t>(7));
  }
  const auto path = fct::test::scratchDir() / "rgb.png";
  ASSERT_TRUE(fct::ImageFileWriter::writePngRgb(image, path).ok());
  const cv::Mat bgr = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  const cv::Vec3b last = bgr.at<cv::Vec3b>(2, 4);
  EXPECT_EQ(last[2], 140);  // red of pixel 14
  EXPECT_EQ(last[1], 186);
  EXPECT_EQ(last[0], 7);
  fct::RgbImage broken = image;
  broken.pixels.pop_back();
  EXPECT_FALSE(fct::ImageFileWriter::writePngRgb(broken, fct::test::scratchDir() / "broken.png").ok());
  EXPECT_FALSE(std::filesystem::exists(fct::test::scratchDir() / "broken.png"));
}
