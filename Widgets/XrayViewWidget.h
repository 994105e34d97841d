#pragma once
// XrayViewWidget: the view of one C-arm X-ray: an ImageViewWidget (window/level, zoom, pan, overlay layers, click and
// drag signals in detector pixels) that takes XrayImage frames. An X-ray opens at the automatic window, taken from the
// field-of-view pixels (the image's own mask, else FieldOfViewDetector): their 1st to 99th percentile, or, when at
// least kMinDirectExposureFraction of them is direct exposure (the unattenuated beam, within 5 % of the range below
// the 99th percentile, which would take most grey levels and leave the bone nearly black), the 1st to
// kPatientHighQuantile percentile of the darker, patient pixels (their upper part is the skin edge ramping up to the
// direct exposure). Either high end is lowered to the median + kTailIqrs interquartile ranges of those pixels when a
// long bright tail (the thin edges of a thick patient) lies above it. Presets give the whole field (1st-99th percentile of every field-of-view pixel) and the full
// range (minimum to maximum).

#include <QString>

#include <cstdint>
#include <vector>

#include "Evaluation/ContourOverlay.h"
#include "Image/XrayImage.h"
#include "Widgets/ImageViewWidget.h"

namespace fct {

/// Window/level presets of the X-ray views.
enum class XrayWindowPreset { Automatic, WholeField, FullRange };

/// An interactive view of one X-ray with overlays (all of ImageViewWidget's API, in the X-ray's pixels).
class XrayViewWidget : public ImageViewWidget {
  Q_OBJECT
 public:
  /// Share of the field-of-view pixels a direct exposure must cover to be left out of the automatic window (twice what
  /// evenly spread values put in the top 5 % of the range).
  static constexpr double kMinDirectExposureFraction = 0.1;
  /// Upper quantile of the patient pixels the automatic window ends at when there is a direct exposure.
  static constexpr double kPatientHighQuantile = 0.8;
  /// The automatic window's high end is at most this many interquartile ranges above the median.
  static constexpr double kTailIqrs = 3.0;

  /// An empty X-ray view.
  explicit XrayViewWidget(QWidget* parent = nullptr);
  using ImageViewWidget::setImage;
  /// Shows an X-ray's pixels (MONOCHROME2 sense) at the automatic window, unless keepView is set and the size is
  /// unchanged (then zoom, pan and window stay).
  void setImage(const XrayImage& xray, bool keepView = false);
  /// Applies a window preset to the shown X-ray (nothing shown: no effect).
  void applyWindowPreset(XrayWindowPreset preset);
  /// Display name of a preset ("Automatic (patient)", "Whole field", "Full range").
  static QString presetName(XrayWindowPreset preset);
  /// Projected bone outlines (ContourOverlay::contours) as the polylines of setPolylineLayer, in pixels.
  static std::vector<std::vector<Eigen::Vector2d>> polylines(const std::vector<PixelContour>& contours);
  /// The field-of-view mask the windows are taken from (row-major, 1 = inside; all ones when none was found).
  const std::vector<std::uint8_t>& fieldMask() const { return m_field; }

 private:
  std::vector<std::uint8_t> m_field;
};

}  // namespace fct
