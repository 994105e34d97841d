#include "XrayPrep/MetalMaskDetector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <tbb/parallel_invoke.h>

#include "XrayPrep/DiscErosion.h"

namespace fct {

namespace {

constexpr float kHigh = std::numeric_limits<float>::max();
/// The dilation covers at least the blurred edge of a shadow (PSF and pixel phase), whatever the pixel size.
constexpr int kMinDilation_px = 3;

/// Grey-level opening of `p` (invalid pixels hold kHigh) with a square window of `side` px, over the valid pixels
/// only: invalid pixels never win the erosion (+max) nor, where the whole erosion window was invalid, the dilation.
cv::Mat validOpening(const cv::Mat& p, int side) {
  const cv::Mat window = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side | 1, side | 1));
  cv::Mat background;
  cv::erode(p, background, window, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(kHigh));
  background.setTo(cv::Scalar(-kHigh), background == kHigh);
  cv::dilate(background, background, window, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(-kHigh));
  return background;
}

/// Dilation of a 0/nonzero mask by a square of radius `radius_px`.
cv::Mat grown(const cv::Mat& mask, int radius_px) {
  cv::Mat out;
  const int side = 2 * radius_px + 1;
  cv::dilate(mask, out, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
  return out;
}

/// Shape and contrast of one connected piece of candidate pixels.
struct Piece {
  std::vector<cv::Point> pixels;
  double wideExcessSum = 0.0;
  double contrastRatioSum = 0.0;
};

/// Sagitta in px of a parabola fitted (least squares) to the piece's pixels across its fitted straight axis, over the
/// piece's length: 0 for a straight bar of any width, the bow of an arc.
double sagitta_px(const std::vector<cv::Point>& pixels) {
  if (pixels.size() < 3) return 0.0;
  cv::Vec4f line;
  cv::fitLine(pixels, line, cv::DIST_L2, 0, 0.01, 0.01);
  const int n = static_cast<int>(pixels.size());
  cv::Mat design(n, 3, CV_64F);
  cv::Mat across(n, 1, CV_64F);
  double tMin = std::numeric_limits<double>::max();
  double tMax = std::numeric_limits<double>::lowest();
  for (int i = 0; i < n; ++i) {
    const double dx = pixels[static_cast<std::size_t>(i)].x - line[2];
    const double dy = pixels[static_cast<std::size_t>(i)].y - line[3];
    const double t = dx * line[0] + dy * line[1];
    design.at<double>(i, 0) = t * t;
    design.at<double>(i, 1) = t;
    design.at<double>(i, 2) = 1.0;
    across.at<double>(i) = -dx * line[1] + dy * line[0];
    tMin = std::min(tMin, t);
    tMax = std::max(tMax, t);
  }
  cv::Mat coefficients;
  if (!cv::solve(design, across, coefficients, cv::DECOMP_SVD)) return 0.0;
  const double halfLength = 0.5 * (tMax - tMin);
  return std::abs(coefficients.at<double>(0)) * halfLength * halfLength;
}

/// The straight bars inside a piece that is not straight as a whole (a K-wire crossing a screw, a wire over a bone
/// rim): the pixels within `halfWidth_px` of each line segment of at least `minLength_px` that a probabilistic Hough
/// transform finds among the piece's pixels. Bars may share pixels.
std::vector<std::vector<cv::Point>> straightBars(const std::vector<cv::Point>& pixels, double minLength_px,
                                                 double halfWidth_px) {
  const cv::Rect box = cv::boundingRect(pixels);
  cv::Mat local = cv::Mat::zeros(box.height, box.width, CV_8U);
  for (const cv::Point& pixel : pixels) local.at<std::uint8_t>(pixel - box.tl()) = 255;
  std::vector<cv::Vec4i> segments;
  cv::HoughLinesP(local, segments, 1.0, CV_PI / 180.0, std::max(2, static_cast<int>(minLength_px / 2.0)), minLength_px,
                  2.0);
  std::vector<std::vector<cv::Point>> bars;
  for (const cv::Vec4i& segment : segments) {
    const cv::Point2d a(segment[0] + box.x, segment[1] + box.y);
    const cv::Point2d b(segment[2] + box.x, segment[3] + box.y);
    const cv::Point2d ab = b - a;
    const double lengthSquared = std::max(1e-12, ab.dot(ab));
    std::vector<cv::Point> bar;
    for (const cv::Point& pixel : pixels) {
      const cv::Point2d ap = cv::Point2d(pixel) - a;
      const double t = std::clamp(ap.dot(ab) / lengthSquared, 0.0, 1.0);
      const cv::Point2d offset = ap - t * ab;
      if (offset.dot(offset) <= halfWidth_px * halfWidth_px) bar.push_back(pixel);
    }
    bars.push_back(std::move(bar));
  }
  return bars;
}

}  // namespace

Result<MetalMask> MetalMaskDetector::detect(const FloatImage& lineIntegrals, const ValidMask& mask,
                                            double pixelSpacing_mm) const {
  const MetalMaskOptions& o = m_options;
  const int cols = lineIntegrals.cols;
  const int rows = lineIntegrals.rows;
  if (cols <= 0 || rows <= 0 || lineIntegrals.pixels.size() != static_cast<std::size_t>(cols) * rows ||
      mask.cols != cols || mask.rows != rows || mask.valid.size() != lineIntegrals.pixels.size()) {
    return fail(fmt::format("metal detection: the image is {}x{} with {} values and the mask {}x{}; both must have "
                            "cols*rows pixels of the same size",
                            cols, rows, lineIntegrals.pixels.size(), mask.cols, mask.rows));
  }
  if (!(pixelSpacing_mm >= 0.0) || !std::isfinite(pixelSpacing_mm)) {
    return fail(fmt::format("metal detection: pixel spacing {} mm; give a positive spacing or 0 for unknown",
                            pixelSpacing_mm));
  }
  const double spacing_mm = pixelSpacing_mm > 0.0 ? pixelSpacing_mm : o.assumedPixelSpacing_mm;
  const auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(spacing_mm) || !positive(o.backgroundWindow_mm) || !positive(o.narrowWindow_mm) ||
      !positive(o.contrastWindow_mm) || !positive(o.minExcess) || !positive(o.maxContrastRatio) ||
      !positive(o.maxSagitta_mm) || !positive(o.seedContrastRatio) || !positive(o.denseExcess) ||
      !positive(o.denseContrastRatio) || !positive(o.veryDenseExcess) || !positive(o.compactExcess) ||
      !positive(o.compactContrastRatio) || !(o.minLength_mm >= 0.0) || !(o.minClippedLength_mm >= 0.0) ||
      !(o.minDenseLength_mm >= 0.0) || !(o.minVeryDenseLength_mm >= 0.0) || !(o.minCompactWidth_mm >= 0.0) ||
      !std::isfinite(o.growExcess) || !(o.growDistance_mm >= 0.0) || !std::isfinite(o.growDistance_mm) ||
      !(o.dilation_mm >= 0.0) || !std::isfinite(o.dilation_mm)) {
    return fail(fmt::format("metal detection options: assumed pixel spacing {} mm, windows ({}, {}, {} mm), "
                            "minimum excess {}, dense, very dense and compact excesses ({}, {}, {}), contrast ratios "
                            "({}, {}, {}, {}) and sagitta {} mm must be > 0; lengths ({}, {}, {}, {}, {} mm), growth "
                            "distance {} mm and dilation {} mm >= 0; fix the settings",
                            o.assumedPixelSpacing_mm, o.backgroundWindow_mm, o.narrowWindow_mm,
                            o.contrastWindow_mm, o.minExcess, o.denseExcess, o.veryDenseExcess, o.compactExcess,
                            o.maxContrastRatio, o.seedContrastRatio, o.denseContrastRatio, o.compactContrastRatio,
                            o.maxSagitta_mm, o.minLength_mm, o.minClippedLength_mm, o.minDenseLength_mm,
                            o.minVeryDenseLength_mm, o.minCompactWidth_mm, o.growDistance_mm, o.dilation_mm));
  }
  const auto toPixels = [spacing_mm](double length_mm) {
    return static_cast<int>(std::lround(length_mm / spacing_mm));
  };
  // Windows of at least 3 px, the wide one at least the narrow one.
  const int narrowWindow_px = std::max(3, toPixels(o.narrowWindow_mm));
  const int wideWindow_px = std::max(narrowWindow_px, toPixels(o.backgroundWindow_mm));
  const int contrastWindow_px = std::max(3, toPixels(o.contrastWindow_mm));
  for (float p : lineIntegrals.pixels) {
    if (!std::isfinite(p)) return fail("metal detection: the line-integral image has non-finite pixels");
  }
  try {
    const cv::Mat image(rows, cols, CV_32F, const_cast<float*>(lineIntegrals.pixels.data()));
    const cv::Mat valid(rows, cols, CV_8U, const_cast<std::uint8_t*>(mask.valid.data()));
    cv::Mat p = image.clone();
    p.setTo(cv::Scalar(kHigh), valid == 0);
    // The wide and narrow surroundings and the low side of the surroundings (the erosion over a disc; invalid pixels
    // never win it) are independent: made side by side.
    cv::Mat wideBackground, narrowBackground, lowSide;
    tbb::parallel_invoke([&] { wideBackground = validOpening(p, wideWindow_px); },
                         [&] { narrowBackground = validOpening(p, narrowWindow_px); },
                         [&] { lowSide = discErosion(p, contrastWindow_px | 1, kHigh); });
    const cv::Mat wideExcess = image - wideBackground;
    const cv::Mat narrowExcess = image - narrowBackground;
    cv::Mat contrast = narrowBackground - lowSide;
    contrast.setTo(cv::Scalar(0.0f), lowSide == kHigh);
    // Bone contrast over narrow excess, read at candidate pixels only (their narrow excess is above minExcess > 0).
    const cv::Mat contrastRatio = contrast / narrowExcess;

    const auto minExcess = static_cast<float>(o.minExcess);
    cv::Mat candidates = cv::Mat::zeros(rows, cols, CV_8U);
    cv::Mat growable = cv::Mat::zeros(rows, cols, CV_8U);
    for (int i = 0; i < rows * cols; ++i) {
      if (!valid.data[i]) continue;
      const float wide = wideExcess.ptr<float>()[i];
      const float narrow = narrowExcess.ptr<float>()[i];
      if (wide > minExcess && narrow > static_cast<float>(o.growExcess)) growable.data[i] = 1;
      if (wide > minExcess && narrow > minExcess &&
          contrast.ptr<float>()[i] < static_cast<float>(o.maxContrastRatio) * narrow) {
        candidates.data[i] = 1;
      }
    }

    cv::Mat labels;
    const int labelCount = cv::connectedComponents(candidates, labels, 8, CV_32S);
    std::vector<Piece> pieces(static_cast<std::size_t>(labelCount));
    for (int i = 0; i < rows * cols; ++i) {
      const int label = labels.ptr<int>()[i];
      if (label == 0) continue;
      Piece& piece = pieces[static_cast<std::size_t>(label)];
      piece.pixels.emplace_back(i % cols, i / cols);
      piece.wideExcessSum += wideExcess.ptr<float>()[i];
      piece.contrastRatioSum += contrastRatio.ptr<float>()[i];
    }
    // Pixels next to an invalid pixel or the image's border: a piece reaching them is cut by the field's edge.
    cv::Mat interior;
    cv::erode(valid != 0, interior, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)), cv::Point(-1, -1), 1,
              cv::BORDER_CONSTANT, cv::Scalar(0));
    // A set of pixels' extent along the longest and the shortest side of its smallest enclosing rectangle, mm.
    const auto extent_mm = [spacing_mm](const std::vector<cv::Point>& pixels) {
      const cv::RotatedRect box = cv::minAreaRect(pixels);
      return std::pair((std::max(box.size.width, box.size.height) + 1.0) * spacing_mm,
                       (std::min(box.size.width, box.size.height) + 1.0) * spacing_mm);
    };
    cv::Mat seeds = cv::Mat::zeros(rows, cols, CV_8U);
    for (std::size_t label = 1; label < pieces.size(); ++label) {
      const Piece& piece = pieces[label];
      const double count = static_cast<double>(piece.pixels.size());
      const auto [pieceLength_mm, pieceWidth_mm] = extent_mm(piece.pixels);
      const double wide = piece.wideExcessSum / count;
      const double ratio = piece.contrastRatioSum / count;
      // Very dense pieces and compact two-sided blobs need no shape test (crossing wires make an X, a tilted screw a
      // head with a stub); the others must be straight.
      const bool veryDense = wide >= o.veryDenseExcess && pieceLength_mm >= o.minVeryDenseLength_mm;
      const bool compact =
          wide >= o.compactExcess && ratio < o.compactContrastRatio && pieceWidth_mm >= o.minCompactWidth_mm;
      const bool clipped = std::any_of(piece.pixels.begin(), piece.pixels.end(), [&interior](const cv::Point& pixel) {
        return interior.at<std::uint8_t>(pixel) == 0;
      });
      const bool longThin =
          pieceLength_mm >= (clipped ? o.minClippedLength_mm : o.minLength_mm) && ratio < o.seedContrastRatio;
      const bool dense =
          wide >= o.denseExcess && pieceLength_mm >= o.minDenseLength_mm && ratio < o.denseContrastRatio;
      if (veryDense || compact || ((longThin || dense) && sagitta_px(piece.pixels) * spacing_mm <= o.maxSagitta_mm)) {
        for (const cv::Point& pixel : piece.pixels) seeds.at<std::uint8_t>(pixel) = 1;
        continue;
      }
      // Not straight as a whole: a long straight bar of it with little bone contrast seeds (a wire crossing a screw).
      if (pieceLength_mm < o.minLength_mm) continue;
      for (const std::vector<cv::Point>& bar :
           straightBars(piece.pixels, o.minLength_mm / spacing_mm, 0.25 * narrowWindow_px)) {  // 2.5 mm each side
        if (bar.size() < 3) continue;
        double barRatio = 0.0;
        for (const cv::Point& pixel : bar) barRatio += contrastRatio.at<float>(pixel);
        barRatio /= static_cast<double>(bar.size());
        if (extent_mm(bar).first >= o.minLength_mm && barRatio < o.seedContrastRatio &&
            sagitta_px(bar) * spacing_mm <= o.maxSagitta_mm) {
          for (const cv::Point& pixel : bar) seeds.at<std::uint8_t>(pixel) = 1;
        }
      }
    }

    // Geodesic growth of the seeds inside the growable pixels, one 3x3 step per pixel of distance.
    cv::Mat metal = seeds.clone();
    const cv::Mat step = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
    for (int s = 0, steps = toPixels(o.growDistance_mm); s < steps; ++s) {
      cv::Mat next;
      cv::dilate(metal, next, step);
      next &= growable;
      next |= seeds;
      if (cv::countNonZero(next != metal) == 0) break;
      metal = next;
    }
    if (o.dilation_mm > 0.0) metal = grown(metal, std::max(kMinDilation_px, toPixels(o.dilation_mm)));
    MetalMask result{mask, 0};
    for (std::size_t i = 0; i < mask.valid.size(); ++i) {
      if (metal.data[i] && result.mask.valid[i]) {
        result.mask.valid[i] = 0;
        ++result.metalPixelCount;
      }
    }
    return result;
  } catch (const cv::Exception& e) {
    return fail(fmt::format("metal detection: OpenCV error: {}", e.what()));
  }
}

}  // namespace fct
