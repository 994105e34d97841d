#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <tiffio.h>
#include <vector>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "IO/Xray/TiffCodec.h"
#include "TestSupport.h"

using fct::RasterSampleType;
using fct::TiffCodec;

namespace {

constexpr std::uint32_t kMaxSide = 16384;
constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 25;

/// How the test writes a TIFF with libtiff itself: the layouts a detector or an image tool may produce.
struct TiffRecipe {
  int bits = 16;
  int samples = 1;
  std::uint16_t photometric = PHOTOMETRIC_MINISBLACK;
  std::uint16_t planar = PLANARCONFIG_CONTIG;
  std::uint16_t compression = COMPRESSION_NONE;
  bool tiled = false;
};

/// Sample s of pixel (c, r) of the test pattern, below 2^bits.
std::uint32_t patternValue(int c, int r, int s, int bits) {
  return static_cast<std::uint32_t>((c * 37 + r * 101 + s * 53) % (bits == 8 ? 256 : 65536));
}

/// Writes a cols x rows TIFF of the pattern with libtiff and returns its bytes.
std::string writeTiff(const TiffRecipe& recipe, int cols, int rows) {
  const auto path = fct::test::scratchDir() / "recipe.tif";
  TIFF* tif = TIFFOpen(path.string().c_str(), "w");
  EXPECT_NE(tif, nullptr);
  TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, cols);
  TIFFSetField(tif, TIFFTAG_IMAGELENGTH, rows);
  TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, recipe.bits);
  TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, recipe.samples);
  TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, recipe.photometric);
  TIFFSetField(tif, TIFFTAG_PLANARCONFIG, recipe.planar);
  TIFFSetField(tif, TIFFTAG_COMPRESSION, recipe.compression);
  if (recipe.photometric == PHOTOMETRIC_PALETTE) {
    std::vector<std::uint16_t> red(256), green(256), blue(256);
    for (int i = 0; i < 256; ++i) {
      red[i] = static_cast<std::uint16_t>(i * 257);
      green[i] = static_cast<std::uint16_t>((255 - i) * 257);
      blue[i] = static_cast<std::uint16_t>(7 * 257);
    }
    TIFFSetField(tif, TIFFTAG_COLORMAP, red.data(), green.data(), blue.data());
  }
  const int bytes = recipe.bits / 8;
  const int planes = recipe.planar == PLANARCONFIG_SEPARATE ? recipe.samples : 1;
  const int perPixel = planes == 1 ? recipe.samples : 1;
  auto fill = [&](std::uint8_t* out, int c, int r, int plane) {
    for (int s = 0; s < perPixel; ++s) {
      const std::uint32_t v = patternValue(c, r, planes == 1 ? s : plane, recipe.bits);
      if (bytes == 1) {
        out[s] = static_cast<std::uint8_t>(v);
      } else {
        const auto v16 = static_cast<std::uint16_t>(v);
        std::memcpy(out + 2 * s, &v16, 2);
      }
    }
  };
  if (recipe.tiled) {
    TIFFSetField(tif, TIFFTAG_TILEWIDTH, 16);
    TIFFSetField(tif, TIFFTAG_TILELENGTH, 16);
    std::vector<std::uint8_t> tile(static_cast<std::size_t>(TIFFTileSize(tif)));
    for (int plane = 0; plane < planes; ++plane) {
      for (int y = 0; y < rows; y += 16) {
        for (int x = 0; x < cols; x += 16) {
          std::fill(tile.begin(), tile.end(), 0);
          for (int ty = 0; ty < 16 && y + ty < rows; ++ty) {
            for (int tx = 0; tx < 16 && x + tx < cols; ++tx) {
              fill(tile.data() + (ty * 16 + tx) * perPixel * bytes, x + tx, y + ty, plane);
            }
          }
          EXPECT_GE(TIFFWriteTile(tif, tile.data(), x, y, 0, static_cast<std::uint16_t>(plane)), 0);
        }
      }
    }
  } else {
    TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, 5);
    std::vector<std::uint8_t> line(static_cast<std::size_t>(cols * perPixel * bytes));
    for (int plane = 0; plane < planes; ++plane) {
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) fill(line.data() + c * perPixel * bytes, c, r, plane);
        EXPECT_GE(TIFFWriteScanline(tif, line.data(), r, static_cast<std::uint16_t>(plane)), 0);
      }
    }
  }
  TIFFClose(tif);
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(TiffCodec, Float32RoundTripsAndOpenCvReadsIt) {
  std::vector<float> pixels(11 * 6);
  for (std::size_t n = 0; n < pixels.size(); ++n) pixels[n] = 0.37f * static_cast<float>(n) - 9.5f;
  auto encoded = TiffCodec::encodeFloat32(pixels.data(), 11, 6);
  ASSERT_TRUE(encoded) << encoded.error();
  auto decoded = TiffCodec::decode(encoded.value(), kMaxSide, kMaxPixels);
  ASSERT_TRUE(decoded) << decoded.error();
  EXPECT_EQ(decoded.value().cols, 11);
  EXPECT_EQ(decoded.value().rows, 6);
  EXPECT_EQ(decoded.value().sampleType, RasterSampleType::Float32);
  EXPECT_EQ(decoded.value().samples, pixels);

  const cv::Mat byOpenCv = cv::imdecode(std::vector<unsigned char>(encoded.value().begin(), encoded.value().end()),
                                        cv::IMREAD_UNCHANGED);
  ASSERT_EQ(byOpenCv.type(), CV_32FC1);
  EXPECT_EQ(byOpenCv.at<float>(5, 10), pixels.back());
}

TEST(TiffCodec, ReadsStripsTilesPlanesAndCompressionAlike) {
  // 37 x 21: neither a multiple of the 16-pixel tiles nor of the 5-row strips.
  for (const bool tiled : {false, true}) {
    for (const std::uint16_t planar : {PLANARCONFIG_CONTIG, PLANARCONFIG_SEPARATE}) {
      for (const std::uint16_t compression : {COMPRESSION_NONE, COMPRESSION_LZW, COMPRESSION_ADOBE_DEFLATE}) {
        TiffRecipe recipe;
        recipe.samples = 3;
        recipe.photometric = PHOTOMETRIC_RGB;
        recipe.planar = planar;
        recipe.compression = compression;
        recipe.tiled = tiled;
        const std::string label = fmt::format("tiled {} planar {} compression {}", tiled, planar, compression);
        auto decoded = TiffCodec::decode(writeTiff(recipe, 37, 21), kMaxSide, kMaxPixels);
        ASSERT_TRUE(decoded) << label << ": " << decoded.error();
        ASSERT_EQ(decoded.value().channels, 3) << label;
        EXPECT_EQ(decoded.value().sampleType, RasterSampleType::UInt16) << label;
        for (int r = 0; r < 21; ++r) {
          for (int c = 0; c < 37; ++c) {
            for (int s = 0; s < 3; ++s) {
              ASSERT_EQ(decoded.value().samples[(r * 37 + c) * 3 + s], static_cast<float>(patternValue(c, r, s, 16)))
                  << label << " at " << c << "," << r << " sample " << s;
            }
          }
        }
      }
    }
  }
}

TEST(TiffCodec, ExpandsPalettesAndFlipsWhiteIsZeroWithANote) {
  TiffRecipe palette;
  palette.bits = 8;
  palette.photometric = PHOTOMETRIC_PALETTE;
  auto colours = TiffCodec::decode(writeTiff(palette, 9, 4), kMaxSide, kMaxPixels);
  ASSERT_TRUE(colours) << colours.error();
  ASSERT_EQ(colours.value().channels, 3);
  const float index = static_cast<float>(patternValue(2, 3, 0, 8));
  const std::size_t at = (3 * 9 + 2) * 3;
  EXPECT_EQ(colours.value().samples[at], index);
  EXPECT_EQ(colours.value().samples[at + 1], 255.0f - index);
  EXPECT_EQ(colours.value().samples[at + 2], 7.0f);
  ASSERT_EQ(colours.value().notes.size(), 1u);

  TiffRecipe whiteIsZero;
  whiteIsZero.photometric = PHOTOMETRIC_MINISWHITE;
  auto flipped = TiffCodec::decode(writeTiff(whiteIsZero, 9, 4), kMaxSide, kMaxPixels);
  ASSERT_TRUE(flipped) << flipped.error();
  EXPECT_EQ(flipped.value().samples[3 * 9 + 2], 65535.0f - static_cast<float>(patternValue(2, 3, 0, 16)));
  ASSERT_EQ(flipped.value().notes.size(), 1u);
  EXPECT_NE(flipped.value().notes[0].find("white-is-zero"), std::string::npos);
}

TEST(TiffCodec, RejectsUnsupportedTypesAndDamagedDataWithAReason) {
  const cv::Mat signedPixels(4, 4, CV_16S, cv::Scalar(-5));
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(cv::imencode(".tif", signedPixels, bytes));
  auto signedImage = TiffCodec::decode(std::string(bytes.begin(), bytes.end()), kMaxSide, kMaxPixels);
  ASSERT_FALSE(signedImage);
  EXPECT_NE(signedImage.error().find("unsupported pixel type (16-bit signed integer samples)"), std::string::npos)
      << signedImage.error();

  TiffRecipe compressed;
  compressed.compression = COMPRESSION_ADOBE_DEFLATE;
  compressed.tiled = true;
  const std::string whole = writeTiff(compressed, 64, 64);
  for (const std::size_t keep : {std::size_t{0}, std::size_t{7}, std::size_t{200}, whole.size() / 2}) {
    auto truncated = TiffCodec::decode(std::string_view(whole).substr(0, keep), kMaxSide, kMaxPixels);
    EXPECT_FALSE(truncated) << "kept " << keep << " of " << whole.size() << " bytes";
  }
  auto tooLarge = TiffCodec::decode(whole, kMaxSide, 64 * 64 - 1);
  ASSERT_FALSE(tooLarge);
  EXPECT_NE(tooLarge.error().find("64 x 64"), std::string::npos) << tooLarge.error();
}
