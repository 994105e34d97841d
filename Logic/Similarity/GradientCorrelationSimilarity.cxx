#include "Similarity/GradientCorrelationSimilarity.h"

#include <cmath>

#include <fmt/format.h>

#include "Similarity/NccAccumulator.h"

namespace fct {
namespace {

/// Sobel derivative along columns at linear index i of a row-major image with `cols` columns.
inline float sobelX(const float* p, std::size_t i, std::size_t cols) {
  return (p[i - cols + 1] + 2.0f * p[i + 1] + p[i + cols + 1]) - (p[i - cols - 1] + 2.0f * p[i - 1] + p[i + cols - 1]);
}
/// Sobel derivative along rows.
inline float sobelY(const float* p, std::size_t i, std::size_t cols) {
  return (p[i + cols - 1] + 2.0f * p[i + cols] + p[i + cols + 1]) - (p[i - cols - 1] + 2.0f * p[i - cols] + p[i - cols + 1]);
}

}  // namespace

Result<GradientCorrelationSimilarity> GradientCorrelationSimilarity::create(const FloatImage& xray,
                                                                           const PixelIndexList& pixels) {
  GradientCorrelationSimilarity metric(xray.cols, xray.rows);
  const auto size = static_cast<std::int64_t>(xray.pixels.size());
  const auto cols = static_cast<std::size_t>(xray.cols);
  for (const std::int32_t index : pixels) {
    if (index < 0 || index >= size) {
      return fail(fmt::format("GC pixel index {} lies outside the {}x{} X-ray", index, xray.cols, xray.rows));
    }
    const int col = index % xray.cols;
    const int row = index / xray.cols;
    if (col == 0 || row == 0 || col == xray.cols - 1 || row == xray.rows - 1) continue;
    metric.m_pixels.push_back(index);
    metric.m_gxCentred.push_back(sobelX(xray.pixels.data(), static_cast<std::size_t>(index), cols));
    metric.m_gyCentred.push_back(sobelY(xray.pixels.data(), static_cast<std::size_t>(index), cols));
  }
  if (metric.m_pixels.empty()) {
    return fail(fmt::format("GC needs pixels with a full 3x3 neighbourhood; none of the {} given pixels has one",
                            pixels.size()));
  }
  metric.m_gxNorm = NccAccumulator::centreInPlace(metric.m_gxCentred.data(), metric.m_gxCentred.size());
  metric.m_gyNorm = NccAccumulator::centreInPlace(metric.m_gyCentred.data(), metric.m_gyCentred.size());
  if (!std::isfinite(metric.m_gxNorm) || !std::isfinite(metric.m_gyNorm)) {
    return fail("X-ray has non-finite values near the compared pixels; fix the X-ray before comparing");
  }
  Result<GradientCorrelationSimilarity> result(std::move(metric));
  if (result.value().m_gxNorm == 0.0 && result.value().m_gyNorm == 0.0) {
    result.addWarning("the X-ray has a constant gradient over the compared pixels; GC will be 0 for every pose");
  }
  return result;
}

double GradientCorrelationSimilarity::compare(const FloatImage& drr) const {
  const float* d = drr.pixels.data();
  const auto cols = static_cast<std::size_t>(drr.cols);
  const std::size_t n = m_pixels.size();
  const auto first = static_cast<std::size_t>(m_pixels[0]);
  NccAccumulator x(sobelX(d, first, cols));
  NccAccumulator y(sobelY(d, first, cols));
  for (std::size_t i = 0; i < n; ++i) {
    const auto p = static_cast<std::size_t>(m_pixels[i]);
    x.add(m_gxCentred[i], sobelX(d, p, cols));
    y.add(m_gyCentred[i], sobelY(d, p, cols));
  }
  return 0.5 * (x.correlation(m_gxNorm, n) + y.correlation(m_gyNorm, n));
}

}  // namespace fct
