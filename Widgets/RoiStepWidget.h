#pragma once
// RoiStepWidget: the "ROIs" step, tuning the dynamic regions of interest. Window size and either a normalized-variance
// threshold or a target fraction (sliders with spin boxes); the kept windows are drawn live as a coloured layer over
// each X-ray with the kept fraction per view; the excluded pixels (image margin, outside the collimator / field of
// view, calibration spheres) are drawn in another colour and their settings are editable, as is the margin around
// the CT's end faces within which rays are not compared (not drawn: it depends on the pose). The window statistics
// come once per view, level and window size (DynamicRoiSelector on the document's prepared case); moving a slider only
// re-thresholds them. In threshold mode the document's target fraction follows the mean kept fraction over the views,
// which is what the registration's ROI stages then keep.

#include <QMetaObject>
#include <QString>
#include <QWidget>

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "Similarity/DynamicRoiSelector.h"
#include "Widgets/StudioDocument.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QRadioButton;
class QSlider;
class QSpinBox;

namespace fct {

class SliceViewWidget;
class XrayViewWidget;

/// The ROIs step: dynamic-ROI threshold tuning with a live overlay.
class RoiStepWidget : public QWidget {
  Q_OBJECT
 public:
  /// Name of the X-ray image layer of the kept ROI windows.
  static inline const QString kRoiLayer = QStringLiteral("rois");
  /// Name of the X-ray image layer of the excluded pixels.
  static inline const QString kExcludedLayer = QStringLiteral("rois-excluded");
  /// Name of the X-ray polyline layer of the calibration-sphere outlines.
  static inline const QString kSphereLayer = QStringLiteral("rois-spheres");
  /// The threshold slider is logarithmic: kThresholdSliderSteps steps per decade of normalized variance, from
  /// 10^kMinThresholdExponent to 10^kMaxThresholdExponent (window variances are mostly far below the image's).
  static constexpr int kThresholdSliderSteps = 100;
  static constexpr int kMinThresholdExponent = -4;
  static constexpr int kMaxThresholdExponent = 1;
  /// Threshold of a slider position, and the nearest slider position of a threshold.
  static double thresholdForSlider(int position);
  static int sliderForThreshold(double threshold);

  /// A step editing `document`'s ROI parameters.
  explicit RoiStepWidget(StudioDocument* document, QWidget* parent = nullptr);

  /// The views this step draws on (X-ray view i shows document view i); slice views are not used.
  void attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3> sliceViews);
  /// While active the step shows its layers and keeps them up to date; inactive it hides them.
  void setActive(bool active);

  /// Kept fraction (kept pixels / valid pixels) of view v at the current settings; NaN when unknown.
  double keptFraction(std::size_t v) const;
  /// Per view, why pixels are excluded and how many (margin, field of view, spheres, other: metal or collimator), as
  /// shown under the fractions.
  QString exclusionText() const;
  /// Pyramid level the ROIs are shown for (0 = full resolution).
  int level() const { return m_level; }
  /// The message line, as shown.
  QString message() const;
  /// The threshold slider (for tests driving it like a user).
  QSlider* thresholdSlider() const { return m_thresholdSlider; }
  /// The threshold spin box beside the slider.
  QDoubleSpinBox* thresholdSpin() const { return m_thresholdSpin; }
  /// The fraction slider.
  QSlider* fractionSlider() const { return m_fractionSlider; }
  /// The spin box of the margin around the CT's end faces (mm; its minimum reads "off").
  QDoubleSpinBox* cutFaceSpin() const { return m_cutFaceSpin; }

 public slots:
  /// Shows the ROIs chosen on pyramid level `level` (0..2).
  void setLevel(int level);
  /// Recomputes the selection and redraws the layers (called on every parameter change).
  void updateSelection();

 private:
  /// Copies the document's parameters into the controls (without feedback).
  void syncControls();
  /// Writes the controls' values into the document.
  void pushParameters();
  /// Gets the prepared case and window statistics when missing; false with a message on failure.
  bool ensureSelectors();
  /// Redraws the exclusion layer and sphere outlines of every view (they change only with the case).
  void drawExclusions();
  void showMessage(const QString& text, bool error);

  StudioDocument* m_document;
  std::vector<XrayViewWidget*> m_xrayViews;
  bool m_active = false;
  bool m_syncing = false;
  int m_level = 0;

  std::shared_ptr<RegistrationCase> m_case;     ///< the document's prepared case the statistics were computed on
  int m_selectorWindow = 0;                     ///< window size of m_selectors
  int m_selectorLevel = -1;                     ///< level of m_selectors
  std::vector<DynamicRoiSelector> m_selectors;  ///< per view
  std::vector<double> m_keptFraction;           ///< per view, NaN when no selection
  bool m_exclusionsDrawn = false;

  QComboBox* m_levelCombo;
  QSpinBox* m_windowSpin;
  QRadioButton* m_thresholdRadio;
  QRadioButton* m_fractionRadio;
  QSlider* m_thresholdSlider;
  QDoubleSpinBox* m_thresholdSpin;
  QSlider* m_fractionSlider;
  QDoubleSpinBox* m_fractionSpin;
  QSpinBox* m_marginSpin;
  QCheckBox* m_fieldOfViewCheck;
  QCheckBox* m_spheresCheck;
  QDoubleSpinBox* m_cutFaceSpin;  ///< RoiParameters::cutFaceMargin_mm; its lowest value, -1, reads "off"
  QLabel* m_fractions;
  QLabel* m_exclusions;  ///< per view, the share of the image each exclusion takes
  QLabel* m_message;
};

}  // namespace fct
