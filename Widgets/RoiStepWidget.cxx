#include "Widgets/RoiStepWidget.h"

#include <QButtonGroup>
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPainter>
#include <QRadioButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QSpinBox>
#include <QVBoxLayout>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "Widgets/XrayViewWidget.h"

namespace fct {

namespace {

const QColor kRoiColour(255, 200, 0);
const QColor kExcludedColour(40, 90, 255);        ///< outside the field of view
const QColor kMarginColour(150, 150, 190);        ///< the image margin
const QColor kSphereExcludedColour(200, 60, 200);  ///< a calibration sphere's shadow
const QColor kOtherExcludedColour(255, 150, 0);   ///< metal, or the inside of a non-circular collimator edge
const QColor kSphereColour(255, 60, 200);
constexpr double kRoiOpacity = 0.5;
constexpr double kExcludedOpacity = 0.35;

/// A slider with a spin box beside it, in one row.
QWidget* sliderRow(QSlider* slider, QWidget* spin, QWidget* parent) {
  auto* row = new QWidget(parent);
  auto* layout = new QHBoxLayout(row);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(slider, 1);
  layout->addWidget(spin);
  return row;
}

/// A circle as a closed polyline of `segments` points, pixels.
std::vector<Eigen::Vector2d> circlePolyline(const PixelCircle& circle, int segments = 48) {
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < segments; ++i) {
    const double angle = 2.0 * M_PI * i / segments;
    points.push_back(circle.centre_px + circle.radius_px * Eigen::Vector2d(std::cos(angle), std::sin(angle)));
  }
  return points;
}

}  // namespace

RoiStepWidget::RoiStepWidget(StudioDocument* document, QWidget* parent) : QWidget(parent), m_document(document) {
  auto* layout = new QVBoxLayout(this);

  auto* roiBox = new QGroupBox(tr("Dynamic ROIs"), this);
  auto* form = new QFormLayout(roiBox);
  m_levelCombo = new QComboBox(roiBox);
  m_levelCombo->addItems({tr("1:1 (full resolution)"), tr("1:4"), tr("1:16")});
  form->addRow(tr("Shown for level"), m_levelCombo);
  m_windowSpin = new QSpinBox(roiBox);
  m_windowSpin->setRange(2, 64);
  m_windowSpin->setSuffix(tr(" px"));
  m_windowSpin->setKeyboardTracking(false);
  form->addRow(tr("Window size"), m_windowSpin);

  m_thresholdRadio = new QRadioButton(tr("Variance threshold"), roiBox);
  m_fractionRadio = new QRadioButton(tr("Target fraction"), roiBox);
  auto* modeGroup = new QButtonGroup(roiBox);
  modeGroup->addButton(m_thresholdRadio);
  modeGroup->addButton(m_fractionRadio);
  m_thresholdSlider = new QSlider(Qt::Horizontal, roiBox);
  m_thresholdSlider->setRange(0, (kMaxThresholdExponent - kMinThresholdExponent) * kThresholdSliderSteps);
  m_thresholdSpin = new QDoubleSpinBox(roiBox);
  // The spin box covers the slider's range, with the decimals its low end needs (10^-4 reads "0.0001", not "0.000").
  m_thresholdSpin->setRange(std::pow(10.0, kMinThresholdExponent), std::pow(10.0, kMaxThresholdExponent));
  m_thresholdSpin->setDecimals(-kMinThresholdExponent);
  m_thresholdSpin->setStepType(QAbstractSpinBox::AdaptiveDecimalStepType);
  m_thresholdSpin->setToolTip(tr("Keep windows whose variance is at least this multiple of the image's variance"));
  form->addRow(m_thresholdRadio, sliderRow(m_thresholdSlider, m_thresholdSpin, roiBox));
  m_fractionSlider = new QSlider(Qt::Horizontal, roiBox);
  m_fractionSlider->setRange(1, 100);
  m_fractionSpin = new QDoubleSpinBox(roiBox);
  m_fractionSpin->setRange(0.001, 1.0);
  m_fractionSpin->setDecimals(3);
  m_fractionSpin->setSingleStep(0.01);
  m_fractionSpin->setToolTip(tr("Keep the highest-variance windows covering this fraction of the valid pixels "
                                "(the paper: 0.10-0.15)"));
  form->addRow(m_fractionRadio, sliderRow(m_fractionSlider, m_fractionSpin, roiBox));
  layout->addWidget(roiBox);

  auto* exclusionBox = new QGroupBox(tr("Excluded pixels (coloured by reason, see below)"), this);
  auto* exclusionForm = new QFormLayout(exclusionBox);
  m_marginSpin = new QSpinBox(exclusionBox);
  m_marginSpin->setRange(0, 200);
  m_marginSpin->setSuffix(tr(" px"));
  m_marginSpin->setKeyboardTracking(false);
  exclusionForm->addRow(tr("Image margin"), m_marginSpin);
  m_fieldOfViewCheck = new QCheckBox(tr("Exclude outside the collimator / field of view"), exclusionBox);
  exclusionForm->addRow(m_fieldOfViewCheck);
  m_spheresCheck = new QCheckBox(tr("Detect more calibration spheres"), exclusionBox);
  m_spheresCheck->setToolTip(tr("The spheres listed in the view file are always excluded; this also finds others"));
  exclusionForm->addRow(m_spheresCheck);
  m_cutFaceSpin = new QDoubleSpinBox(exclusionBox);
  m_cutFaceSpin->setRange(-1.0, RegistrationCaseOptions::kMaxCutFaceMargin_mm);
  m_cutFaceSpin->setDecimals(1);
  m_cutFaceSpin->setSuffix(tr(" mm"));
  m_cutFaceSpin->setSpecialValueText(tr("off"));  // shown at the minimum, -1: every ray is compared
  m_cutFaceSpin->setKeyboardTracking(false);
  m_cutFaceSpin->setToolTip(tr("Rays that pass within this distance of the CT's end faces (at the start pose) are not "
                               "compared: beyond them the X-ray shows anatomy the CT lacks. Lowest value: off"));
  exclusionForm->addRow(tr("Margin around the CT's end faces"), m_cutFaceSpin);
  layout->addWidget(exclusionBox);

  m_fractions = new QLabel(this);
  m_fractions->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(m_fractions);
  m_exclusions = new QLabel(this);
  m_exclusions->setWordWrap(true);
  m_exclusions->setTextFormat(Qt::RichText);
  layout->addWidget(m_exclusions);
  m_message = new QLabel(this);
  m_message->setWordWrap(true);
  layout->addWidget(m_message);
  layout->addStretch(1);

  connect(m_levelCombo, &QComboBox::currentIndexChanged, this, &RoiStepWidget::setLevel);
  connect(m_windowSpin, &QSpinBox::valueChanged, this, &RoiStepWidget::pushParameters);
  connect(m_thresholdRadio, &QRadioButton::toggled, this, [this](bool threshold) {
    // Switching to the threshold keeps the selection: the threshold starts where the fraction was (mean over views).
    if (threshold && !m_selectors.empty()) {
      double sum = 0.0;
      int count = 0;
      for (const DynamicRoiSelector& selector : m_selectors) {
        if (auto selection = selector.selectFraction(m_document->roiParameters().targetFraction)) {
          sum += selection.value().threshold;
          ++count;
        }
      }
      if (count > 0) {
        const QSignalBlocker blocker(m_thresholdSpin);
        m_thresholdSpin->setValue(sum / count);
      }
    }
    pushParameters();
  });
  connect(m_thresholdSlider, &QSlider::valueChanged, this, [this](int value) {
    const QSignalBlocker blocker(m_thresholdSpin);
    m_thresholdSpin->setValue(thresholdForSlider(value));
    pushParameters();
  });
  connect(m_thresholdSpin, &QDoubleSpinBox::valueChanged, this, [this](double value) {
    const QSignalBlocker blocker(m_thresholdSlider);
    m_thresholdSlider->setValue(sliderForThreshold(value));
    pushParameters();
  });
  connect(m_fractionSlider, &QSlider::valueChanged, this, [this](int value) {
    const QSignalBlocker blocker(m_fractionSpin);
    m_fractionSpin->setValue(value / 100.0);
    pushParameters();
  });
  connect(m_fractionSpin, &QDoubleSpinBox::valueChanged, this, [this](double value) {
    const QSignalBlocker blocker(m_fractionSlider);
    m_fractionSlider->setValue(static_cast<int>(std::lround(value * 100.0)));
    pushParameters();
  });
  connect(m_marginSpin, &QSpinBox::valueChanged, this, &RoiStepWidget::pushParameters);
  connect(m_fieldOfViewCheck, &QCheckBox::toggled, this, &RoiStepWidget::pushParameters);
  connect(m_spheresCheck, &QCheckBox::toggled, this, &RoiStepWidget::pushParameters);
  connect(m_cutFaceSpin, &QDoubleSpinBox::valueChanged, this, &RoiStepWidget::pushParameters);

  connect(m_document, &StudioDocument::roiParametersChanged, this, [this] {
    syncControls();
    if (!m_syncing) updateSelection();
  });
  const auto dropCase = [this] {
    m_case.reset();
    updateSelection();
  };
  connect(m_document, &StudioDocument::casePreparationProgressed, this, [this](const QString& step, double fraction) {
    if (m_active) showMessage(tr("Preparing the case for the ROIs: %1 (%2 %)…").arg(step).arg(100.0 * fraction, 0, 'f', 0), false);
  });
  connect(m_document, &StudioDocument::casePreparationFinished, this, [this](bool prepared, const QString& why) {
    if (!m_active) return;
    if (prepared) {
      showMessage(QString(), false);
      updateSelection();
    } else if (!m_document->isPreparingCase() && !m_document->readyCase()) {
      showMessage(tr("No ROIs to show: %1").arg(why), true);
    }
  });
  connect(m_document, &StudioDocument::ctChanged, this, dropCase);
  connect(m_document, &StudioDocument::viewsChanged, this, dropCase);
  syncControls();
}

double RoiStepWidget::thresholdForSlider(int position) {
  return std::pow(10.0, kMinThresholdExponent + static_cast<double>(position) / kThresholdSliderSteps);
}

int RoiStepWidget::sliderForThreshold(double threshold) {
  const double exponent = std::log10(std::max(threshold, std::pow(10.0, kMinThresholdExponent)));
  return static_cast<int>(std::lround((exponent - kMinThresholdExponent) * kThresholdSliderSteps));
}

void RoiStepWidget::attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3>) {
  m_xrayViews = std::move(xrayViews);
  m_exclusionsDrawn = false;
  updateSelection();
}

void RoiStepWidget::setActive(bool active) {
  m_active = active;
  for (XrayViewWidget* view : m_xrayViews) {
    for (const QString& layer : {kRoiLayer, kExcludedLayer, kSphereLayer}) view->setLayerVisible(layer, active);
  }
  updateSelection();
}

double RoiStepWidget::keptFraction(std::size_t v) const {
  return v < m_keptFraction.size() ? m_keptFraction[v] : std::numeric_limits<double>::quiet_NaN();
}

QString RoiStepWidget::message() const { return m_message->text(); }

void RoiStepWidget::showMessage(const QString& text, bool error) {
  m_message->setStyleSheet(error ? QStringLiteral("color: #c0392b;") : QString());
  m_message->setText(text);
}

void RoiStepWidget::setLevel(int level) {
  m_level = std::clamp(level, 0, 2);
  if (m_levelCombo->currentIndex() != m_level) {
    const QSignalBlocker blocker(m_levelCombo);
    m_levelCombo->setCurrentIndex(m_level);
  }
  updateSelection();
}

void RoiStepWidget::syncControls() {
  const RoiParameters& p = m_document->roiParameters();
  const QSignalBlocker b1(m_windowSpin), b2(m_thresholdRadio), b3(m_fractionRadio), b4(m_thresholdSlider),
      b5(m_thresholdSpin), b6(m_fractionSlider), b7(m_fractionSpin), b8(m_marginSpin), b9(m_fieldOfViewCheck),
      b10(m_spheresCheck), b11(m_cutFaceSpin);
  m_windowSpin->setValue(p.windowSize);
  m_thresholdRadio->setChecked(p.useThreshold);
  m_fractionRadio->setChecked(!p.useThreshold);
  m_thresholdSpin->setValue(p.varianceThreshold);
  m_thresholdSlider->setValue(sliderForThreshold(p.varianceThreshold));
  m_fractionSpin->setValue(p.targetFraction);
  m_fractionSlider->setValue(static_cast<int>(std::lround(p.targetFraction * 100.0)));
  m_marginSpin->setValue(p.margin_px);
  m_fieldOfViewCheck->setChecked(p.detectFieldOfView);
  m_spheresCheck->setChecked(p.detectSpheres);
  m_cutFaceSpin->setValue(p.cutFaceMargin_mm < 0.0 ? m_cutFaceSpin->minimum() : p.cutFaceMargin_mm);
  m_thresholdSlider->setEnabled(p.useThreshold);
  m_thresholdSpin->setEnabled(p.useThreshold);
  m_fractionSlider->setEnabled(!p.useThreshold);
  m_fractionSpin->setEnabled(!p.useThreshold);
}

void RoiStepWidget::pushParameters() {
  RoiParameters p = m_document->roiParameters();
  p.windowSize = m_windowSpin->value();
  p.useThreshold = m_thresholdRadio->isChecked();
  p.varianceThreshold = m_thresholdSpin->value();
  if (!p.useThreshold) p.targetFraction = m_fractionSpin->value();
  p.margin_px = m_marginSpin->value();
  p.detectFieldOfView = m_fieldOfViewCheck->isChecked();
  p.detectSpheres = m_spheresCheck->isChecked();
  // Below 0 is off; a document's own negative value stays as it is while the spin box shows "off".
  const double cutFace_mm = m_cutFaceSpin->value();
  if (cutFace_mm >= 0.0 || p.cutFaceMargin_mm >= 0.0) p.cutFaceMargin_mm = cutFace_mm;
  m_document->setRoiParameters(p);
}

bool RoiStepWidget::ensureSelectors() {
  const std::shared_ptr<RegistrationCase>& prepared = m_document->readyCase();
  if (!prepared) {
    // The case is prepared on a worker thread (seconds for a large CT); casePreparationFinished brings the ROIs.
    m_case.reset();
    m_selectors.clear();
    if (!m_document->ct() || m_document->views().empty()) {
      showMessage(tr("No ROIs to show: open a CT and X-ray views in the Data step."), true);
    } else {
      if (!m_document->isPreparingCase()) showMessage(tr("Preparing the case for the ROIs…"), false);
      m_document->prepareCaseInBackground();
    }
    return false;
  }
  const int window = m_document->roiParameters().windowSize;
  if (prepared != m_case) {
    m_case = prepared;
    m_selectors.clear();
    m_exclusionsDrawn = false;
  }
  const int level = std::min(m_level, m_case->levelCount() - 1);
  if (!m_selectors.empty() && m_selectorLevel == level && m_selectorWindow == window) return true;
  m_selectors.clear();
  for (std::size_t v = 0; v < m_case->viewCount(); ++v) {
    const PyramidLevel& pyramidLevel = m_case->prepared(v).pyramid.level(level);
    auto selector = DynamicRoiSelector::create(pyramidLevel.image, pyramidLevel.mask, window);
    if (!selector) {
      m_selectors.clear();
      showMessage(tr("View '%1', level %2: %3")
                      .arg(QString::fromStdString(m_case->viewName(v)))
                      .arg(level)
                      .arg(QString::fromStdString(selector.error())),
                  true);
      return false;
    }
    m_selectors.push_back(std::move(selector).value());
  }
  m_selectorLevel = level;
  m_selectorWindow = window;
  return true;
}

QString RoiStepWidget::exclusionText() const { return m_exclusions->text(); }

void RoiStepWidget::drawExclusions() {
  const RoiParameters& roi = m_document->roiParameters();
  QStringList lines;
  for (std::size_t v = 0; v < m_xrayViews.size() && v < m_case->viewCount(); ++v) {
    const PreparedXray& prepared = m_case->prepared(v);
    const ValidMask& mask = prepared.pyramid.level(0).mask;
    QImage excluded(mask.cols, mask.rows, QImage::Format_ARGB32);
    // Each excluded pixel is coloured by the first reason that explains it: margin, sphere, outside the circular
    // field, else metal or a collimator edge (the masks are merged by XrayPreparation).
    std::array<long, 4> counts{};  // margin, field, sphere, other
    const int m = roi.margin_px;
    for (int row = 0; row < mask.rows; ++row) {
      auto* line = reinterpret_cast<QRgb*>(excluded.scanLine(row));
      for (int col = 0; col < mask.cols; ++col) {
        if (mask.isValid(col, row)) {
          line[col] = 0u;
          continue;
        }
        const bool margin = col < m || row < m || col >= mask.cols - m || row >= mask.rows - m;
        const bool sphere = std::any_of(prepared.spheres.begin(), prepared.spheres.end(), [&](const PixelCircle& s) {
          PixelCircle grown = s;
          grown.radius_px += roi.sphereMargin_px;
          return grown.contains(col, row);
        });
        const bool field = prepared.fieldOfView && !prepared.fieldOfView->contains(col, row);
        const int reason = margin ? 0 : sphere ? 2 : field ? 1 : 3;
        ++counts[static_cast<std::size_t>(reason)];
        static const QRgb kColours[4] = {kMarginColour.rgba(), kExcludedColour.rgba(), kSphereExcludedColour.rgba(),
                                         kOtherExcludedColour.rgba()};
        line[col] = kColours[reason];
      }
    }
    const double total = std::max(1.0, static_cast<double>(mask.cols) * mask.rows);
    const auto share = [&](std::size_t i) { return QString::number(100.0 * counts[i] / total, 'f', 1); };
    lines << tr("%1 excluded: <span style='color:%2'>margin %3 %</span>, <span style='color:%4'>outside the field %5 "
                "%</span>, <span style='color:%6'>spheres %7 %</span>, <span style='color:%8'>%9 %10 %</span>")
                 .arg(QString::fromStdString(m_case->viewName(v)).toHtmlEscaped(), kMarginColour.name(), share(0),
                      kExcludedColour.name(), share(1), kSphereExcludedColour.name(), share(2),
                      kOtherExcludedColour.name(),
                      prepared.metalFraction > 0.0 ? tr("metal or collimator edge") : tr("collimator edge"), share(3));
    m_xrayViews[v]->setImageLayer(kExcludedLayer, std::move(excluded), kExcludedOpacity);
    std::vector<std::vector<Eigen::Vector2d>> spheres;
    for (const PixelCircle& sphere : prepared.spheres) spheres.push_back(circlePolyline(sphere));
    m_xrayViews[v]->setPolylineLayer(kSphereLayer, std::move(spheres), kSphereColour);
  }
  m_exclusions->setText(lines.join(QStringLiteral("<br>")));
  m_exclusionsDrawn = true;
}

void RoiStepWidget::updateSelection() {
  m_keptFraction.assign(m_document->views().size(), std::numeric_limits<double>::quiet_NaN());
  if (!m_active) return;
  if (!ensureSelectors()) {
    for (XrayViewWidget* view : m_xrayViews) {
      for (const QString& layer : {kRoiLayer, kExcludedLayer, kSphereLayer}) view->clearLayer(layer);
    }
    m_fractions->clear();
    return;
  }
  if (!m_exclusionsDrawn) drawExclusions();

  const RoiParameters& p = m_document->roiParameters();
  const int scale = 1 << m_selectorLevel;
  QStringList lines;
  QStringList problems;
  double fractionSum = 0.0;
  int fractionCount = 0;
  m_keptFraction.assign(m_selectors.size(), 0.0);
  for (std::size_t v = 0; v < m_selectors.size(); ++v) {
    auto selection = p.useThreshold ? m_selectors[v].selectAboveThreshold(p.varianceThreshold)
                                    : m_selectors[v].selectFraction(p.targetFraction);
    const QString name = QString::fromStdString(m_case->viewName(v));
    if (selection) {
      m_keptFraction[v] = selection.value().keptFraction;
      fractionSum += m_keptFraction[v];
      ++fractionCount;
    } else {
      problems << tr("%1: %2").arg(name, QString::fromStdString(selection.error()));
    }
    lines << tr("%1: %2 % kept (%3 windows of %4)")
                 .arg(name)
                 .arg(100.0 * m_keptFraction[v], 0, 'f', 1)
                 .arg(selection ? selection.value().windows.size() : 0)
                 .arg(m_selectors[v].candidateCount());
    if (v >= m_xrayViews.size()) continue;
    const ValidMask& mask = m_case->prepared(v).pyramid.level(0).mask;
    QImage rois(mask.cols, mask.rows, QImage::Format_ARGB32_Premultiplied);
    rois.fill(Qt::transparent);
    if (selection) {
      QPainter painter(&rois);
      const int side = selection.value().windowSize * scale;
      for (const RoiWindow& window : selection.value().windows) {
        painter.fillRect(window.col0 * scale, window.row0 * scale, side, side, kRoiColour);
      }
    }
    m_xrayViews[v]->setImageLayer(kRoiLayer, std::move(rois), kRoiOpacity);
  }
  m_fractions->setText(lines.join(QLatin1Char('\n')));
  if (problems.isEmpty()) {
    showMessage(p.useThreshold ? tr("Registration keeps the mean kept fraction, %1 %, in every ROI stage.")
                                     .arg(100.0 * fractionSum / std::max(fractionCount, 1), 0, 'f', 1)
                               : QString(),
                false);
  } else {
    showMessage(problems.join(QLatin1Char('\n')) + tr("\nLower the threshold."), true);
  }

  // Threshold mode: the registration's ROI stages keep the fraction the threshold gives (mean over the views).
  if (p.useThreshold && fractionCount > 0) {
    const double mean = fractionSum / fractionCount;
    if (std::abs(mean - p.targetFraction) > 1e-9) {
      RoiParameters updated = p;
      updated.targetFraction = mean;
      m_syncing = true;
      m_document->setRoiParameters(updated);
      m_syncing = false;
    }
  }
}

}  // namespace fct
