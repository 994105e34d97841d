#include "XrayPrep/XrayHazeCorrector.h"

#include <Eigen/Cholesky>
#include <fmt/format.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "XrayPrep/XrayIntensityModel.h"

namespace fct {

namespace {

/// The smallest number of valid pixels a fit needs.
constexpr std::size_t kMinPixels = 100;
/// The local moments are blurred on a grid whose pixels are at most sigma_px / kPixelsPerSigma wide.
constexpr double kPixelsPerSigma = 4.0;

/// A CV_64F matrix of `image`'s pixels.
cv::Mat toMat(const FloatImage& image) {
  cv::Mat mat;
  cv::Mat(image.rows, image.cols, CV_32F, const_cast<float*>(image.pixels.data())).convertTo(mat, CV_64F);
  return mat;
}

/// The global fit uses at most this many valid pixels (an even subsample): its seven parameters need no more.
constexpr std::size_t kMaxGlobalFitPixels = 10000;
/// The refinement of the best grid point: rounds of coordinate descent, golden-section iterations per coordinate.
constexpr int kRefineRounds = 6;
constexpr int kRefineIterations = 20;
/// The global haze surface: a quadratic in the detector position (1, u, v, u^2, uv, v^2; u, v in [-1, 1]).
constexpr int kSurfaceTerms = 6;
using SurfaceVector = Eigen::Matrix<double, kSurfaceTerms, 1>;

/// The haze surface's terms at pixel (col, row) of a cols x rows image.
SurfaceVector surfaceTerms(int col, int row, int cols, int rows) {
  const double u = 2.0 * col / std::max(1, cols - 1) - 1.0, v = 2.0 * row / std::max(1, rows - 1) - 1.0;
  SurfaceVector terms;
  terms << 1.0, u, v, u * u, u * v, v * v;
  return terms;
}

/// The view's beam-hardening curve h(x) = c x / (1 + b x), x the DRR's line integral above its smallest.
struct HardeningCurve {
  double c = 1.0;
  double b = 0.0;
  /// The X-ray's line integral of a ray whose DRR line integral is x above the smallest.
  double apply(double x) const { return c * x / (1.0 + b * x); }
  /// The DRR line integral x of an X-ray line integral p (h's inverse); p is capped below h's asymptote c / b.
  double invert(double p) const {
    if (b > 0.0) p = std::min(p, 0.95 * c / b);
    return p / (c - b * p);
  }
};

/// The pixels of the global fit and their moments that do not depend on the curve.
struct GlobalFitSample {
  std::vector<double> intensity;       ///< I
  std::vector<double> drr;             ///< d - dmin
  std::vector<SurfaceVector> terms;    ///< the haze surface's terms
  Eigen::Matrix<double, kSurfaceTerms, kSurfaceTerms> termGram = decltype(termGram)::Zero();  ///< sum of terms terms^T
  SurfaceVector termIntensity = SurfaceVector::Zero();  ///< sum of terms I
  double intensitySquares = 0.0;                        ///< sum of I^2

  void add(double i, double d, const SurfaceVector& t) {
    intensity.push_back(i);
    drr.push_back(d);
    terms.push_back(t);
    termGram += t * t.transpose();
    termIntensity += t * i;
    intensitySquares += i * i;
  }
};

/// The global fit I ~ g0 exp(-h(d - dmin)) + s(u) of one curve, s a quadratic surface: gain, surface and squared
/// residual over the sample.
struct GlobalFit {
  HardeningCurve curve;
  double gain = 0.0;
  SurfaceVector surface = SurfaceVector::Zero();
  double residual = std::numeric_limits<double>::infinity();
};

GlobalFit fitGlobally(const GlobalFitSample& sample, HardeningCurve curve) {
  double sEE = 0.0, sEI = 0.0;
  SurfaceVector sET = SurfaceVector::Zero();
  for (std::size_t i = 0; i < sample.intensity.size(); ++i) {
    const double e = std::exp(-curve.apply(sample.drr[i]));
    sEE += e * e;
    sEI += e * sample.intensity[i];
    sET += e * sample.terms[i];
  }
  Eigen::Matrix<double, kSurfaceTerms + 1, kSurfaceTerms + 1> normal;
  normal(0, 0) = sEE;
  normal.block<1, kSurfaceTerms>(0, 1) = sET.transpose();
  normal.block<kSurfaceTerms, 1>(1, 0) = sET;
  normal.block<kSurfaceTerms, kSurfaceTerms>(1, 1) = sample.termGram;
  Eigen::Matrix<double, kSurfaceTerms + 1, 1> rhs;
  rhs << sEI, sample.termIntensity;
  GlobalFit fit;
  fit.curve = curve;
  const Eigen::LLT<decltype(normal)> llt(normal);
  if (llt.info() != Eigen::Success) return fit;
  const Eigen::Matrix<double, kSurfaceTerms + 1, 1> solution = llt.solve(rhs);
  fit.gain = solution(0);
  fit.surface = solution.tail<kSurfaceTerms>();
  fit.residual = sample.intensitySquares - solution.dot(rhs);  // the least-squares residual sum of squares
  return fit;
}

/// The best global fit: a grid over c (log-spaced) and b, then refined by coordinate descent.
/// `drrRange` is dmax - dmin. Sets `atEdge` when the best c is the grid's first or last value.
GlobalFit fitCurve(const GlobalFitSample& sample, double drrRange, bool& atEdge) {
  const double ratio = std::pow(XrayHazeCorrector::kMaxFactor / XrayHazeCorrector::kMinFactor,
                                1.0 / (XrayHazeCorrector::kFactorGrid - 1));
  GlobalFit best;
  int bestK = 0;
  for (int k = 0; k < XrayHazeCorrector::kFactorGrid; ++k) {
    for (int j = 0; j < XrayHazeCorrector::kHardeningGrid; ++j) {
      const HardeningCurve curve{XrayHazeCorrector::kMinFactor * std::pow(ratio, k),
                                 XrayHazeCorrector::kMaxHardening * j / (XrayHazeCorrector::kHardeningGrid - 1) /
                                     drrRange};
      const GlobalFit fit = fitGlobally(sample, curve);
      if (fit.residual < best.residual) {
        best = fit;
        bestK = k;
      }
    }
  }
  atEdge = bestK == 0 || bestK == XrayHazeCorrector::kFactorGrid - 1;
  // Coordinate descent from the best grid point: golden sections on c (one grid step either side) and on b.
  const double bStep = XrayHazeCorrector::kMaxHardening / (XrayHazeCorrector::kHardeningGrid - 1) / drrRange;
  const auto goldenSection = [&](double lo, double hi, const auto& curveAt) {
    for (int it = 0; it < kRefineIterations; ++it) {
      const double m1 = lo + 0.382 * (hi - lo), m2 = lo + 0.618 * (hi - lo);
      if (fitGlobally(sample, curveAt(m1)).residual < fitGlobally(sample, curveAt(m2)).residual) {
        hi = m2;
      } else {
        lo = m1;
      }
    }
    return 0.5 * (lo + hi);
  };
  for (int round = 0; round < kRefineRounds; ++round) {
    const double b = best.curve.b;
    const double c = goldenSection(best.curve.c / ratio, best.curve.c * ratio,
                                   [&](double x) { return HardeningCurve{x, b}; });
    const double bNew = goldenSection(std::max(0.0, b - bStep), b + bStep,
                                      [&](double x) { return HardeningCurve{c, x}; });
    for (const HardeningCurve curve : {HardeningCurve{c, b}, HardeningCurve{c, bNew}}) {
      const GlobalFit fit = fitGlobally(sample, curve);
      if (fit.residual < best.residual) best = fit;
    }
  }
  return best;
}

/// The fit over the valid pixels: the global curve and gain, and per pixel the local gain g(u) and haze
/// s(u).
struct ViewFit {
  GlobalFit global;
  cv::Mat gain;  ///< g(u)
  cv::Mat haze;  ///< s(u)
};

/// Fits the model over the valid `pixels` (raster indices). Fails when the DRR does not explain the X-ray (gain not
/// positive) or the attenuation factor lies at the edge of the searched range.
Result<ViewFit> fitView(const cv::Mat& intensity, const cv::Mat& drr, const PixelIndexList& pixels, double dMin,
                        double drrRange, double sigma_px) {
  const int rows = intensity.rows, cols = intensity.cols;
  cv::Mat valid(rows, cols, CV_64F, cv::Scalar(0.0));  // the valid pixels as weights of 1
  for (const std::int32_t i : pixels) valid.at<double>(i / cols, i % cols) = 1.0;
  // The global fit on an even subsample: the hardening curve, the gain g0 and the haze surface.
  const std::size_t stride = (pixels.size() + kMaxGlobalFitPixels - 1) / kMaxGlobalFitPixels;
  GlobalFitSample sample;
  for (std::size_t k = 0; k < pixels.size(); k += stride) {
    const int r = pixels[k] / cols, col = pixels[k] % cols;
    sample.add(intensity.at<double>(r, col), drr.at<double>(r, col) - dMin, surfaceTerms(col, r, cols, rows));
  }
  bool atEdge = false;
  ViewFit fit;
  fit.global = fitCurve(sample, drrRange, atEdge);
  const GlobalFit& best = fit.global;
  if (!(best.gain > 0.0)) {
    return fail("haze removal: the DRR does not explain the X-ray (the fitted gain is not positive); the pose is far "
                "from the truth");
  }
  if (atEdge) {
    return fail(fmt::format("haze removal: the X-ray's attenuation is {:.2f} times the DRR's, at the edge of the range "
                            "searched ({}-{}); check the CT's calibration (HU) and the X-ray's log transform",
                            best.curve.c, XrayHazeCorrector::kMinFactor, XrayHazeCorrector::kMaxFactor));
  }

  // The local fit: Gaussian-weighted moments over the valid pixels.
  cv::Mat drrTerm = drr.clone();  // exp(-h(d - dmin)), h's argument clamped at 0 off the valid pixels
  for (auto it = drrTerm.begin<double>(); it != drrTerm.end<double>(); ++it) {
    *it = std::exp(-best.curve.apply(std::max(*it - dMin, 0.0)));
  }
  // The haze is smooth on the scale of sigma_px: its moments are blurred on a grid `step` times coarser (area
  // averages), with sigma_px / step, and interpolated back.
  const int step = std::max(1, static_cast<int>(sigma_px / kPixelsPerSigma));
  const cv::Size coarseSize((cols + step - 1) / step, (rows + step - 1) / step);
  const auto smooth = [&](const cv::Mat& image) {
    cv::Mat coarse, blurred, fine;
    cv::resize(image.mul(valid), coarse, coarseSize, 0, 0, cv::INTER_AREA);
    cv::GaussianBlur(coarse, blurred, cv::Size(0, 0), sigma_px / step, sigma_px / step, cv::BORDER_REFLECT);
    cv::resize(blurred, fine, cv::Size(cols, rows), 0, 0, cv::INTER_LINEAR);
    return fine;
  };
  const cv::Mat weight = smooth(cv::Mat::ones(rows, cols, CV_64F));
  const cv::Mat sumE = smooth(drrTerm), sumI = smooth(intensity);
  const cv::Mat sumEE = smooth(drrTerm.mul(drrTerm)), sumEI = smooth(drrTerm.mul(intensity));
  cv::Mat meanE(rows, cols, CV_64F), meanI(rows, cols, CV_64F), varE(rows, cols, CV_64F), covEI(rows, cols, CV_64F);
  std::vector<double> validVariances;
  validVariances.reserve(pixels.size());
  for (int r = 0; r < rows; ++r) {
    for (int col = 0; col < cols; ++col) {
      const double w = weight.at<double>(r, col);
      if (w < 1e-9) {  // no valid pixel within reach: the global fit
        meanE.at<double>(r, col) = meanI.at<double>(r, col) = 0.0;
        varE.at<double>(r, col) = covEI.at<double>(r, col) = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      const double e = sumE.at<double>(r, col) / w, in = sumI.at<double>(r, col) / w;
      meanE.at<double>(r, col) = e;
      meanI.at<double>(r, col) = in;
      varE.at<double>(r, col) = std::max(0.0, sumEE.at<double>(r, col) / w - e * e);
      covEI.at<double>(r, col) = sumEI.at<double>(r, col) / w - e * in;
      if (valid.at<double>(r, col) > 0.0) validVariances.push_back(varE.at<double>(r, col));
    }
  }
  const auto middle = validVariances.begin() + static_cast<std::ptrdiff_t>(validVariances.size() / 2);
  std::nth_element(validVariances.begin(), middle, validVariances.end());
  const double ridge = std::max(XrayHazeCorrector::kRidge * *middle, 1e-12);

  fit.gain.create(rows, cols, CV_64F);
  fit.haze.create(rows, cols, CV_64F);
  for (int r = 0; r < rows; ++r) {
    for (int col = 0; col < cols; ++col) {
      double gain = best.gain, haze = 0.0;
      if (std::isnan(varE.at<double>(r, col))) {  // no valid pixel within reach: the global fit
        haze = best.surface.dot(surfaceTerms(col, r, cols, rows));
      } else {
        gain = (covEI.at<double>(r, col) + ridge * best.gain) / (varE.at<double>(r, col) + ridge);
        gain = std::max(gain, 0.1 * best.gain);  // a gain near 0 would blow the noise up
        haze = meanI.at<double>(r, col) - gain * meanE.at<double>(r, col);
      }
      fit.gain.at<double>(r, col) = gain;
      fit.haze.at<double>(r, col) = haze;
    }
  }
  return fit;
}

}  // namespace

Result<HazeCorrection> XrayHazeCorrector::correct(const FloatImage& xrayLineIntegrals,
                                                  const FloatImage& drrLineIntegrals, const ValidMask& mask,
                                                  double sigma_px) {
  const int cols = xrayLineIntegrals.cols;
  const int rows = xrayLineIntegrals.rows;
  if (drrLineIntegrals.cols != cols || drrLineIntegrals.rows != rows || mask.cols != cols || mask.rows != rows ||
      xrayLineIntegrals.pixels.size() != static_cast<std::size_t>(cols) * rows) {
    return fail(fmt::format("haze removal: the X-ray ({}x{}), DRR ({}x{}) and mask ({}x{}) differ in size", cols, rows,
                            drrLineIntegrals.cols, drrLineIntegrals.rows, mask.cols, mask.rows));
  }
  if (!(sigma_px > 0.0) || !std::isfinite(sigma_px)) {
    return fail(fmt::format("haze removal: the haze's smoothness must be a positive number of pixels, got {}", sigma_px));
  }
  const PixelIndexList pixels = mask.pixelList();
  if (pixels.size() < kMinPixels) {
    return fail(fmt::format("haze removal: {} valid pixels; at least {} are needed", pixels.size(), kMinPixels));
  }
  // The DRR's range over the valid pixels.
  double dMin = std::numeric_limits<double>::infinity(), dMax = -dMin;
  for (const std::int32_t i : pixels) {
    const double d = drrLineIntegrals.pixels[static_cast<std::size_t>(i)];
    if (!std::isfinite(d) || !std::isfinite(xrayLineIntegrals.pixels[static_cast<std::size_t>(i)])) {
      return fail("haze removal: the X-ray or the DRR has non-finite pixels");
    }
    dMin = std::min(dMin, d);
    dMax = std::max(dMax, d);
  }
  if (!(dMax - dMin > 1e-6)) return fail("haze removal: the DRR is constant over the valid pixels (no contrast to fit)");
  cv::Mat intensityMat;
  cv::exp(-toMat(xrayLineIntegrals), intensityMat);
  const cv::Mat drrMat = toMat(drrLineIntegrals);
  auto viewFit = fitView(intensityMat, drrMat, pixels, dMin, dMax - dMin, sigma_px);
  if (!viewFit) return fail(viewFit.error());
  const ViewFit& fit = viewFit.value();
  const GlobalFit& best = fit.global;

  FloatImage corrected = FloatImage::filled(cols, rows, 0.0f);
  double hazeFractionSum = 0.0;
  for (int r = 0; r < rows; ++r) {
    for (int col = 0; col < cols; ++col) {
      const double in = intensityMat.at<double>(r, col), gain = fit.gain.at<double>(r, col);
      const double haze = fit.haze.at<double>(r, col);
      corrected.at(col, r) = static_cast<float>((in - haze) / gain);
      if (mask.valid[static_cast<std::size_t>(r) * cols + col] != 0) hazeFractionSum += std::abs(haze) / in;
    }
  }
  auto lineIntegrals = XrayIntensityModel().toLineIntegrals(corrected, mask);
  if (!lineIntegrals) return fail("haze removal: " + lineIntegrals.error());
  HazeCorrection result;
  result.lineIntegrals = std::move(lineIntegrals.value().lineIntegrals);
  for (float& p : result.lineIntegrals.pixels) p = static_cast<float>(best.curve.invert(p));  // to the DRR's scale
  result.attenuationFactor = best.curve.c;
  result.hardening = best.curve.b * (dMax - dMin);
  result.globalGain = best.gain;
  result.meanHazeFraction = hazeFractionSum / static_cast<double>(pixels.size());
  return result;
}

}  // namespace fct
