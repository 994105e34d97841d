#include "IO/Xray/PngCodec.h"

#include <fmt/core.h>
#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

namespace fct {

namespace {

// libpng reports errors by calling its error function, which must not return: it long-jumps back to the setjmp of
// the call that failed. The functions that set a jump point (readHeader, readRows, writeImage) hold only plain C
// values, so the jump skips no destructor; every C++ object is created by their callers.

/// Where libpng's last error message goes (its error pointer).
struct PngErrorText {
  char message[256] = {};
};

[[noreturn]] void onPngError(png_structp png, png_const_charp message) {
  auto* text = static_cast<PngErrorText*>(png_get_error_ptr(png));
  std::snprintf(text->message, sizeof text->message, "%s", message ? message : "unknown libpng error");
  png_longjmp(png, 1);
}

void onPngWarning(png_structp, png_const_charp) {}  // recoverable oddities (e.g. a bad CRC in an ancillary chunk)

/// The bytes libpng reads from, and how far it has read.
struct MemoryInput {
  const char* data;
  std::size_t size;
  std::size_t position;
};

void readFromMemory(png_structp png, png_bytep out, png_size_t count) {
  auto* input = static_cast<MemoryInput*>(png_get_io_ptr(png));
  if (count > input->size - input->position) png_error(png, "the file ends inside the image (truncated)");
  std::memcpy(out, input->data + input->position, count);
  input->position += count;
}

void appendToString(png_structp png, png_bytep data, png_size_t count) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), count);
}

void flushNothing(png_structp) {}

/// The image layout after the read transforms.
struct PngLayout {
  png_uint_32 cols, rows;
  int channels, bitDepth, colourType;
  png_size_t rowBytes;
};

/// Reads the header and sets the transforms to 8- or 16-bit samples in host byte order; false on a libpng error.
bool readHeader(png_structp png, png_infop info, PngLayout* layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  layout->colourType = png_get_color_type(png, info);
  if (layout->colourType == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (layout->colourType == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_bit_depth(png, info) == 16) png_set_swap(png);  // PNG is big-endian; FluoroCT runs on little-endian
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  layout->cols = png_get_image_width(png, info);
  layout->rows = png_get_image_height(png, info);
  layout->channels = png_get_channels(png, info);
  layout->bitDepth = png_get_bit_depth(png, info);
  layout->rowBytes = png_get_rowbytes(png, info);
  return true;
}

/// Decodes every row into `rowPointers`; false on a libpng error.
bool readRows(png_structp png, png_infop info, png_bytepp rowPointers) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rowPointers);
  png_read_end(png, nullptr);
  return true;
}

/// Writes a whole image with the given IHDR colour type and depth; false on a libpng error.
bool writeImage(png_structp png, png_infop info, png_uint_32 cols, png_uint_32 rows, int bitDepth, int colourType,
                png_bytepp rowPointers) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, cols, rows, bitDepth, colourType, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);  // fastest deflate: DRRs and overlays are written often and read locally
  png_write_info(png, info);
  if (bitDepth == 16) png_set_swap(png);
  png_write_image(png, rowPointers);
  png_write_end(png, nullptr);
  return true;
}

Result<std::string> encode(const std::uint8_t* pixels, int cols, int rows, int bitDepth, int colourType,
                           std::size_t rowBytes) {
  PngErrorText error;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, onPngError, onPngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    return fail("libpng could not start an encoder (out of memory?)");
  }
  std::string encoded;
  png_set_write_fn(png, &encoded, appendToString, flushNothing);
  std::vector<png_bytep> rowPointers(static_cast<std::size_t>(rows));
  for (int r = 0; r < rows; ++r) rowPointers[r] = const_cast<png_bytep>(pixels) + r * rowBytes;  // libpng reads only
  const bool ok = writeImage(png, info, static_cast<png_uint_32>(cols), static_cast<png_uint_32>(rows), bitDepth,
                             colourType, rowPointers.data());
  png_destroy_write_struct(&png, &info);
  if (!ok) return fail(fmt::format("libpng could not encode the image: {}", error.message));
  return encoded;
}

}  // namespace

Result<DecodedRaster> PngCodec::decode(std::string_view bytes, std::uint32_t maxSide, std::uint64_t maxPixels) {
  PngErrorText error;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, onPngError, onPngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return fail("libpng could not start a decoder (out of memory?)");
  }
  MemoryInput input{bytes.data(), bytes.size(), 0};
  png_set_read_fn(png, &input, readFromMemory);
  png_set_user_limits(png, maxSide, maxSide);
  PngLayout layout{};
  DecodedRaster raster;
  std::string refusal;
  bool ok = readHeader(png, info, &layout);
  if (ok && std::uint64_t{layout.cols} * layout.rows > maxPixels) {
    refusal = fmt::format("the PNG declares {} x {} pixels, more than FluoroCT decodes ({} at most)", layout.cols,
                          layout.rows, maxPixels);
  } else if (ok) {
    std::vector<png_byte> buffer(layout.rowBytes * layout.rows);
    std::vector<png_bytep> rowPointers(layout.rows);
    for (png_uint_32 r = 0; r < layout.rows; ++r) rowPointers[r] = buffer.data() + r * layout.rowBytes;
    ok = readRows(png, info, rowPointers.data());
    if (ok) {
      // After the transforms the rows hold exactly cols x channels samples of 1 or 2 bytes, back to back.
      raster.cols = static_cast<int>(layout.cols);
      raster.rows = static_cast<int>(layout.rows);
      raster.channels = layout.channels;
      raster.sampleType = layout.bitDepth == 16 ? RasterSampleType::UInt16 : RasterSampleType::UInt8;
      raster.samples.resize(std::size_t{layout.cols} * layout.rows * static_cast<std::size_t>(layout.channels));
      if (layout.bitDepth == 16) {
        for (std::size_t n = 0; n < raster.samples.size(); ++n) {
          std::uint16_t wide;
          std::memcpy(&wide, buffer.data() + 2 * n, 2);
          raster.samples[n] = wide;
        }
      } else {
        std::copy_n(buffer.begin(), raster.samples.size(), raster.samples.begin());
      }
      if (layout.colourType == PNG_COLOR_TYPE_PALETTE) raster.notes.push_back("palette expanded to RGB");
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (!refusal.empty()) return fail(refusal);
  if (!ok) return fail(fmt::format("libpng: {} (damaged or truncated PNG data)", error.message));
  return raster;
}

Result<std::string> PngCodec::encodeGrey16(const std::uint16_t* pixels, int cols, int rows) {
  return encode(reinterpret_cast<const std::uint8_t*>(pixels), cols, rows, 16, PNG_COLOR_TYPE_GRAY,
                2 * static_cast<std::size_t>(cols));
}

Result<std::string> PngCodec::encodeRgb8(const std::uint8_t* pixels, int cols, int rows) {
  return encode(pixels, cols, rows, 8, PNG_COLOR_TYPE_RGB, 3 * static_cast<std::size_t>(cols));
}

}  // namespace fct
