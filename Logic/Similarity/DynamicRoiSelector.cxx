#include "Similarity/DynamicRoiSelector.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace fct {

Result<DynamicRoiSelector> DynamicRoiSelector::create(const FloatImage& image, const ValidMask& mask, int windowSize) {
  if (windowSize < 2 || windowSize > 64) {
    return fail(fmt::format("ROI window size {} out of range; use 2 to 64 pixels (the paper uses 7)", windowSize));
  }
  if (image.cols <= 0 || image.rows <= 0 || image.pixels.size() != static_cast<std::size_t>(image.cols) * image.rows ||
      mask.cols != image.cols || mask.rows != image.rows || mask.valid.size() != image.pixels.size()) {
    return fail(fmt::format("X-ray is {}x{} and its mask {}x{}; they must be the same non-empty size", image.cols,
                            image.rows, mask.cols, mask.rows));
  }
  // Variance of all valid pixels, two-pass for accuracy.
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    if (mask.valid[i]) {
      sum += image.pixels[i];
      ++count;
    }
  }
  if (count == 0) return fail("the X-ray's mask excludes every pixel; no ROI can be chosen");
  const double mean = sum / static_cast<double>(count);
  double squares = 0.0;
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    if (mask.valid[i]) squares += (image.pixels[i] - mean) * (image.pixels[i] - mean);
  }
  const double globalVariance = squares / static_cast<double>(count);
  if (!(globalVariance > 0.0) || !std::isfinite(globalVariance)) {
    return fail(fmt::format("X-ray is constant (or not finite) over its {} valid pixels (variance {}); there is no "
                            "structure to register to",
                            count, globalVariance));
  }

  DynamicRoiSelector selector;
  selector.m_imageCols = image.cols;
  selector.m_windowSize = windowSize;
  selector.m_validPixelCount = count;
  const int w = windowSize;
  const double n = static_cast<double>(w) * w;
  for (int row0 = 0; row0 + w <= image.rows; row0 += w) {
    for (int col0 = 0; col0 + w <= image.cols; col0 += w) {
      bool allValid = true;
      double s = 0.0;
      for (int r = row0; r < row0 + w && allValid; ++r) {
        const std::size_t line = static_cast<std::size_t>(r) * image.cols;
        for (int c = col0; c < col0 + w; ++c) {
          if (!mask.valid[line + c]) {
            allValid = false;
            break;
          }
          s += image.pixels[line + c];
        }
      }
      if (!allValid) continue;
      const double windowMean = s / n;
      double ss = 0.0;
      for (int r = row0; r < row0 + w; ++r) {
        const float* line = image.pixels.data() + static_cast<std::size_t>(r) * image.cols;
        for (int c = col0; c < col0 + w; ++c) ss += (line[c] - windowMean) * (line[c] - windowMean);
      }
      const double variance = ss / n;
      selector.m_byVariance.push_back(
          RoiWindow{col0, row0, static_cast<float>(variance), static_cast<float>(variance / globalVariance)});
    }
  }
  if (selector.m_byVariance.empty()) {
    return fail(fmt::format("no complete {0}x{0} window of valid pixels in the {1}x{2} X-ray; the mask leaves too "
                            "little, or use a smaller window",
                            w, image.cols, image.rows));
  }
  std::stable_sort(selector.m_byVariance.begin(), selector.m_byVariance.end(),
                   [](const RoiWindow& a, const RoiWindow& b) { return a.normalizedVariance > b.normalizedVariance; });
  return selector;
}

RoiSelection DynamicRoiSelector::selectTop(std::size_t count) const {
  RoiSelection selection;
  selection.windowSize = m_windowSize;
  selection.windows.assign(m_byVariance.begin(), m_byVariance.begin() + static_cast<std::ptrdiff_t>(count));
  selection.threshold = selection.windows.back().normalizedVariance;
  std::sort(selection.windows.begin(), selection.windows.end(), [](const RoiWindow& a, const RoiWindow& b) {
    return a.row0 != b.row0 ? a.row0 < b.row0 : a.col0 < b.col0;
  });
  const int w = m_windowSize;
  selection.pixels.reserve(count * static_cast<std::size_t>(w) * w);
  for (const RoiWindow& window : selection.windows) {
    for (int r = window.row0; r < window.row0 + w; ++r) {
      for (int c = window.col0; c < window.col0 + w; ++c) selection.pixels.push_back(r * m_imageCols + c);
    }
  }
  selection.keptFraction = static_cast<double>(selection.pixels.size()) / static_cast<double>(m_validPixelCount);
  return selection;
}

Result<RoiSelection> DynamicRoiSelector::selectAboveThreshold(double threshold) const {
  if (!std::isfinite(threshold)) return fail("ROI variance threshold is not a finite number");
  const auto end = std::partition_point(m_byVariance.begin(), m_byVariance.end(), [threshold](const RoiWindow& w) {
    return w.normalizedVariance >= threshold;
  });
  const auto count = static_cast<std::size_t>(end - m_byVariance.begin());
  if (count == 0) {
    return fail(fmt::format("no ROI window has a normalized variance >= {} (the highest is {:.3g}); lower the "
                            "threshold or select by fraction",
                            threshold, m_byVariance.front().normalizedVariance));
  }
  RoiSelection selection = selectTop(count);
  selection.threshold = threshold;
  return selection;
}

Result<RoiSelection> DynamicRoiSelector::selectFraction(double targetFraction) const {
  if (!(targetFraction > 0.0 && targetFraction <= 1.0)) {
    return fail(fmt::format("ROI target fraction {} out of range; use 0 < fraction <= 1 (the paper: 0.10 to 0.15)",
                            targetFraction));
  }
  const double windowPixels = static_cast<double>(m_windowSize) * m_windowSize;
  const auto wanted = static_cast<std::size_t>(std::lround(targetFraction * m_validPixelCount / windowPixels));
  return selectTop(std::clamp<std::size_t>(wanted, 1, m_byVariance.size()));
}

RoiSelection DynamicRoiSelector::selectAll() const { return selectTop(m_byVariance.size()); }

}  // namespace fct
