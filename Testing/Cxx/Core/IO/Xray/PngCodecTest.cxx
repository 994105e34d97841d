#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "IO/Xray/PngCodec.h"

using fct::PngCodec;
using fct::RasterSampleType;

namespace {

/// `mat` encoded by OpenCV (an independent PNG writer), with the given imwrite parameters.
std::string encodedByOpenCv(const cv::Mat& mat, const std::vector<int>& parameters = {}) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(".png", mat, bytes, parameters));
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace

TEST(PngCodec, SixteenBitGreyRoundTripsAndOpenCvReadsIt) {
  std::vector<std::uint16_t> pixels(13 * 7);
  for (std::size_t n = 0; n < pixels.size(); ++n) pixels[n] = static_cast<std::uint16_t>(n * 719 % 65536);
  auto encoded = PngCodec::encodeGrey16(pixels.data(), 13, 7);
  ASSERT_TRUE(encoded) << encoded.error();

  auto decoded = PngCodec::decode(encoded.value(), 16384, 1u << 25);
  ASSERT_TRUE(decoded) << decoded.error();
  EXPECT_EQ(decoded.value().cols, 13);
  EXPECT_EQ(decoded.value().rows, 7);
  EXPECT_EQ(decoded.value().channels, 1);
  EXPECT_EQ(decoded.value().sampleType, RasterSampleType::UInt16);
  ASSERT_EQ(decoded.value().samples.size(), pixels.size());
  for (std::size_t n = 0; n < pixels.size(); ++n) ASSERT_EQ(decoded.value().samples[n], pixels[n]) << n;

  const cv::Mat byOpenCv = cv::imdecode(std::vector<unsigned char>(encoded.value().begin(), encoded.value().end()),
                                        cv::IMREAD_UNCHANGED);
  ASSERT_EQ(byOpenCv.type(), CV_16UC1);
  EXPECT_EQ(byOpenCv.at<std::uint16_t>(6, 12), pixels.back());
}

TEST(PngCodec, RgbRoundTripsInChannelOrder) {
  const std::vector<std::uint8_t> rgb = {1, 2, 3, 250, 128, 0};
  auto encoded = PngCodec::encodeRgb8(rgb.data(), 2, 1);
  ASSERT_TRUE(encoded) << encoded.error();
  auto decoded = PngCodec::decode(encoded.value(), 16384, 1u << 25);
  ASSERT_TRUE(decoded) << decoded.error();
  EXPECT_EQ(decoded.value().channels, 3);
  EXPECT_EQ(decoded.value().samples, std::vector<float>({1, 2, 3, 250, 128, 0}));
}

TEST(PngCodec, WidensOneBitGreyAndKeepsAlphaAsAChannel) {
  cv::Mat bilevel(3, 9, CV_8U, cv::Scalar(0));
  bilevel.at<std::uint8_t>(1, 4) = 255;
  auto oneBit = PngCodec::decode(encodedByOpenCv(bilevel, {cv::IMWRITE_PNG_BILEVEL, 1}), 16384, 1u << 25);
  ASSERT_TRUE(oneBit) << oneBit.error();
  EXPECT_EQ(oneBit.value().sampleType, RasterSampleType::UInt8);
  EXPECT_EQ(oneBit.value().samples[1 * 9 + 4], 255.0f);
  EXPECT_EQ(oneBit.value().samples[0], 0.0f);

  cv::Mat bgra(2, 2, CV_8UC4, cv::Scalar(10, 20, 30, 40));  // OpenCV's order: B, G, R, A
  auto rgba = PngCodec::decode(encodedByOpenCv(bgra), 16384, 1u << 25);
  ASSERT_TRUE(rgba) << rgba.error();
  EXPECT_EQ(rgba.value().channels, 4);
  EXPECT_EQ(std::vector<float>(rgba.value().samples.begin(), rgba.value().samples.begin() + 4),
            std::vector<float>({30, 20, 10, 40}));
}

TEST(PngCodec, RejectsTruncatedDamagedAndOversizedDataWithLibpngsReason) {
  const std::string whole = encodedByOpenCv(cv::Mat(40, 40, CV_16U, cv::Scalar(1234)));
  for (const std::size_t keep : {std::size_t{0}, std::size_t{8}, std::size_t{30}, whole.size() / 2, whole.size() - 13}) {
    auto truncated = PngCodec::decode(std::string_view(whole).substr(0, keep), 16384, 1u << 25);
    ASSERT_FALSE(truncated) << "kept " << keep << " bytes";
    EXPECT_EQ(truncated.error().rfind("libpng: ", 0), 0u) << truncated.error();
  }
  std::string damaged = whole;
  damaged[45] = static_cast<char>(damaged[45] ^ 0x5a);  // inside the image data: its CRC no longer matches
  EXPECT_FALSE(PngCodec::decode(damaged, 16384, 1u << 25));
  auto wide = PngCodec::decode(whole, 39, 1u << 25);
  ASSERT_FALSE(wide);
  EXPECT_NE(wide.error().find("libpng"), std::string::npos) << wide.error();
}
