#pragma once
// DecodedRaster: the samples of a decoded PNG or TIFF as the file stores them (interleaved channels, unconverted
// values), before XrayImageFileReader turns them into one grey X-ray.

#include <string>
#include <vector>

namespace fct {

/// What one sample of a decoded image file was in the file.
enum class RasterSampleType { UInt8, UInt16, Float32 };

/// A decoded image: rows*cols pixels of `channels` interleaved samples, row 0 at the top.
struct DecodedRaster {
  int cols = 0;
  int rows = 0;
  int channels = 0;                              ///< 1 grey, 2 grey + alpha, 3 RGB, 4 RGB + alpha
  RasterSampleType sampleType = RasterSampleType::UInt8;
  std::vector<float> samples;                    ///< rows*cols*channels values, exactly the stored integers or floats
  std::vector<std::string> notes;                ///< conversions the decoder applied (e.g. a palette expanded)
};

}  // namespace fct
