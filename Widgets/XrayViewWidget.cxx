#include "Widgets/XrayViewWidget.h"

#include <algorithm>

#include "XrayPrep/FieldOfViewDetector.h"

namespace fct {

namespace {

/// `high`, lowered to the values' median + kTailIqrs interquartile ranges where a long bright tail (the thin edge of a
/// thick patient, e.g. a lateral pelvis) would otherwise leave most of the pixels in the window's darkest few levels.
double belowTheBrightTail(const std::vector<float>& values, double high) {
  const double median = ImageViewWidget::quantile(values, 0.5);
  const double iqr = ImageViewWidget::quantile(values, 0.75) - ImageViewWidget::quantile(values, 0.25);
  return std::min(high, median + XrayViewWidget::kTailIqrs * iqr);
}

/// The low and high window ends of a preset over the field-of-view pixels `field` (MONOCHROME2 values).
std::pair<double, double> presetRange(XrayWindowPreset preset, const std::vector<float>& field) {
  if (preset == XrayWindowPreset::FullRange) {
    const auto [low, high] = std::minmax_element(field.begin(), field.end());
    return {*low, *high};
  }
  const double low = ImageViewWidget::quantile(field, 0.01);
  const double high = ImageViewWidget::quantile(field, 0.99);
  if (preset == XrayWindowPreset::WholeField || !(high > low)) return {low, high};
  // The direct exposure: the brightest values, within 5 % of the field's range of its 99th percentile.
  const double directLevel = high - 0.05 * (high - low);
  std::vector<float> patient;
  patient.reserve(field.size());
  for (float value : field) {
    if (value < directLevel) patient.push_back(value);
  }
  const double directFraction = 1.0 - static_cast<double>(patient.size()) / static_cast<double>(field.size());
  if (directFraction < XrayViewWidget::kMinDirectExposureFraction || patient.size() < 100) {
    return {low, belowTheBrightTail(field, high)};
  }
  // The upper part of the patient's pixels is the thin skin edge ramping up to the direct exposure: leave it out.
  return {ImageViewWidget::quantile(patient, 0.01),
          belowTheBrightTail(patient, ImageViewWidget::quantile(patient, XrayViewWidget::kPatientHighQuantile))};
}

}  // namespace

XrayViewWidget::XrayViewWidget(QWidget* parent) : ImageViewWidget(parent) { setPlaceholderText(tr("No X-ray")); }

void XrayViewWidget::setImage(const XrayImage& xray, bool keepView) {
  const bool sameSize = xray.cols == image().cols && xray.rows == image().rows;
  FloatImage pixels{xray.cols, xray.rows, xray.pixels};
  const std::size_t count = pixels.pixels.size();
  if (xray.fovMask.size() == count) {
    m_field = xray.fovMask;
  } else if (auto detected = FieldOfViewDetector().detect(pixels); detected && detected.value().mask.validCount() > 0) {
    m_field = detected.value().mask.valid;
  } else {
    m_field.assign(count, 1);
  }
  ImageViewWidget::setImage(pixels, keepView);
  if (!(keepView && sameSize)) applyWindowPreset(XrayWindowPreset::Automatic);
}

void XrayViewWidget::applyWindowPreset(XrayWindowPreset preset) {
  const FloatImage& shown = image();
  if (shown.empty() || m_field.size() != shown.pixels.size()) return;
  std::vector<float> field;
  field.reserve(shown.pixels.size());
  for (std::size_t i = 0; i < shown.pixels.size(); ++i) {
    if (m_field[i] && std::isfinite(shown.pixels[i])) field.push_back(shown.pixels[i]);
  }
  if (field.empty()) return;
  const auto [low, high] = presetRange(preset, field);
  setWindowLevel(high > low ? high - low : std::max(1.0, std::abs(high)), 0.5 * (low + high));
}

QString XrayViewWidget::presetName(XrayWindowPreset preset) {
  switch (preset) {
    case XrayWindowPreset::Automatic: return tr("Automatic (patient)");
    case XrayWindowPreset::WholeField: return tr("Whole field");
    case XrayWindowPreset::FullRange: return tr("Full range");
  }
  return {};
}

std::vector<std::vector<Eigen::Vector2d>> XrayViewWidget::polylines(const std::vector<PixelContour>& contours) {
  std::vector<std::vector<Eigen::Vector2d>> lines;
  lines.reserve(contours.size());
  for (const PixelContour& contour : contours) {
    std::vector<Eigen::Vector2d> line;
    line.reserve(contour.size());
    for (const Eigen::Vector2i& p : contour) line.push_back(p.cast<double>());
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace fct
