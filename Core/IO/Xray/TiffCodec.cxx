#include "IO/Xray/TiffCodec.h"

#include <fmt/core.h>
#include <tiffio.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

namespace fct {

namespace {

/// The bytes libtiff reads (`input`) or writes (`output`), and its position in them.
struct MemoryStream {
  std::string_view input;
  std::string* output = nullptr;
  std::uint64_t position = 0;

  std::uint64_t size() const { return output ? output->size() : input.size(); }
};

tmsize_t readProc(thandle_t handle, void* buffer, tmsize_t count) {
  auto* s = static_cast<MemoryStream*>(handle);
  if (count < 0 || s->output) return -1;
  const std::uint64_t available = s->position < s->input.size() ? s->input.size() - s->position : 0;
  const std::uint64_t n = std::min<std::uint64_t>(static_cast<std::uint64_t>(count), available);
  std::memcpy(buffer, s->input.data() + s->position, n);
  s->position += n;
  return static_cast<tmsize_t>(n);
}

tmsize_t writeProc(thandle_t handle, void* buffer, tmsize_t count) {
  auto* s = static_cast<MemoryStream*>(handle);
  if (count < 0 || !s->output) return -1;
  const std::uint64_t end = s->position + static_cast<std::uint64_t>(count);
  if (end > s->output->size()) s->output->resize(end);
  std::memcpy(s->output->data() + s->position, buffer, static_cast<std::size_t>(count));
  s->position = end;
  return count;
}

toff_t seekProc(thandle_t handle, toff_t offset, int whence) {
  auto* s = static_cast<MemoryStream*>(handle);
  const std::uint64_t base = whence == SEEK_CUR ? s->position : whence == SEEK_END ? s->size() : 0;
  // libtiff passes negative offsets as wrapped unsigned values; a position outside 0..2^62 is refused.
  const std::uint64_t target = base + offset;
  if (target > (std::uint64_t{1} << 62)) return static_cast<toff_t>(-1);
  s->position = target;
  return target;
}

int closeProc(thandle_t) { return 0; }
toff_t sizeProc(thandle_t handle) { return static_cast<MemoryStream*>(handle)->size(); }
int mapProc(thandle_t, void**, toff_t*) { return 0; }  // no mapping: libtiff reads through readProc
void unmapProc(thandle_t, void*, toff_t) {}

/// Keeps libtiff's first error message (the cause; later ones follow from it).
int onTiffError(TIFF*, void* user, const char* module, const char* format, va_list args) {
  auto* text = static_cast<std::string*>(user);
  if (!text->empty()) return 1;
  char message[512];
  std::vsnprintf(message, sizeof message, format, args);
  *text = module && *module ? fmt::format("{}: {}", module, message) : std::string(message);
  return 1;  // handled: nothing printed to stderr
}

int onTiffWarning(TIFF*, void*, const char*, const char*, va_list) { return 1; }  // unknown tags and the like

struct TiffCloser {
  void operator()(TIFF* tif) const { TIFFClose(tif); }
};
using TiffHandle = std::unique_ptr<TIFF, TiffCloser>;

/// Opens `stream` for reading ("r") or writing ("w") with FluoroCT's handlers and a limit on libtiff's single
/// allocations (0: none).
TiffHandle open(MemoryStream& stream, const char* mode, std::string& error, std::int64_t maxBytes) {
  TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
  if (!options) return nullptr;
  TIFFOpenOptionsSetMaxSingleMemAlloc(options, maxBytes);
  TIFFOpenOptionsSetErrorHandlerExtR(options, onTiffError, &error);
  TIFFOpenOptionsSetWarningHandlerExtR(options, onTiffWarning, nullptr);
  TIFF* tif = TIFFClientOpenExt("image", mode, &stream, readProc, writeProc, seekProc, closeProc, sizeProc, mapProc,
                                unmapProc, options);
  TIFFOpenOptionsFree(options);
  return TiffHandle(tif);
}

/// Sample `index` of a decoded row or tile, as a float.
float sampleAt(const std::uint8_t* data, std::size_t index, RasterSampleType type) {
  switch (type) {
    case RasterSampleType::UInt8: return data[index];
    case RasterSampleType::UInt16: {
      std::uint16_t v;
      std::memcpy(&v, data + 2 * index, 2);
      return v;
    }
    case RasterSampleType::Float32: {
      float v;
      std::memcpy(&v, data + 4 * index, 4);
      return v;
    }
  }
  return 0.0f;
}

/// The fields of the first directory that decoding needs.
struct TiffLayout {
  std::uint32_t cols = 0, rows = 0;
  std::uint16_t bitsPerSample = 1, samplesPerPixel = 1, sampleFormat = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG;
  std::uint16_t photometric = PHOTOMETRIC_MINISBLACK;
  RasterSampleType type = RasterSampleType::UInt8;
  int channels = 1;      ///< channels of the raster
  int fileSamples = 1;   ///< samples read per pixel (1 for a palette index)
};

Result<TiffLayout> readLayout(TIFF* tif, std::uint32_t maxSide, std::uint64_t maxPixels) {
  TiffLayout l;
  if (!TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &l.cols) || !TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &l.rows) || l.cols == 0 ||
      l.rows == 0) {
    return fail("the TIFF directory has no image width or height");
  }
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &l.bitsPerSample);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &l.samplesPerPixel);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &l.sampleFormat);
  TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &l.planar);
  if (!TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &l.photometric)) {
    l.photometric = l.samplesPerPixel >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK;
  }
  const char* kind = l.sampleFormat == SAMPLEFORMAT_INT ? "signed integer" : l.sampleFormat == SAMPLEFORMAT_IEEEFP ? "float"
                                                                                                                     : "unsigned integer";
  if (l.sampleFormat == SAMPLEFORMAT_UINT && l.bitsPerSample == 8) {
    l.type = RasterSampleType::UInt8;
  } else if (l.sampleFormat == SAMPLEFORMAT_UINT && l.bitsPerSample == 16) {
    l.type = RasterSampleType::UInt16;
  } else if (l.sampleFormat == SAMPLEFORMAT_IEEEFP && l.bitsPerSample == 32) {
    l.type = RasterSampleType::Float32;
  } else {
    return fail(fmt::format("unsupported pixel type ({}-bit {} samples); use unsigned 8- or 16-bit grey or float32 TIFF",
                            l.bitsPerSample, kind));
  }
  if (l.samplesPerPixel == 0) return fail("the TIFF declares 0 samples per pixel");
  switch (l.photometric) {
    case PHOTOMETRIC_MINISBLACK:
    case PHOTOMETRIC_MINISWHITE:
      if (l.photometric == PHOTOMETRIC_MINISWHITE && l.type == RasterSampleType::Float32) {
        return fail("unsupported pixel type (float32 stored white-is-zero); store float images black-is-zero");
      }
      l.channels = l.fileSamples = l.samplesPerPixel == 1 ? 1 : 2;
      break;
    case PHOTOMETRIC_RGB:
      if (l.samplesPerPixel < 3) return fail(fmt::format("an RGB TIFF with {} samples per pixel", l.samplesPerPixel));
      l.channels = l.fileSamples = l.samplesPerPixel == 3 ? 3 : 4;
      break;
    case PHOTOMETRIC_PALETTE:
      if (l.type != RasterSampleType::UInt8 || l.samplesPerPixel != 1) {
        return fail("unsupported pixel type (a palette TIFF other than 8-bit indices)");
      }
      l.channels = 3;
      l.fileSamples = 1;
      break;
    default:
      return fail(fmt::format("unsupported pixel type (photometric interpretation {}: CMYK, YCbCr, Lab or another colour "
                              "space); use grey or RGB",
                              l.photometric));
  }
  if (l.cols > maxSide || l.rows > maxSide || std::uint64_t{l.cols} * l.rows > maxPixels) {
    return fail(fmt::format("the TIFF declares {} x {} pixels, more than FluoroCT decodes ({} a side, {} in all at most)",
                            l.cols, l.rows, maxSide, maxPixels));
  }
  return l;
}

/// Copies `count` pixels of one row or tile row (`data`, holding `stride` samples per pixel) into the raster's row
/// `row` from column `col`, channel `channel` onward (`samples` channels from each pixel).
void copyPixels(const std::uint8_t* data, int stride, int samples, const TiffLayout& l, std::uint32_t row,
                std::uint32_t col, std::uint32_t count, int channel, DecodedRaster& raster) {
  float* out = raster.samples.data() + (std::size_t{row} * l.cols + col) * static_cast<std::size_t>(l.channels);
  for (std::uint32_t x = 0; x < count; ++x) {
    for (int s = 0; s < samples; ++s) {
      out[std::size_t{x} * l.channels + channel + s] = sampleAt(data, std::size_t{x} * stride + s, l.type);
    }
  }
}

/// Reads every pixel (strips or tiles, interleaved or planar) into `raster`; fails with libtiff's message.
Status readPixels(TIFF* tif, const TiffLayout& l, DecodedRaster& raster, const std::string& error) {
  const bool planar = l.planar == PLANARCONFIG_SEPARATE && l.samplesPerPixel > 1;
  const int planes = planar ? l.fileSamples : 1;
  const int stride = planar ? 1 : l.samplesPerPixel;   // samples per pixel in one decoded buffer
  const int samples = planar ? 1 : l.fileSamples;      // of which the raster keeps
  auto failed = [&](const char* what) {
    return fail(fmt::format("libtiff cannot decode the {}: {} (damaged or truncated TIFF data)", what,
                            error.empty() ? "no reason given" : error));
  };
  if (TIFFIsTiled(tif)) {
    std::uint32_t tileCols = 0, tileRows = 0;
    TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tileCols);
    TIFFGetField(tif, TIFFTAG_TILELENGTH, &tileRows);
    const tmsize_t tileBytes = TIFFTileSize(tif), tileRowBytes = TIFFTileRowSize(tif);
    if (tileCols == 0 || tileRows == 0 || tileRowBytes <= 0 || tileBytes < tileRowBytes * static_cast<tmsize_t>(tileRows) ||
        static_cast<std::size_t>(tileRowBytes) < std::size_t{tileCols} * stride * (l.bitsPerSample / 8)) {
      return failed("tile layout");
    }
    std::vector<std::uint8_t> tile(static_cast<std::size_t>(tileBytes));
    const auto rowBytes = static_cast<std::size_t>(tileRowBytes);
    for (int p = 0; p < planes; ++p) {
      for (std::uint32_t y = 0; y < l.rows; y += tileRows) {
        for (std::uint32_t x = 0; x < l.cols; x += tileCols) {
          if (TIFFReadTile(tif, tile.data(), x, y, 0, static_cast<std::uint16_t>(p)) < 0) return failed("tiles");
          const std::uint32_t count = std::min(tileCols, l.cols - x);
          for (std::uint32_t ty = 0; ty < tileRows && y + ty < l.rows; ++ty) {
            copyPixels(tile.data() + ty * rowBytes, stride, samples, l, y + ty, x, count, p, raster);
          }
        }
      }
    }
  } else {
    const tmsize_t lineBytes = TIFFScanlineSize(tif);
    if (lineBytes <= 0) return failed("strip layout");
    std::vector<std::uint8_t> line(static_cast<std::size_t>(lineBytes));
    if (line.size() < std::size_t{l.cols} * stride * (l.bitsPerSample / 8)) return failed("strip layout");
    for (int p = 0; p < planes; ++p) {
      for (std::uint32_t y = 0; y < l.rows; ++y) {
        if (TIFFReadScanline(tif, line.data(), y, static_cast<std::uint16_t>(p)) < 0) return failed("rows");
        copyPixels(line.data(), stride, samples, l, y, 0, l.cols, p, raster);
      }
    }
  }
  return Ok{};
}

/// Replaces 8-bit palette indices (channel 0 of every pixel) by their RGB colours.
Status expandPalette(TIFF* tif, DecodedRaster& raster) {
  std::uint16_t *red = nullptr, *green = nullptr, *blue = nullptr;
  if (!TIFFGetField(tif, TIFFTAG_COLORMAP, &red, &green, &blue)) return fail("a palette TIFF without a colour map");
  // Colour maps are 16-bit; some old writers stored 8-bit values in them.
  bool eightBit = true;
  for (int i = 0; i < 256; ++i) eightBit = eightBit && red[i] < 256 && green[i] < 256 && blue[i] < 256;
  const int shift = eightBit ? 0 : 8;
  for (std::size_t n = 0; n < raster.samples.size(); n += 3) {
    const auto index = static_cast<std::size_t>(raster.samples[n]);
    raster.samples[n] = static_cast<float>(red[index] >> shift);
    raster.samples[n + 1] = static_cast<float>(green[index] >> shift);
    raster.samples[n + 2] = static_cast<float>(blue[index] >> shift);
  }
  raster.notes.push_back("palette expanded to RGB");
  return Ok{};
}

}  // namespace

Result<DecodedRaster> TiffCodec::decode(std::string_view bytes, std::uint32_t maxSide, std::uint64_t maxPixels) {
  MemoryStream stream;
  stream.input = bytes;
  std::string error;
  const auto maxAllocation = static_cast<std::int64_t>(std::min<std::uint64_t>(maxPixels, std::uint64_t{1} << 40) * 16);
  TiffHandle tif = open(stream, "rm", error, maxAllocation);
  if (!tif) {
    return fail(fmt::format("libtiff: {} (damaged or truncated TIFF data)", error.empty() ? "not a readable TIFF" : error));
  }
  auto layout = readLayout(tif.get(), maxSide, maxPixels);
  if (!layout) return fail(layout.error());
  const TiffLayout& l = layout.value();
  DecodedRaster raster;
  raster.cols = static_cast<int>(l.cols);
  raster.rows = static_cast<int>(l.rows);
  raster.channels = l.channels;
  raster.sampleType = l.photometric == PHOTOMETRIC_PALETTE ? RasterSampleType::UInt8 : l.type;
  raster.samples.assign(std::size_t{l.cols} * l.rows * static_cast<std::size_t>(l.channels), 0.0f);
  if (Status read = readPixels(tif.get(), l, raster, error); !read) return fail(read.error());
  if (l.photometric == PHOTOMETRIC_PALETTE) {
    if (Status expanded = expandPalette(tif.get(), raster); !expanded) return fail(expanded.error());
  }
  if (l.photometric == PHOTOMETRIC_MINISWHITE) {
    const float top = l.type == RasterSampleType::UInt8 ? 255.0f : 65535.0f;
    for (std::size_t n = 0; n < raster.samples.size(); n += static_cast<std::size_t>(l.channels)) {
      raster.samples[n] = top - raster.samples[n];
    }
    raster.notes.push_back("stored white-is-zero; flipped to black-is-zero");
  }
  return raster;
}

Result<std::string> TiffCodec::encodeFloat32(const float* pixels, int cols, int rows) {
  std::string encoded;
  MemoryStream stream;
  stream.output = &encoded;
  std::string error;
  TiffHandle tif = open(stream, "w", error, 0);
  if (!tif) return fail(fmt::format("libtiff could not start an encoder: {}", error));
  TIFF* t = tif.get();
  TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(cols));
  TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(rows));
  TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 32);
  TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
  TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_IEEEFP);
  TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
  TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, TIFFDefaultStripSize(t, 0));
  for (int r = 0; r < rows; ++r) {
    if (TIFFWriteScanline(t, const_cast<float*>(pixels + static_cast<std::size_t>(r) * cols), static_cast<std::uint32_t>(r),
                          0) < 0) {
      return fail(fmt::format("libtiff could not encode row {}: {}", r, error));
    }
  }
  tif.reset();  // TIFFClose writes the directory
  if (!error.empty()) return fail(fmt::format("libtiff could not finish the file: {}", error));
  return encoded;
}

}  // namespace fct
