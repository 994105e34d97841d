#include "XrayPrep/MetalMaskReview.h"

#include <fmt/format.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace fct {

namespace {

/// The median of `values` (reordered; not empty).
float medianOf(std::vector<float>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// The DRR times the median ratio X-ray / DRR over the pixels valid in `mask` where the DRR is above a quarter of its
/// largest value there; the DRR itself when no such pixel has a positive ratio.
FloatImage atXrayScale(const FloatImage& drr, const FloatImage& xray, const ValidMask& mask) {
  float largest = 0.0f;
  for (std::size_t i = 0; i < drr.pixels.size(); ++i) {
    if (mask.valid[i] && std::isfinite(drr.pixels[i])) largest = std::max(largest, drr.pixels[i]);
  }
  std::vector<float> ratios;
  for (std::size_t i = 0; i < drr.pixels.size(); ++i) {
    if (mask.valid[i] && drr.pixels[i] > 0.25f * largest && xray.pixels[i] > 0.0f) {
      ratios.push_back(xray.pixels[i] / drr.pixels[i]);
    }
  }
  FloatImage scaled = drr;
  if (ratios.empty() || !(largest > 0.0f)) return scaled;
  const float gain = medianOf(ratios);
  for (float& value : scaled.pixels) value *= gain;
  return scaled;
}

}  // namespace

Result<MetalMaskReviewOutcome> MetalMaskReview::review(const ValidMask& fieldMask, const ValidMask& xrayMask,
                                                       const FloatImage& xrayLineIntegrals,
                                                       const FloatImage& drrLineIntegrals,
                                                       const ValidMask& coveredMask, double pixelSpacing_mm) const {
  const int cols = fieldMask.cols, rows = fieldMask.rows;
  const auto count = static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows);
  if (xrayMask.cols != cols || xrayMask.rows != rows || drrLineIntegrals.cols != cols ||
      drrLineIntegrals.rows != rows || xrayLineIntegrals.cols != cols || xrayLineIntegrals.rows != rows ||
      fieldMask.valid.size() != count || xrayMask.valid.size() != count || drrLineIntegrals.pixels.size() != count ||
      xrayLineIntegrals.pixels.size() != count || coveredMask.cols != cols || coveredMask.rows != rows ||
      coveredMask.valid.size() != count) {
    return fail(fmt::format("metal mask review: the field mask is {}x{}, the metal mask {}x{}, the X-ray {}x{}, the "
                            "DRR {}x{} and the covered mask {}x{}; all must be the X-ray's size",
                            cols, rows, xrayMask.cols, xrayMask.rows, xrayLineIntegrals.cols, xrayLineIntegrals.rows,
                            drrLineIntegrals.cols, drrLineIntegrals.rows, coveredMask.cols, coveredMask.rows));
  }
  MetalMaskReviewOutcome outcome;
  outcome.mask = xrayMask;
  std::vector<std::uint8_t> metal(count, 0);
  for (std::size_t i = 0; i < count; ++i) {
    if (xrayMask.valid[i] && !fieldMask.valid[i]) {
      return fail("metal mask review: the metal mask has valid pixels outside the field; give the masks in order");
    }
    metal[i] = fieldMask.valid[i] && !xrayMask.valid[i] ? 1 : 0;
  }
  const FloatImage drr = atXrayScale(drrLineIntegrals, xrayLineIntegrals, xrayMask);
  const double spacing_mm = pixelSpacing_mm > 0.0 ? pixelSpacing_mm : m_options.assumedPixelSpacing_mm;
  const int ring_px = std::max(2, static_cast<int>(std::lround(kRing_mm / spacing_mm)));
  const float standOut = static_cast<float>(0.5 * m_options.minExcess);
  const int minUnexplained_px =
      std::max(1, static_cast<int>(std::lround(kMinUnexplained_mm2 / (spacing_mm * spacing_mm))));
  const int width_px = std::max(2, static_cast<int>(std::lround(kMinUnexplainedWidth_mm / spacing_mm)));
  try {
    const cv::Mat metalImage(rows, cols, CV_8U, metal.data());
    cv::Mat labels;
    cv::Mat stats, centroids;
    const int labelCount = cv::connectedComponentsWithStats(metalImage, labels, stats, centroids, 8, CV_32S);
    const cv::Mat widthElement = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(width_px, width_px));
    const cv::Mat ringElement =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * ring_px + 1, 2 * ring_px + 1));
    for (int label = 1; label < labelCount; ++label) {
      // The piece and its ring, within the piece's box grown by the ring's width.
      const cv::Rect box = cv::Rect(stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
                                    stats.at<int>(label, cv::CC_STAT_WIDTH), stats.at<int>(label, cv::CC_STAT_HEIGHT));
      const cv::Rect around = (box + cv::Size(2 * ring_px, 2 * ring_px) - cv::Point(ring_px, ring_px)) &
                              cv::Rect(0, 0, cols, rows);
      const cv::Mat piece = labels(around) == label;
      cv::Mat ring;
      cv::dilate(piece, ring, ringElement);
      // Linear index in the image of pixel (x, y) of the box.
      const auto indexOf = [&around, cols](int x, int y) {
        return static_cast<std::size_t>(around.y + y) * static_cast<std::size_t>(cols) +
               static_cast<std::size_t>(around.x + x);
      };
      std::vector<cv::Point> pieceCovered;
      std::vector<float> ringXray, ringResidual;
      std::size_t piecePixels = 0;
      for (int y = 0; y < around.height; ++y) {
        for (int x = 0; x < around.width; ++x) {
          const std::size_t i = indexOf(x, y);
          const bool covered = coveredMask.valid[i] && drr.pixels[i] > kCoveredLineIntegral;
          if (piece.at<std::uint8_t>(y, x)) {
            ++piecePixels;
            if (covered) pieceCovered.emplace_back(x, y);
          } else if (ring.at<std::uint8_t>(y, x) && covered && xrayMask.valid[i]) {
            ringXray.push_back(xrayLineIntegrals.pixels[i]);
            ringResidual.push_back(xrayLineIntegrals.pixels[i] - drr.pixels[i]);
          }
        }
      }
      // Anatomy: judged, and no patch of the piece's core is left unexplained (a patch at least kMinUnexplainedWidth_mm
      // thick and kMinUnexplained_mm2 large). Anything else stays excluded whole: a tool the detector's growth joined
      // to a bone rim included.
      bool anatomy = false;
      if (!ringXray.empty() &&
          static_cast<double>(pieceCovered.size()) >= kMinCovered * static_cast<double>(piecePixels)) {
        const float ringLevel = medianOf(ringXray);
        const float ringResidualLevel = medianOf(ringResidual);
        cv::Mat unexplained = cv::Mat::zeros(around.size(), CV_8U);
        bool core = false;
        for (const cv::Point& pixel : pieceCovered) {
          const std::size_t i = indexOf(pixel.x, pixel.y);
          if (xrayLineIntegrals.pixels[i] - ringLevel <= standOut) continue;
          core = true;
          if (xrayLineIntegrals.pixels[i] - drr.pixels[i] - ringResidualLevel > standOut) {
            unexplained.at<std::uint8_t>(pixel) = 1;
          }
        }
        // Slivers thinner than kMinUnexplainedWidth_mm (a bone edge a pixel or two off) are not a tool's shadow.
        cv::morphologyEx(unexplained, unexplained, cv::MORPH_OPEN, widthElement);
        cv::Mat patches, patchStats, patchCentroids;
        const int patchCount = cv::connectedComponentsWithStats(unexplained, patches, patchStats, patchCentroids, 8);
        bool tool = false;
        for (int patch = 1; patch < patchCount && !tool; ++patch) {
          tool = patchStats.at<int>(patch, cv::CC_STAT_AREA) >= minUnexplained_px;
        }
        anatomy = core && !tool;
      }
      (anatomy ? outcome.piecesGivenBack : outcome.piecesKept) += 1;
      for (int y = 0; y < around.height; ++y) {
        for (int x = 0; x < around.width; ++x) {
          if (!piece.at<std::uint8_t>(y, x)) continue;
          if (anatomy) {
            outcome.mask.valid[indexOf(x, y)] = 1;
          } else {
            ++outcome.metalPixelCount;
          }
        }
      }
    }
  } catch (const cv::Exception& e) {
    return fail(fmt::format("metal mask review: OpenCV error: {}", e.what()));
  }
  return outcome;
}

}  // namespace fct
