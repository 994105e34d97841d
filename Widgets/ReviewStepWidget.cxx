#include "Widgets/ReviewStepWidget.h"

#include <QApplication>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QFutureWatcher>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPainter>
#include <QPixmap>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>

#include <algorithm>

#include "IO/Project/ItkTransformFile.h"
#include "Interop/IgtlTransformSender.h"
#include "IO/Project/PoseFile.h"
#include "Registration/RegistrationDicomExport.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/XrayViewWidget.h"

namespace fct {

namespace {

QColor colourOf(const std::array<std::uint8_t, 3>& rgb) { return QColor(rgb[0], rgb[1], rgb[2]); }

void setButtonColour(QPushButton* button, const QColor& colour) {
  button->setStyleSheet(QStringLiteral("background-color: %1;").arg(colour.name()));
}

/// The DRR as an 8-bit grey image shaded like the X-ray (white where rays miss the bone, dark through much of it),
/// scaled to its 99th percentile line integral.
QImage greyDrr(const FloatImage& drr) {
  std::vector<float> sorted = drr.pixels;
  const std::size_t k = sorted.size() * 99 / 100;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  const float top = std::max(sorted[k], 1e-6f);
  QImage grey(drr.cols, drr.rows, QImage::Format_Grayscale8);
  for (int row = 0; row < drr.rows; ++row) {
    uchar* line = grey.scanLine(row);
    for (int col = 0; col < drr.cols; ++col) {
      line[col] = static_cast<uchar>(255.0f * (1.0f - std::clamp(drr.at(col, row) / top, 0.0f, 1.0f)));
    }
  }
  return grey;
}

/// The verdict of a result in words.
QString verdictName(ResultVerdict verdict) {
  switch (verdict) {
    case ResultVerdict::Accepted: return QObject::tr("accepted");
    case ResultVerdict::Rejected: return QObject::tr("rejected");
    case ResultVerdict::Undecided: break;
  }
  return QObject::tr("not judged");
}

}  // namespace

ReviewStepWidget::ReviewStepWidget(StudioDocument* document, QWidget* parent)
    : QWidget(parent),
      m_document(document),
      m_initialColour(colourOf(ContourOverlay::kInitialColour)),
      m_finalColour(colourOf(ContourOverlay::kFinalColour)) {
  auto* layout = new QVBoxLayout(this);

  auto* historyRow = new QHBoxLayout();
  m_historyCombo = new QComboBox(this);
  m_historyCombo->setToolTip(tr("Every registration of this session; choose one to review, accept or export it"));
  historyRow->addWidget(new QLabel(tr("Result"), this));
  historyRow->addWidget(m_historyCombo, 1);
  layout->addLayout(historyRow);

  auto* contourBox = new QGroupBox(tr("Bone outlines"), this);
  auto* contourForm = new QFormLayout(contourBox);
  auto* initialRow = new QHBoxLayout();
  m_initialCheck = new QCheckBox(tr("Initial pose"), contourBox);
  m_initialCheck->setChecked(true);
  m_initialColourButton = new QPushButton(tr("Colour…"), contourBox);
  initialRow->addWidget(m_initialCheck);
  initialRow->addWidget(m_initialColourButton);
  contourForm->addRow(initialRow);
  auto* finalRow = new QHBoxLayout();
  m_finalCheck = new QCheckBox(tr("Final pose"), contourBox);
  m_finalCheck->setChecked(true);
  m_finalColourButton = new QPushButton(tr("Colour…"), contourBox);
  finalRow->addWidget(m_finalCheck);
  finalRow->addWidget(m_finalColourButton);
  contourForm->addRow(finalRow);
  m_contourOpacitySlider = new QSlider(Qt::Horizontal, contourBox);
  m_contourOpacitySlider->setRange(0, 100);
  m_contourOpacitySlider->setValue(100);
  contourForm->addRow(tr("Opacity"), m_contourOpacitySlider);
  layout->addWidget(contourBox);
  setButtonColour(m_initialColourButton, m_initialColour);
  setButtonColour(m_finalColourButton, m_finalColour);

  auto* drrBox = new QGroupBox(tr("DRR at the final pose"), this);
  auto* drrForm = new QFormLayout(drrBox);
  m_drrModeCombo = new QComboBox(drrBox);
  m_drrModeCombo->addItems({tr("Off"), tr("Blend"), tr("Checkerboard")});
  drrForm->addRow(tr("Show"), m_drrModeCombo);
  m_drrOpacitySlider = new QSlider(Qt::Horizontal, drrBox);
  m_drrOpacitySlider->setRange(0, 100);
  m_drrOpacitySlider->setValue(50);
  drrForm->addRow(tr("Blend"), m_drrOpacitySlider);
  m_flickerCheck = new QCheckBox(tr("Flicker"), drrBox);
  drrForm->addRow(m_flickerCheck);
  layout->addWidget(drrBox);

  m_treLabel = new QLabel(this);
  m_treLabel->setWordWrap(true);
  layout->addWidget(m_treLabel);

  auto* verdictRow = new QHBoxLayout();
  auto* acceptButton = new QPushButton(tr("Accept"), this);
  auto* rejectButton = new QPushButton(tr("Reject"), this);
  verdictRow->addWidget(acceptButton);
  verdictRow->addWidget(rejectButton);
  layout->addLayout(verdictRow);
  m_verdictLabel = new QLabel(this);
  layout->addWidget(m_verdictLabel);

  auto* exportRow = new QHBoxLayout();
  auto* exportButton = new QPushButton(tr("Export pose…"), this);
  auto* dicomButton = new QPushButton(tr("Export DICOM registration…"), this);
  dicomButton->setToolTip(tr("Write the final pose as a DICOM Spatial Registration object (REG) referring to the CT "
                             "series and the DICOM X-rays, for a navigation system or PACS"));
  auto* screenshotButton = new QPushButton(tr("Screenshot…"), this);
  exportRow->addWidget(exportButton);
  exportRow->addWidget(dicomButton);
  exportRow->addWidget(screenshotButton);
  layout->addLayout(exportRow);

  auto* slicerBox = new QGroupBox(tr("3D Slicer (OpenIGTLink)"), this);
  auto* slicerRow = new QHBoxLayout(slicerBox);
  m_slicerHost = new QLineEdit(QStringLiteral("localhost"), slicerBox);
  m_slicerHost->setToolTip(tr("Host of 3D Slicer's OpenIGTLinkIF server connector"));
  m_slicerPort = new QSpinBox(slicerBox);
  m_slicerPort->setRange(1, 65535);
  m_slicerPort->setValue(18944);
  m_sendToSlicerButton = new QPushButton(tr("Send to Slicer"), slicerBox);
  m_sendToSlicerButton->setObjectName(QStringLiteral("sendToSlicerButton"));
  m_sendToSlicerButton->setToolTip(tr("Send the final pose as the OpenIGTLink TRANSFORM 'FluoroCT' (RAS)"));
  slicerRow->addWidget(m_slicerHost, 1);
  slicerRow->addWidget(m_slicerPort);
  slicerRow->addWidget(m_sendToSlicerButton);
  layout->addWidget(slicerBox);
  m_slicerSend = new QFutureWatcher<QString>(this);
  m_message = new QLabel(this);
  m_message->setWordWrap(true);
  m_message->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(m_message);
  layout->addStretch(1);

  m_flickerTimer = new QTimer(this);
  m_flickerTimer->setInterval(kFlickerInterval_ms);
  connect(m_flickerTimer, &QTimer::timeout, this, [this] {
    m_flickerShown = !m_flickerShown;
    for (XrayViewWidget* view : m_xrayViews) view->setLayerVisible(kDrrLayer, m_active && m_flickerShown);
  });

  connect(m_initialCheck, &QCheckBox::toggled, this, &ReviewStepWidget::setShowInitial);
  connect(m_finalCheck, &QCheckBox::toggled, this, &ReviewStepWidget::setShowFinal);
  connect(m_initialColourButton, &QPushButton::clicked, this, [this] {
    const QColor colour = QColorDialog::getColor(m_initialColour, this, tr("Initial outline colour"));
    if (colour.isValid()) setContourColours(colour, m_finalColour);
  });
  connect(m_finalColourButton, &QPushButton::clicked, this, [this] {
    const QColor colour = QColorDialog::getColor(m_finalColour, this, tr("Final outline colour"));
    if (colour.isValid()) setContourColours(m_initialColour, colour);
  });
  connect(m_contourOpacitySlider, &QSlider::valueChanged, this, [this](int value) { setContourOpacity(value / 100.0); });
  connect(m_drrModeCombo, &QComboBox::currentIndexChanged, this,
          [this](int index) { setDrrMode(static_cast<DrrMode>(index)); });
  connect(m_drrOpacitySlider, &QSlider::valueChanged, this, [this](int value) { setDrrOpacity(value / 100.0); });
  connect(m_flickerCheck, &QCheckBox::toggled, this, &ReviewStepWidget::setFlicker);
  connect(m_historyCombo, &QComboBox::activated, m_document, &StudioDocument::setCurrentResult);
  connect(acceptButton, &QPushButton::clicked, this, &ReviewStepWidget::acceptResult);
  connect(rejectButton, &QPushButton::clicked, this, &ReviewStepWidget::rejectResult);
  connect(exportButton, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Export pose"), m_document->suggestedPath(QStringLiteral("pose.tfm")),
                                                      tr("3D Slicer transform (*.tfm);;Pose JSON (*.json)"));
    if (!path.isEmpty()) exportPose(path);
  });
  connect(m_sendToSlicerButton, &QPushButton::clicked, this, &ReviewStepWidget::sendToSlicer);
  connect(m_slicerSend, &QFutureWatcher<QString>::finished, this, [this] {
    m_sendToSlicerButton->setEnabled(true);
    const QString error = m_slicerSend->result();
    const QString where = QStringLiteral("%1:%2").arg(m_slicerHost->text().trimmed()).arg(m_slicerPort->value());
    if (error.isEmpty()) {
      showMessage(tr("Sent the final pose to 3D Slicer at %1 as the transform 'FluoroCT'.").arg(where), false);
    } else {
      showMessage(tr("Not sent to 3D Slicer: %1").arg(error), true);
    }
    emit slicerSendFinished(error.isEmpty());
  });
  connect(dicomButton, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Export DICOM registration"),
                                                      QStringLiteral("registration.dcm"), tr("DICOM file (*.dcm)"));
    if (!path.isEmpty()) exportDicomRegistration(path);
  });
  connect(screenshotButton, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save screenshot"), m_document->suggestedPath(QStringLiteral("review.png")),
                                                      tr("PNG image (*.png)"));
    if (!path.isEmpty()) saveScreenshot(path);
  });

  for (auto signal : {&StudioDocument::ctChanged, &StudioDocument::viewsChanged, &StudioDocument::truthPoseChanged}) {
    connect(m_document, signal, this, [this] {
      if (m_active) refresh();
    });
  }
  // A verdict also emits resultChanged: redraw only when a pose shown changed.
  for (auto signal : {&StudioDocument::resultChanged, &StudioDocument::initialPoseChanged}) {
    connect(m_document, signal, this, [this] {
      if (m_active && reviewedPoses() != m_shownPoses) refresh();
    });
  }
  connect(m_document, &StudioDocument::casePreparationFinished, this, [this](bool prepared) {
    if (m_active && prepared && m_shownPoses.second && m_drrGrey.empty()) refresh();
  });
  connect(m_document, &StudioDocument::resultChanged, this, &ReviewStepWidget::updateVerdict);
  updateVerdict();
}

void ReviewStepWidget::attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3>) {
  m_xrayViews = std::move(xrayViews);
  if (m_active) refresh();
}

void ReviewStepWidget::setActive(bool active) {
  m_active = active;
  if (active) {
    refresh();
  } else {
    m_flickerTimer->stop();
    for (XrayViewWidget* view : m_xrayViews) {
      for (const QString& layer : {kInitialLayer, kFinalLayer, kDrrLayer}) view->setLayerVisible(layer, false);
    }
  }
}

QString ReviewStepWidget::message() const { return m_message->text(); }

bool ReviewStepWidget::isFlickering() const { return m_flickerTimer->isActive(); }

void ReviewStepWidget::showMessage(const QString& text, bool error) {
  m_message->setStyleSheet(error ? QStringLiteral("color: #c0392b;") : QString());
  m_message->setText(text);
}

bool ReviewStepWidget::ensureOverlay() {
  const auto& ct = m_document->ct();
  if (!ct) {
    m_overlay.reset();
    m_bone.reset();
    m_overlayCt.reset();
    showMessage(tr("No CT loaded: open a CT in the Data step first."), true);
    return false;
  }
  if (ct == m_overlayCt && m_overlay) return true;
  auto overlay = ContourOverlay::create(*ct);
  if (!overlay) {
    showMessage(tr("No bone outline: %1").arg(QString::fromStdString(overlay.error())), true);
    return false;
  }
  auto bone = BoneSurface::extract(*ct);
  m_overlay = std::move(overlay).value();
  m_bone = bone ? std::optional<BoneSurface>(std::move(bone).value()) : std::nullopt;
  m_overlayCt = ct;
  return true;
}

ReviewStepWidget::PosePair ReviewStepWidget::reviewedPoses() const {
  const auto& result = m_document->result();
  if (!result) {
    const auto& initial = m_document->initialPose();
    return {initial ? std::optional<Eigen::Matrix4d>(initial->matrix()) : std::nullopt, std::nullopt};
  }
  return {result->T_initial.matrix(), result->T_world_from_ct.matrix()};
}

void ReviewStepWidget::refresh() {
  m_initialContours.clear();
  m_finalContours.clear();
  m_drrGrey.clear();
  m_finalTre_mm.reset();
  m_treLabel->clear();
  m_shownPoses = reviewedPoses();
  const auto& result = m_document->result();
  const auto asPose = [](const std::optional<Eigen::Matrix4d>& matrix) {
    return matrix ? std::optional<Eigen::Isometry3d>(Eigen::Isometry3d(*matrix)) : std::nullopt;
  };
  const std::optional<Eigen::Isometry3d> initial = asPose(m_shownPoses.first);
  const std::optional<Eigen::Isometry3d> final = asPose(m_shownPoses.second);
  if (!initial && !final) {
    showMessage(tr("Nothing to review yet: set an initial pose and run a registration."), false);
    drawContours();
    drawDrr();
    return;
  }
  if (!ensureOverlay()) return;
  QApplication::setOverrideCursor(Qt::WaitCursor);
  const auto& views = m_document->views();
  QStringList problems;
  for (std::size_t v = 0; v < views.size(); ++v) {
    for (auto [pose, contours] : {std::pair{&initial, &m_initialContours}, std::pair{&final, &m_finalContours}}) {
      contours->emplace_back();
      if (!*pose) continue;
      auto projected = m_overlay->contours(views[v].camera, **pose);
      if (projected) {
        contours->back() = XrayViewWidget::polylines(projected.value());
      } else {
        problems << QString::fromStdString(views[v].name + ": " + projected.error());
      }
    }
  }
  if (final && !m_document->readyCase()) {
    // The DRR needs the prepared case: it is made on a worker thread and casePreparationFinished redraws.
    m_document->prepareCaseInBackground();
  } else if (final) {
    const DrrRenderer& renderer = m_document->readyCase()->renderer();
    for (std::size_t v = 0; v < views.size(); ++v) {
      auto drr = renderer.render(views[v].camera, *final, 0);
      if (drr) {
        m_drrGrey.push_back(greyDrr(drr.value()));
      } else {
        m_drrGrey.emplace_back();
        problems << QString::fromStdString(views[v].name + ": " + drr.error());
      }
    }
  }
  QApplication::restoreOverrideCursor();

  const auto& truth = m_document->truthPose();
  if (truth && m_bone) {
    QString text = tr("sTRE (mean bone-surface distance to the truth):");
    if (initial) text += tr(" initial %1 mm").arg(m_bone->meanDistance_mm(*initial, *truth), 0, 'f', 2);
    if (final) {
      m_finalTre_mm = m_bone->meanDistance_mm(*final, *truth);
      text += tr(", final %1 mm").arg(*m_finalTre_mm, 0, 'f', 2);
    }
    m_treLabel->setText(text);
  }
  if (!problems.isEmpty()) {
    showMessage(problems.join(QLatin1Char('\n')), true);
  } else if (result && result->cancelled) {
    showMessage(tr("This result is from a cancelled run: the best pose found before cancelling."), false);
  } else {
    showMessage(final ? QString() : tr("No registration result yet: the outline shows the initial pose."), false);
  }
  drawContours();
  drawDrr();
}

void ReviewStepWidget::drawContours() {
  for (std::size_t v = 0; v < m_xrayViews.size(); ++v) {
    XrayViewWidget* view = m_xrayViews[v];
    const auto layerOf = [&](const QString& name, const auto& contours, const QColor& colour, bool show) {
      if (v >= contours.size() || contours[v].empty()) {
        view->clearLayer(name);
        return;
      }
      view->setPolylineLayer(name, contours[v], colour, m_contourOpacity);
      view->setLayerVisible(name, m_active && show);
    };
    layerOf(kInitialLayer, m_initialContours, m_initialColour, m_showInitial);
    layerOf(kFinalLayer, m_finalContours, m_finalColour, m_showFinal);
  }
}

void ReviewStepWidget::drawDrr() {
  for (std::size_t v = 0; v < m_xrayViews.size(); ++v) {
    XrayViewWidget* view = m_xrayViews[v];
    if (m_drrMode == DrrMode::Off || v >= m_drrGrey.size() || m_drrGrey[v].isNull()) {
      view->clearLayer(kDrrLayer);
      continue;
    }
    const QImage& grey = m_drrGrey[v];
    QImage argb = grey.convertToFormat(QImage::Format_ARGB32);
    double opacity = m_drrOpacity;
    if (m_drrMode == DrrMode::Checkerboard) {
      const int square = std::max(8, std::max(argb.width(), argb.height()) / 8);
      for (int row = 0; row < argb.height(); ++row) {
        auto* line = reinterpret_cast<QRgb*>(argb.scanLine(row));
        for (int col = 0; col < argb.width(); ++col) {
          if (((col / square) + (row / square)) % 2 == 1) line[col] = 0u;
        }
      }
      opacity = 1.0;
    }
    view->setImageLayer(kDrrLayer, std::move(argb), opacity);
    view->setLayerVisible(kDrrLayer, m_active && (!isFlickering() || m_flickerShown));
  }
}

void ReviewStepWidget::setShowInitial(bool show) {
  m_showInitial = show;
  const QSignalBlocker blocker(m_initialCheck);
  m_initialCheck->setChecked(show);
  drawContours();
}

void ReviewStepWidget::setShowFinal(bool show) {
  m_showFinal = show;
  const QSignalBlocker blocker(m_finalCheck);
  m_finalCheck->setChecked(show);
  drawContours();
}

void ReviewStepWidget::setContourColours(const QColor& initial, const QColor& final) {
  m_initialColour = initial;
  m_finalColour = final;
  setButtonColour(m_initialColourButton, initial);
  setButtonColour(m_finalColourButton, final);
  drawContours();
}

void ReviewStepWidget::setContourOpacity(double opacity) {
  m_contourOpacity = std::clamp(opacity, 0.0, 1.0);
  drawContours();
}

void ReviewStepWidget::setDrrMode(DrrMode mode) {
  m_drrMode = mode;
  const QSignalBlocker blocker(m_drrModeCombo);
  m_drrModeCombo->setCurrentIndex(static_cast<int>(mode));
  drawDrr();
}

void ReviewStepWidget::setDrrOpacity(double opacity) {
  m_drrOpacity = std::clamp(opacity, 0.0, 1.0);
  drawDrr();
}

void ReviewStepWidget::setFlicker(bool on) {
  {
    const QSignalBlocker blocker(m_flickerCheck);
    m_flickerCheck->setChecked(on);
  }
  if (on && m_drrMode == DrrMode::Off) setDrrMode(DrrMode::Blend);
  m_flickerShown = true;
  if (on && m_active) {
    m_flickerTimer->start();
  } else {
    m_flickerTimer->stop();
  }
  drawDrr();
}

void ReviewStepWidget::acceptResult() {
  if (!m_document->result()) {
    showMessage(tr("No registration result to accept: run one in the Register step."), true);
    return;
  }
  m_document->setResultVerdict(ResultVerdict::Accepted);
}

void ReviewStepWidget::rejectResult() {
  if (!m_document->result()) {
    showMessage(tr("No registration result to reject: run one in the Register step."), true);
    return;
  }
  m_document->setResultVerdict(ResultVerdict::Rejected);
}

void ReviewStepWidget::updateVerdict() {
  {
    const QSignalBlocker blocker(m_historyCombo);
    m_historyCombo->clear();
    const auto& results = m_document->results();
    for (std::size_t i = 0; i < results.size(); ++i) {
      const RegistrationResult& r = results[i].result;
      m_historyCombo->addItem(tr("%1. %2, %3 s%4 — %5")
                                  .arg(i + 1)
                                  .arg(QString::fromStdString(r.schedule.name))
                                  .arg(r.totalSeconds, 0, 'f', 1)
                                  .arg(r.cancelled ? tr(", cancelled") : QString())
                                  .arg(verdictName(results[i].verdict)));
    }
    m_historyCombo->setCurrentIndex(m_document->currentResultIndex());
    m_historyCombo->setEnabled(results.size() > 1);
  }
  const auto& result = m_document->result();
  if (!result) {
    m_verdictLabel->setText(tr("No result"));
    return;
  }
  const QString cancelled = result->cancelled ? tr(" (cancelled run)") : QString();
  switch (m_document->resultVerdict()) {
    case ResultVerdict::Accepted: m_verdictLabel->setText(tr("Accepted") + cancelled); break;
    case ResultVerdict::Rejected: m_verdictLabel->setText(tr("Rejected") + cancelled); break;
    case ResultVerdict::Undecided: m_verdictLabel->setText(tr("Not yet accepted or rejected") + cancelled); break;
  }
}

bool ReviewStepWidget::exportPose(const QString& path) {
  const auto& result = m_document->result();
  if (!result) {
    showMessage(tr("No registration result to export: run one in the Register step."), true);
    return false;
  }
  const std::filesystem::path file = path.toStdString();
  const Status written = path.endsWith(QStringLiteral(".tfm"), Qt::CaseInsensitive)
                             ? ItkTransformFile::write(result->T_world_from_ct, file)
                             : PoseFile::write(result->T_world_from_ct, file);
  if (!written) {
    showMessage(tr("Cannot export the pose: %1").arg(QString::fromStdString(written.error())), true);
    return false;
  }
  showMessage(tr("Exported the final pose%1 to %2.").arg(result->cancelled ? tr(" (cancelled run)") : QString(), path),
              false);
  return true;
}

void ReviewStepWidget::setSlicerAddress(const QString& host, int port) {
  m_slicerHost->setText(host);
  m_slicerPort->setValue(port);
}

void ReviewStepWidget::sendToSlicer() {
  if (m_slicerSend->isRunning()) return;
  const auto& result = m_document->result();
  const QString host = m_slicerHost->text().trimmed();
  if (!result || host.isEmpty()) {
    showMessage(result ? tr("Enter the host of 3D Slicer (e.g. localhost) before sending.")
                       : tr("No registration result to send: run one in the Register step."),
                true);
    emit slicerSendFinished(false);
    return;
  }
  const IgtlEndpoint endpoint{host.toStdString(), m_slicerPort->value()};
  const Eigen::Isometry3d T_world_from_ct = result->T_world_from_ct;
  m_sendToSlicerButton->setEnabled(false);
  showMessage(tr("Sending the final pose to 3D Slicer at %1…").arg(QString::fromStdString(endpoint.text())), false);
  m_slicerSend->setFuture(QtConcurrent::run([endpoint, T_world_from_ct] {
    IgtlTransformSender sender(endpoint, "FluoroCT");
    const Status sent = sender.send(T_world_from_ct);
    return sent ? QString() : QString::fromStdString(sent.error());
  }));
}

bool ReviewStepWidget::exportDicomRegistration(const QString& path) {
  const auto& result = m_document->result();
  if (!result || !m_document->ct()) {
    showMessage(tr("No registration result to export: run one in the Register step."), true);
    return false;
  }
  auto written =
      RegistrationDicomExport::write(*m_document->ct(), m_document->views(), *result, path.toStdString());
  if (!written) {
    showMessage(tr("Cannot export the DICOM registration: %1").arg(QString::fromStdString(written.error())), true);
    return false;
  }
  QString text = tr("Exported the final pose%1 as a DICOM registration to %2.")
                     .arg(result->cancelled ? tr(" (cancelled run)") : QString(), path);
  for (const std::string& warning : written.warnings()) text += QStringLiteral("\n") + QString::fromStdString(warning);
  showMessage(text, false);
  return true;
}

bool ReviewStepWidget::saveScreenshot(const QString& path) {
  if (m_xrayViews.empty()) {
    showMessage(tr("No X-ray views to capture."), true);
    return false;
  }
  std::vector<QPixmap> shots;
  int width = 0;
  int height = 0;
  for (XrayViewWidget* view : m_xrayViews) {
    shots.push_back(view->grab());
    width += shots.back().width();
    height = std::max(height, shots.back().height());
  }
  QImage combined(std::max(width, 1), std::max(height, 1), QImage::Format_RGB32);
  combined.fill(Qt::black);
  {
    QPainter painter(&combined);
    int x = 0;
    for (const QPixmap& shot : shots) {
      painter.drawPixmap(x, 0, shot);
      x += shot.width();
    }
  }
  if (!combined.save(path, "PNG")) {
    showMessage(tr("Cannot write the screenshot to '%1'; check the folder exists and is writable.").arg(path), true);
    return false;
  }
  showMessage(tr("Saved the screenshot to %1.").arg(path), false);
  return true;
}

}  // namespace fct
