#include "Similarity/NccSimilarity.h"

#include <cmath>

#include <fmt/format.h>

#include "Similarity/NccAccumulator.h"

namespace fct {

Result<NccSimilarity> NccSimilarity::create(const FloatImage& xray, PixelIndexList pixels) {
  if (pixels.empty()) return fail("NCC needs at least one pixel to compare; the pixel set is empty");
  const auto size = static_cast<std::int64_t>(xray.pixels.size());
  NccSimilarity metric(xray.cols, xray.rows);
  metric.m_xrayCentred.resize(pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    if (pixels[i] < 0 || pixels[i] >= size) {
      return fail(fmt::format("NCC pixel index {} lies outside the {}x{} X-ray", pixels[i], xray.cols, xray.rows));
    }
    metric.m_xrayCentred[i] = xray.pixels[static_cast<std::size_t>(pixels[i])];
    if (!std::isfinite(metric.m_xrayCentred[i])) {
      return fail(fmt::format("X-ray pixel index {} is not finite; fix the X-ray before comparing", pixels[i]));
    }
  }
  metric.m_pixels = std::move(pixels);
  metric.m_xrayNorm = NccAccumulator::centreInPlace(metric.m_xrayCentred.data(), metric.m_xrayCentred.size());
  Result<NccSimilarity> result(std::move(metric));
  if (result.value().m_xrayNorm == 0.0) {
    result.addWarning("the X-ray is constant over the compared pixels; NCC will be 0 for every pose");
  }
  return result;
}

double NccSimilarity::compare(const FloatImage& drr) const {
  const float* d = drr.pixels.data();
  const std::int32_t* index = m_pixels.data();
  const float* x = m_xrayCentred.data();
  const std::size_t n = m_pixels.size();
  NccAccumulator sums(d[index[0]]);
  for (std::size_t i = 0; i < n; ++i) sums.add(x[i], d[index[i]]);
  return sums.correlation(m_xrayNorm, n);
}

}  // namespace fct
