#include "Widgets/TrackStepWidget.h"

#include <QCheckBox>
#include <QFileDialog>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QThread>
#include <QVBoxLayout>

#include <algorithm>

#include <fmt/format.h>

#include "Evaluation/LineChart.h"
#include "Evaluation/TrackPoseChart.h"
#include "IO/Project/ViewFile.h"
#include "Registration/RegistrationViewLoader.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/WorkerThread.h"
#include "Widgets/XrayViewWidget.h"

namespace fct {

namespace {

/// The chart as a QImage (a deep copy of the RGB pixels).
QImage toQImage(const RgbImage& rgb) {
  const QImage view(rgb.pixels.data(), rgb.cols, rgb.rows, 3 * rgb.cols, QImage::Format_RGB888);
  return view.copy();
}

/// Reads every frame of a view file's sequences: frames[f][v]; fails naming the view and frame.
Result<TrackingSequence> readSequence(const std::filesystem::path& viewFile) {
  auto specs = ViewFile::read(viewFile);
  if (!specs) return fail(specs.error());
  TrackingSequence sequence;
  int frames = -1;
  for (const ViewSpec& spec : specs.value()) {
    if (!spec.sequence) {
      return fail(fmt::format("view '{}' of '{}' has no \"sequence\": give each view its frames (a multi-frame DICOM "
                              "file or a list of image files) to track",
                              spec.name, viewFile.string()));
    }
    frames = spec.sequence->frameCount();
  }
  sequence.frames.resize(static_cast<std::size_t>(frames));
  for (const ViewSpec& spec : specs.value()) {
    for (int f = 0; f < frames; ++f) {
      auto view = RegistrationViewLoader::loadFrame(spec, f);
      if (!view) return fail(view.error());
      if (f == 0) sequence.views.push_back(view.value());
      sequence.frames[static_cast<std::size_t>(f)].push_back(std::move(view.value().xray));
    }
  }
  return sequence;
}

}  // namespace

TrackStepWidget::TrackStepWidget(StudioDocument* document, QWidget* parent) : QWidget(parent), m_document(document) {
  qRegisterMetaType<fct::TrackedFrame>();
  qRegisterMetaType<Eigen::Vector3d>("Eigen::Vector3d");
  auto* layout = new QVBoxLayout(this);
  auto* intro = new QLabel(tr("Follow the bone through a fluoroscopy sequence of these C-arm views. Frame 0 is "
                              "registered from the current result (or the initial pose); every later frame starts "
                              "from the one before."),
                           this);
  intro->setWordWrap(true);
  layout->addWidget(intro);

  auto* loadRow = new QHBoxLayout();
  m_loadButton = new QPushButton(tr("Load sequence…"), this);
  m_loadButton->setToolTip(tr("A view file whose views give \"sequence\" frames (see the README, View file)"));
  m_sequenceLabel = new QLabel(tr("No sequence loaded"), this);
  m_sequenceLabel->setWordWrap(true);
  loadRow->addWidget(m_loadButton);
  loadRow->addWidget(m_sequenceLabel, 1);
  layout->addLayout(loadRow);

  auto* runRow = new QHBoxLayout();
  m_trackButton = new QPushButton(tr("Track"), this);
  m_cancelButton = new QPushButton(tr("Cancel"), this);
  m_cancelButton->setEnabled(false);
  m_progressBar = new QProgressBar(this);
  m_progressBar->setRange(0, 1);
  m_progressBar->setValue(0);
  runRow->addWidget(m_trackButton);
  runRow->addWidget(m_cancelButton);
  runRow->addWidget(m_progressBar, 1);
  layout->addLayout(runRow);

  auto* frameRow = new QHBoxLayout();
  m_frameSlider = new QSlider(Qt::Horizontal, this);
  m_frameSlider->setRange(0, 0);
  m_frameSlider->setEnabled(false);
  m_outlineCheck = new QCheckBox(tr("Outline"), this);
  m_outlineCheck->setChecked(true);
  m_outlineCheck->setToolTip(tr("The projected bone outline at the frame's tracked pose"));
  frameRow->addWidget(new QLabel(tr("Frame"), this));
  frameRow->addWidget(m_frameSlider, 1);
  frameRow->addWidget(m_outlineCheck);
  layout->addLayout(frameRow);
  m_frameLabel = new QLabel(this);
  m_frameLabel->setWordWrap(true);
  layout->addWidget(m_frameLabel);

  m_chartLabel = new QLabel(this);
  m_chartLabel->setAlignment(Qt::AlignCenter);
  m_chartLabel->setMinimumHeight(160);
  layout->addWidget(m_chartLabel);
  m_message = new QLabel(this);
  m_message->setWordWrap(true);
  layout->addWidget(m_message);
  layout->addStretch(1);

  connect(m_loadButton, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Load a fluoroscopy sequence"), QString(),
                                                      tr("View files (*.json);;All files (*)"));
    if (!path.isEmpty()) (void)loadSequence(path.toStdString());  // a failure is shown in the message line
  });
  connect(m_trackButton, &QPushButton::clicked, this, &TrackStepWidget::startTracking);
  connect(m_cancelButton, &QPushButton::clicked, this, &TrackStepWidget::cancel);
  connect(m_frameSlider, &QSlider::valueChanged, this, &TrackStepWidget::showFrame);
  connect(m_outlineCheck, &QCheckBox::toggled, this, [this] { showFrame(shownFrame()); });
  // A new CT or new views make the sequence and the track belong to another case.
  for (auto signal : {&StudioDocument::ctChanged, &StudioDocument::viewsChanged}) {
    connect(m_document, signal, this, [this] {
      if (isRunning() || !m_sequence) return;
      m_sequence.reset();
      m_tracked.clear();
      m_chart = QImage();
      m_chartLabel->clear();
      m_frameSlider->setRange(0, 0);
      m_frameSlider->setEnabled(false);
      m_sequenceLabel->setText(tr("No sequence loaded"));
      m_frameLabel->clear();
      if (m_active) restoreViews();
      showMessage(tr("The case changed: load the sequence again."), false);
    });
  }
}

TrackStepWidget::~TrackStepWidget() {
  if (m_worker) m_worker->cancel();
  endThread();
}

void TrackStepWidget::attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3>) {
  if (m_active) restoreViews();
  m_xrayViews = std::move(xrayViews);
  if (m_active) showFrame(shownFrame());
}

void TrackStepWidget::setActive(bool active) {
  m_active = active;
  if (active) {
    if (m_sequence) showFrame(shownFrame());
  } else {
    restoreViews();
  }
}

Status TrackStepWidget::loadSequence(const std::filesystem::path& viewFile) {
  if (isRunning()) {
    showMessage(tr("Tracking is under way: cancel it before loading another sequence."), true);
    return fail("tracking is under way");
  }
  auto sequence = readSequence(viewFile);
  if (sequence) {
    // The sequence must be of the case's views: their X-ray views show it, and frame 0 starts from their pose.
    const auto& caseViews = m_document->views();
    std::string mismatch;
    if (sequence.value().views.size() != caseViews.size()) {
      mismatch = fmt::format("it has {} views, the open case {}", sequence.value().views.size(), caseViews.size());
    }
    for (std::size_t v = 0; mismatch.empty() && v < caseViews.size(); ++v) {
      const RegistrationView& mine = sequence.value().views[v];
      const RegistrationView& theirs = caseViews[v];
      if (mine.name != theirs.name || mine.xray.cols != theirs.xray.cols || mine.xray.rows != theirs.xray.rows) {
        mismatch = fmt::format("its view {} is '{}' of {}x{} pixels, the open case's '{}' of {}x{}", v + 1, mine.name,
                               mine.xray.cols, mine.xray.rows, theirs.name, theirs.xray.cols, theirs.xray.rows);
      }
    }
    if (!mismatch.empty()) {
      sequence = fail(fmt::format("'{}' is not a sequence of the open case's C-arm views: {}; open the case the "
                                  "sequence was taken with, or a sequence of these views",
                                  viewFile.string(), mismatch));
    }
  }
  if (!sequence) {
    showMessage(tr("Cannot load the sequence: %1").arg(QString::fromStdString(sequence.error())), true);
    return fail(sequence.error());
  }
  m_sequence = std::make_shared<const TrackingSequence>(std::move(sequence).value());
  m_sequenceWindowed = false;
  m_tracked.clear();
  m_chart = QImage();
  m_chartLabel->clear();
  m_sequenceLabel->setText(tr("%1: %2 frames of %3 views")
                               .arg(QString::fromStdString(viewFile.filename().string()))
                               .arg(frameCount())
                               .arg(m_sequence->views.size()));
  m_frameSlider->setRange(0, frameCount() - 1);
  m_frameSlider->setValue(0);
  m_frameSlider->setEnabled(true);
  m_progressBar->setRange(0, frameCount());
  m_progressBar->setValue(0);
  showMessage(tr("Sequence loaded: press Track."), false);
  if (m_active) showFrame(0);
  return Ok{};
}

int TrackStepWidget::frameCount() const { return m_sequence ? static_cast<int>(m_sequence->frames.size()) : 0; }

int TrackStepWidget::shownFrame() const { return m_frameSlider->value(); }

QString TrackStepWidget::message() const { return m_message->text(); }

std::optional<Eigen::Isometry3d> TrackStepWidget::startPose() const {
  if (const RegistrationResult* result = m_document->result()) return result->T_world_from_ct;
  return m_document->initialPose();
}

void TrackStepWidget::startTracking() {
  if (isRunning()) return;
  const std::optional<Eigen::Isometry3d> T_start = startPose();
  QString refusal;
  if (!m_document->ct()) {
    refusal = tr("No CT loaded: open a CT in the Data step first.");
  } else if (!m_sequence) {
    refusal = tr("No sequence loaded: load one with Load sequence….");
  } else if (!T_start) {
    refusal = tr("No start pose: register in the Register step (or set an initial pose) first.");
  }
  if (!refusal.isEmpty()) {
    showMessage(refusal, true);
    return;
  }
  auto caseOptions = m_document->caseOptions();
  if (!caseOptions) {
    showMessage(tr("Cannot track: %1").arg(QString::fromStdString(caseOptions.error())), true);
    return;
  }
  CineTrackerOptions trackerOptions;
  trackerOptions.firstFrame.seed = m_document->registrationOptions().seed;
  m_tracked.clear();
  m_chart = QImage();
  m_chartLabel->clear();
  m_progressBar->setValue(0);
  m_worker = new TrackingWorker(m_document->ct(), m_sequence, *T_start, std::move(caseOptions).value(), trackerOptions);
  m_thread = new QThread(this);
  m_worker->moveToThread(m_thread);
  connect(m_thread, &QThread::started, m_worker, &TrackingWorker::run);
  connect(m_worker, &TrackingWorker::caseReady, this, &TrackStepWidget::onCaseReady);
  connect(m_worker, &TrackingWorker::frameTracked, this, &TrackStepWidget::onFrameTracked);
  connect(m_worker, &TrackingWorker::finished, this, &TrackStepWidget::onFinished);
  connect(m_worker, &TrackingWorker::failed, this, &TrackStepWidget::onFailed);
  setRunningUi(true);
  showMessage(tr("Preparing the CT and registering frame 0…"), false);
  m_thread->start();
  emit runningChanged(true);
}

void TrackStepWidget::cancel() {
  if (!m_worker) return;
  m_worker->cancel();
  m_cancelButton->setEnabled(false);
  showMessage(tr("Cancelling: the frames tracked so far are kept."), false);
}

void TrackStepWidget::onCaseReady(const Eigen::Vector3d& rotationCentre_ct_mm) {
  m_rotationCentre_ct_mm = rotationCentre_ct_mm;
}

void TrackStepWidget::onFrameTracked(const TrackedFrame& frame) {
  m_tracked.push_back(frame);
  m_progressBar->setValue(static_cast<int>(m_tracked.size()));
  showMessage(tr("Frame %1 of %2: %3").arg(frame.index).arg(frameCount() - 1).arg(CineTracker::statusName(frame.status)),
              false);
  updateChart();
  showFrame(frame.index);  // the slider follows the run
  emit frameDone(frame.index);
}

void TrackStepWidget::onFinished(int frames, bool cancelled) {
  endThread();
  setRunningUi(false);
  int recovered = 0, lost = 0;
  double seconds = 0.0;
  for (std::size_t i = 1; i < m_tracked.size(); ++i) seconds += m_tracked[i].seconds;
  for (const TrackedFrame& frame : m_tracked) {
    recovered += frame.status == TrackedFrameStatus::Recovered;
    lost += frame.status == TrackedFrameStatus::Lost;
  }
  const QString rate = m_tracked.size() > 1 && seconds > 0.0
                           ? tr(", %1 frames/s after frame 0").arg(static_cast<double>(m_tracked.size() - 1) / seconds, 0, 'f', 1)
                           : QString();
  showMessage(tr("%1 %2 of %3 frames: %4 recovered, %5 lost%6.")
                  .arg(cancelled ? tr("Cancelled after") : tr("Tracked"))
                  .arg(frames)
                  .arg(frameCount())
                  .arg(recovered)
                  .arg(lost)
                  .arg(rate),
              lost > 0);
  emit runningChanged(false);
}

void TrackStepWidget::onFailed(const QString& message) {
  endThread();
  setRunningUi(false);
  showMessage(tr("Tracking failed: %1").arg(message), true);
  emit runningChanged(false);
}

void TrackStepWidget::endThread() { endWorkerThread(m_thread, m_worker); }

void TrackStepWidget::showFrame(int index) {
  if (!m_sequence) return;
  index = std::clamp(index, 0, frameCount() - 1);
  {
    const QSignalBlocker blocker(m_frameSlider);
    m_frameSlider->setValue(index);
  }
  if (!m_active) return;
  const auto& images = m_sequence->frames[static_cast<std::size_t>(index)];
  const TrackedFrame* tracked = static_cast<std::size_t>(index) < m_tracked.size() ? &m_tracked[index] : nullptr;
  QStringList problems;
  const bool outline = tracked && m_outlineCheck->isChecked() && ensureOverlay();
  for (std::size_t v = 0; v < m_xrayViews.size() && v < images.size(); ++v) {
    // The first frame shown gets the automatic window of its own values (the case's X-rays may be on another scale);
    // later frames keep the window, zoom and pan the user set.
    m_xrayViews[v]->setImage(images[v], m_sequenceWindowed);
    if (!outline) {
      m_xrayViews[v]->clearLayer(kTrackLayer);
      continue;
    }
    auto contours = m_overlay->contours(m_sequence->views[v].camera, tracked->T_world_from_ct);
    if (!contours) {
      problems << QString::fromStdString(m_sequence->views[v].name + ": " + contours.error());
      continue;
    }
    m_xrayViews[v]->setPolylineLayer(kTrackLayer, XrayViewWidget::polylines(contours.value()),
                                     QColor(ContourOverlay::kFinalColour[0], ContourOverlay::kFinalColour[1],
                                            ContourOverlay::kFinalColour[2]));
  }
  m_sequenceWindowed = !m_xrayViews.empty();
  if (!problems.isEmpty()) showMessage(problems.join(QLatin1Char('\n')), true);
  m_frameLabel->setText(
      tracked ? tr("Frame %1: %2, image match %3, %4 s%5")
                    .arg(index)
                    .arg(CineTracker::statusName(tracked->status))
                    .arg(tracked->similarity, 0, 'f', 3)
                    .arg(tracked->seconds, 0, 'f', 3)
                    .arg(tracked->note.empty() ? QString() : tr(" (%1)").arg(QString::fromStdString(tracked->note)))
              : tr("Frame %1: not tracked yet").arg(index));
}

void TrackStepWidget::updateChart() {
  if (m_tracked.empty()) return;
  auto chart = LineChart::draw(TrackPoseChart::spec(m_tracked, m_rotationCentre_ct_mm, 640, 320));
  if (!chart) {
    showMessage(tr("No pose chart: %1").arg(QString::fromStdString(chart.error())), true);
    return;
  }
  m_chart = toQImage(chart.value());
  m_chartLabel->setPixmap(QPixmap::fromImage(m_chart).scaledToWidth(std::max(320, m_chartLabel->width()),
                                                                     Qt::SmoothTransformation));
}

bool TrackStepWidget::ensureOverlay() {
  const auto& ct = m_document->ct();
  if (!ct) return false;
  if (ct == m_overlayCt && m_overlay) return true;
  auto overlay = ContourOverlay::create(*ct);
  if (!overlay) {
    showMessage(tr("No bone outline: %1").arg(QString::fromStdString(overlay.error())), true);
    return false;
  }
  m_overlay = std::move(overlay).value();
  m_overlayCt = ct;
  return true;
}

void TrackStepWidget::restoreViews() {
  const auto& views = m_document->views();
  for (std::size_t v = 0; v < m_xrayViews.size(); ++v) {
    m_xrayViews[v]->clearLayer(kTrackLayer);
    if (m_sequence && v < views.size()) m_xrayViews[v]->setImage(views[v].xray);
  }
  m_sequenceWindowed = false;
}

void TrackStepWidget::setRunningUi(bool running) {
  m_trackButton->setEnabled(!running);
  m_loadButton->setEnabled(!running);
  m_cancelButton->setEnabled(running);
}

void TrackStepWidget::showMessage(const QString& text, bool error) {
  m_message->setText(text);
  m_message->setStyleSheet(error ? QStringLiteral("color: #c0392b;") : QString());
}

}  // namespace fct
