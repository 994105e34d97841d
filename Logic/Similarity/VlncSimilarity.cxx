#include "Similarity/VlncSimilarity.h"

#include <cmath>

#include <fmt/format.h>

#include "Similarity/NccAccumulator.h"

namespace fct {

namespace {

/// The detector intensity relative to I0 of a line integral p: exp(-p).
float intensityOf(float lineIntegral) { return std::exp(-lineIntegral); }

}  // namespace

Result<VlncSimilarity> VlncSimilarity::create(const FloatImage& xray, const RoiSelection& selection,
                                              VlncDomain domain, const FloatImage* weightSource) {
  const int w = selection.windowSize;
  if (selection.windows.empty() || w <= 0) {
    return fail("VLNC needs at least one window; the ROI selection is empty (lower the threshold or raise the "
                "target fraction)");
  }
  if (weightSource && (weightSource->cols != xray.cols || weightSource->rows != xray.rows)) {
    return fail(fmt::format("VLNC window weights: the weight image is {}x{} but the X-ray {}x{}", weightSource->cols,
                            weightSource->rows, xray.cols, xray.rows));
  }
  VlncSimilarity metric(xray.cols, xray.rows);
  metric.m_domain = domain;
  const bool intensity = domain == VlncDomain::Intensity;
  metric.m_windowPixels = static_cast<std::size_t>(w) * w;
  std::vector<float> values(metric.m_windowPixels);
  std::vector<float> weightValues(weightSource ? metric.m_windowPixels : 0);
  PixelIndexList indices(metric.m_windowPixels);
  double varianceSum = 0.0;
  for (const RoiWindow& window : selection.windows) {
    if (window.col0 < 0 || window.row0 < 0 || window.col0 + w > xray.cols || window.row0 + w > xray.rows) {
      return fail(fmt::format("VLNC window at ({},{}) of size {} is not inside the {}x{} X-ray; select the ROIs on "
                              "this image",
                              window.col0, window.row0, w, xray.cols, xray.rows));
    }
    std::size_t k = 0;
    bool finite = true, weightsFinite = true;
    for (int r = window.row0; r < window.row0 + w; ++r) {
      for (int c = window.col0; c < window.col0 + w; ++c, ++k) {
        indices[k] = r * xray.cols + c;
        const float lineIntegral = xray.pixels[static_cast<std::size_t>(indices[k])];
        finite = finite && std::isfinite(lineIntegral);
        values[k] = intensity ? intensityOf(lineIntegral) : lineIntegral;
        if (weightSource) {
          const float weightLineIntegral = weightSource->pixels[static_cast<std::size_t>(indices[k])];
          weightsFinite = weightsFinite && std::isfinite(weightLineIntegral);
          weightValues[k] = intensity ? intensityOf(weightLineIntegral) : weightLineIntegral;
        }
      }
    }
    if (!finite) {
      return fail(fmt::format("X-ray has non-finite values in the window at ({},{})", window.col0, window.row0));
    }
    if (!weightsFinite) {
      return fail(fmt::format("VLNC window weights: the weight image has non-finite values in the window at ({},{})",
                              window.col0, window.row0));
    }
    const double norm = NccAccumulator::centreInPlace(values.data(), values.size());
    const double weightNorm =
        weightSource ? NccAccumulator::centreInPlace(weightValues.data(), weightValues.size()) : norm;
    if (norm == 0.0 || weightNorm == 0.0) continue;  // constant window: weight 0
    metric.m_pixels.insert(metric.m_pixels.end(), indices.begin(), indices.end());
    metric.m_xrayCentred.insert(metric.m_xrayCentred.end(), values.begin(), values.end());
    metric.m_xrayNorms.push_back(norm);
    metric.m_weights.push_back(weightNorm * weightNorm);  // n * variance; n is common to all windows
    varianceSum += weightNorm * weightNorm;
  }
  for (double& weight : metric.m_weights) weight /= varianceSum;
  Result<VlncSimilarity> result(std::move(metric));
  if (result.value().m_weights.empty()) {
    result.addWarning(weightSource ? "every VLNC window is constant in the X-ray or in the weight image; VLNC will "
                                     "be 0 for every pose"
                                   : "the X-ray is constant in every VLNC window; VLNC will be 0 for every pose");
  }
  return result;
}

double VlncSimilarity::compare(const FloatImage& drr) const {
  const float* d = drr.pixels.data();
  const std::size_t m = m_windowPixels;
  // The same sums in either domain; `toDomain` maps a DRR line integral to the compared value.
  const auto weightedSum = [&](auto toDomain) {
    double vlnc = 0.0;
    for (std::size_t window = 0; window < m_weights.size(); ++window) {
      const std::int32_t* index = m_pixels.data() + window * m;
      const float* x = m_xrayCentred.data() + window * m;
      NccAccumulator sums(toDomain(d[index[0]]));
      for (std::size_t i = 0; i < m; ++i) sums.add(x[i], toDomain(d[index[i]]));
      vlnc += m_weights[window] * sums.correlation(m_xrayNorms[window], m);
    }
    return vlnc;
  };
  const double vlnc = m_domain == VlncDomain::Intensity ? weightedSum([](float p) { return intensityOf(p); })
                                                        : weightedSum([](float p) { return p; });
  return std::clamp(vlnc, -1.0, 1.0);  // NaN stays NaN
}

}  // namespace fct
