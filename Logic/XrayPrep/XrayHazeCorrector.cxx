#include "XrayPrep/XrayHazeCorrector.h"

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

/// The global fit I ~ g0 exp(-c (d - dmin)) + s0 of one c: gain, offset and squared residual over `valid`.
struct GlobalFit {
  double c = 1.0;
  double gain = 0.0;
  double offset = 0.0;
  double residual = std::numeric_limits<double>::infinity();
};

GlobalFit fitGlobally(const std::vector<double>& intensity, const std::vector<double>& drr, double c) {
  double sE = 0, sEE = 0, sI = 0, sEI = 0, sII = 0;
  for (std::size_t i = 0; i < intensity.size(); ++i) {
    const double e = std::exp(-c * drr[i]);
    sE += e;
    sEE += e * e;
    sI += intensity[i];
    sEI += e * intensity[i];
    sII += intensity[i] * intensity[i];
  }
  const auto n = static_cast<double>(intensity.size());
  const double det = n * sEE - sE * sE;
  GlobalFit fit;
  fit.c = c;
  if (!(det > 0.0)) return fit;
  fit.gain = (n * sEI - sE * sI) / det;
  fit.offset = (sI - fit.gain * sE) / n;
  fit.residual = sII - fit.gain * sEI - fit.offset * sI;  // the least-squares residual sum of squares
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
  // The valid pixels' intensities and DRR values (measured from the DRR's smallest), in one pass.
  std::vector<double> intensity, drr;
  intensity.reserve(pixels.size());
  drr.reserve(pixels.size());
  double dMin = std::numeric_limits<double>::infinity(), dMax = -dMin;
  for (const std::int32_t i : pixels) {
    const double d = drrLineIntegrals.pixels[static_cast<std::size_t>(i)];
    const double p = xrayLineIntegrals.pixels[static_cast<std::size_t>(i)];
    if (!std::isfinite(d) || !std::isfinite(p)) return fail("haze removal: the X-ray or the DRR has non-finite pixels");
    dMin = std::min(dMin, d);
    dMax = std::max(dMax, d);
    intensity.push_back(std::exp(-p));
    drr.push_back(d);
  }
  if (!(dMax - dMin > 1e-6)) return fail("haze removal: the DRR is constant over the valid pixels (no contrast to fit)");
  for (double& d : drr) d -= dMin;

  // The global fit: the attenuation factor c and gain g0.
  GlobalFit best;
  for (int k = 0; k < kGainGrid; ++k) {
    const GlobalFit fit = fitGlobally(intensity, drr, 0.5 + k / double(kGainGrid - 1));
    if (fit.residual < best.residual) best = fit;
  }
  if (!(best.gain > 0.0)) {
    return fail("haze removal: the DRR does not explain the X-ray (the fitted gain is not positive); the pose is far "
                "from the truth");
  }

  // The local fit: Gaussian-weighted moments over the valid pixels.
  cv::Mat valid(rows, cols, CV_64F, cv::Scalar(0.0));
  for (const std::int32_t i : pixels) valid.at<double>(i / cols, i % cols) = 1.0;
  cv::Mat intensityMat;
  cv::exp(-toMat(xrayLineIntegrals), intensityMat);
  cv::Mat drrTerm;
  cv::exp(-best.c * (toMat(drrLineIntegrals) - dMin), drrTerm);
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
  const cv::Mat sumE = smooth(drrTerm), sumI = smooth(intensityMat);
  const cv::Mat sumEE = smooth(drrTerm.mul(drrTerm)), sumEI = smooth(drrTerm.mul(intensityMat));
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
  const double ridge = std::max(kRidge * *middle, 1e-12);

  FloatImage corrected = FloatImage::filled(cols, rows, 0.0f);
  double hazeFractionSum = 0.0;
  for (int r = 0; r < rows; ++r) {
    for (int col = 0; col < cols; ++col) {
      double gain = best.gain, haze = best.offset;
      if (!std::isnan(varE.at<double>(r, col))) {
        gain = (covEI.at<double>(r, col) + ridge * best.gain) / (varE.at<double>(r, col) + ridge);
        gain = std::max(gain, 0.1 * best.gain);  // a gain near 0 would blow the noise up
        haze = meanI.at<double>(r, col) - gain * meanE.at<double>(r, col);
      }
      const double in = intensityMat.at<double>(r, col);
      corrected.at(col, r) = static_cast<float>((in - haze) / gain);
      if (valid.at<double>(r, col) > 0.0) hazeFractionSum += std::abs(haze) / in;
    }
  }
  auto lineIntegrals = XrayIntensityModel().toLineIntegrals(corrected, mask);
  if (!lineIntegrals) return fail("haze removal: " + lineIntegrals.error());
  HazeCorrection result;
  result.lineIntegrals = std::move(lineIntegrals.value().lineIntegrals);
  result.attenuationFactor = best.c;
  result.globalGain = best.gain;
  result.meanHazeFraction = hazeFractionSum / static_cast<double>(pixels.size());
  return result;
}

}  // namespace fct
