#include "XrayPrep/XrayIntensityModel.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

namespace fct {

Result<LineIntegralImage> XrayIntensityModel::toLineIntegrals(const FloatImage& image, const ValidMask& mask) const {
  const IntensityModelOptions& o = m_options;
  if (!(o.referencePercentile > 0.0 && o.referencePercentile <= 100.0) ||
      !(o.floorFraction > 0.0 && o.floorFraction < 1.0)) {
    return fail(fmt::format("intensity model options out of range: reference percentile {} (0 < q <= 100), floor "
                            "fraction {} (0 < f < 1)",
                            o.referencePercentile, o.floorFraction));
  }
  if (mask.cols != image.cols || mask.rows != image.rows || mask.valid.size() != image.pixels.size()) {
    return fail(fmt::format("mask is {}x{} but the X-ray is {}x{}; build the mask for this image", mask.cols,
                            mask.rows, image.cols, image.rows));
  }
  std::vector<float> inField;
  inField.reserve(image.pixels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    if (!std::isfinite(image.pixels[i])) {
      return fail(fmt::format("X-ray pixel ({},{}) is not finite; cannot take its logarithm",
                              i % static_cast<std::size_t>(image.cols), i / static_cast<std::size_t>(image.cols)));
    }
    if (mask.valid[i]) inField.push_back(image.pixels[i]);
  }
  if (inField.empty()) return fail("the X-ray's mask excludes every pixel; nothing left to convert");

  const auto rank = static_cast<std::size_t>(
      std::min<double>(static_cast<double>(inField.size() - 1),
                       std::ceil(o.referencePercentile / 100.0 * static_cast<double>(inField.size())) - 1.0));
  std::nth_element(inField.begin(), inField.begin() + static_cast<std::ptrdiff_t>(rank), inField.end());
  const double reference = inField[rank];
  if (!(reference > 0.0)) {
    return fail(fmt::format("X-ray reference level (the {}th percentile of the field) is {}, not positive: the image "
                            "is black or not in the MONOCHROME2 intensity sense",
                            o.referencePercentile, reference));
  }

  LineIntegralImage out;
  out.referenceIntensity = reference;
  out.lineIntegrals = FloatImage::filled(image.cols, image.rows);
  const double floorIntensity = o.floorFraction * reference;
  const double logReference = std::log(reference);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    const double intensity = std::clamp<double>(image.pixels[i], floorIntensity, reference);
    out.lineIntegrals.pixels[i] = static_cast<float>(logReference - std::log(intensity));
  }
  return out;
}

}  // namespace fct
