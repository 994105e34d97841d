#include "Widgets/RegisterStepWidget.h"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QThread>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>

#include <algorithm>
#include <exception>

#include <fmt/format.h>

#include "Widgets/RegistrationWorker.h"
#include "Widgets/RunTimeEstimator.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/WorkerThread.h"

namespace fct {

RegisterStepWidget::RegisterStepWidget(StudioDocument* document, QWidget* parent)
    : QWidget(parent), m_document(document) {
  qRegisterMetaType<fct::RegistrationProgress>();
  qRegisterMetaType<fct::RegistrationResult>();
  auto* layout = new QVBoxLayout(this);

  auto* optionsBox = new QGroupBox(tr("Options"), this);
  auto* form = new QFormLayout(optionsBox);
  m_presetCombo = new QComboBox(optionsBox);
  for (const std::string& name : RegistrationSchedule::builtinNames()) m_presetCombo->addItem(QString::fromStdString(name));
  m_presetCombo->setToolTip(tr("clinical (default): the paper's stages at a small fraction of its time, ending at "
                               "1:4; accurate: clinical with every valid pixel at 1:4; fast: a small genetic search, "
                               "then VLNC on ROIs at 1:16, 1:4, 1:1; paper: the paper's three stages with n = 4 genetic "
                               "guesses"));
  form->addRow(tr("Preset"), m_presetCombo);
  m_estimateLabel = new QLabel(optionsBox);
  m_estimateLabel->setWordWrap(true);
  m_estimateLabel->setToolTip(tr("Each stage's evaluation cap times the DRR pixels it renders, at the DRR speed "
                                 "measured on this case at the initial pose; a search usually stops before its cap, "
                                 "and comparing the images costs extra. Without ablation switches."));
  form->addRow(tr("Time (estimate)"), m_estimateLabel);
  m_seedSpin = new QSpinBox(optionsBox);
  m_seedSpin->setRange(0, 1000000);
  form->addRow(tr("Random seed"), m_seedSpin);
  m_methodCombo = new QComboBox(optionsBox);
  m_methodCombo->addItems({QStringLiteral("siddon"), QStringLiteral("raycast"), QStringLiteral("transgraph")});
  m_methodCombo->setToolTip(tr("transgraph: precomputed ray tables, one per view, built around the initial pose at the "
                               "first run (takes a while once; later runs of the same case reuse them)"));
  form->addRow(tr("DRR method"), m_methodCombo);
  m_boneContrastSpin = new QDoubleSpinBox(optionsBox);
  m_boneContrastSpin->setRange(0.1, DrrValueOptions::kMaxBoneContrast);
  m_boneContrastSpin->setDecimals(2);
  m_boneContrastSpin->setSingleStep(0.1);
  m_boneContrastSpin->setKeyboardTracking(false);
  m_boneContrastSpin->setToolTip(tr("How much more the X-ray's beam sees of bone than the CT's did: the DRRs' "
                                    "attenuation above 100 HU is scaled by it. %1 suits an 80 kVp fluoroscope and a "
                                    "120 kVp CT, about 1.3 a 100 kVp one; 1: the CT's own contrast")
                                     .arg(RegistrationCaseOptions::kDefaultBoneContrast));
  form->addRow(tr("Bone contrast"), m_boneContrastSpin);
  layout->addWidget(optionsBox);

  auto* ablationBox = new QGroupBox(tr("Switch off (ablation)"), this);
  auto* ablationLayout = new QVBoxLayout(ablationBox);
  m_noRoisCheck = new QCheckBox(tr("Dynamic ROIs (compare every pixel)"), ablationBox);
  m_noPyramidCheck = new QCheckBox(tr("Pyramid (every stage at full resolution)"), ablationBox);
  m_nccOnlyCheck = new QCheckBox(tr("VLNC (NCC in every stage)"), ablationBox);
  m_localOnlyCheck = new QCheckBox(tr("Global search (local simplex only)"), ablationBox);
  m_cmaesCheck = new QCheckBox(tr("Genetic search (CMA-ES instead)"), ablationBox);
  m_noTransgraphCheck = new QCheckBox(tr("Transgraph (exact DRRs instead of the tables)"), ablationBox);
  m_noCtPyramidCheck = new QCheckBox(tr("CT pyramid (coarse levels ray-cast the full CT)"), ablationBox);
  m_noCtPyramidCheck->setToolTip(tr("By default the DRRs of a coarse pyramid level integrate the CT averaged to the "
                                    "level's pixel size at the bone (faster on thin-slice CTs)"));
  for (QCheckBox* check : {m_noRoisCheck, m_noPyramidCheck, m_nccOnlyCheck, m_localOnlyCheck, m_cmaesCheck,
                           m_noTransgraphCheck, m_noCtPyramidCheck}) {
    ablationLayout->addWidget(check);
  }
  layout->addWidget(ablationBox);

  auto* buttons = new QHBoxLayout();
  m_runButton = new QPushButton(tr("Run"), this);
  m_cancelButton = new QPushButton(tr("Cancel"), this);
  m_cancelButton->setEnabled(false);
  buttons->addWidget(m_runButton);
  buttons->addWidget(m_cancelButton);
  layout->addLayout(buttons);

  m_progressBar = new QProgressBar(this);
  m_progressBar->setRange(0, 1000);
  m_progressBar->setValue(0);
  m_progressBar->setTextVisible(false);
  layout->addWidget(m_progressBar);
  m_progressLabel = new QLabel(tr("Not started"), this);
  m_progressLabel->setWordWrap(true);  // a long stage line must not widen the panel and push Cancel out of sight
  layout->addWidget(m_progressLabel);
  m_message = new QLabel(this);
  m_message->setWordWrap(true);
  m_message->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(m_message);
  m_log = new QPlainTextEdit(this);
  m_log->setReadOnly(true);
  m_log->setMaximumBlockCount(2000);
  layout->addWidget(m_log, 1);

  connect(m_runButton, &QPushButton::clicked, this, &RegisterStepWidget::run);
  connect(m_cancelButton, &QPushButton::clicked, this, &RegisterStepWidget::cancel);
  connect(m_presetCombo, &QComboBox::currentIndexChanged, this, &RegisterStepWidget::pushOptions);
  connect(m_seedSpin, &QSpinBox::valueChanged, this, &RegisterStepWidget::pushOptions);
  connect(m_methodCombo, &QComboBox::currentIndexChanged, this, &RegisterStepWidget::pushOptions);
  connect(m_boneContrastSpin, &QDoubleSpinBox::valueChanged, this, &RegisterStepWidget::pushOptions);
  connect(m_document, &StudioDocument::registrationOptionsChanged, this, &RegisterStepWidget::syncControls);
  connect(m_document, &StudioDocument::resultChanged, this, &RegisterStepWidget::showDocumentResult);
  for (auto signal : {&StudioDocument::ctChanged, &StudioDocument::viewsChanged, &StudioDocument::initialPoseChanged}) {
    connect(m_document, signal, this, &RegisterStepWidget::updateRunButton);
  }
  for (auto signal : {&StudioDocument::ctChanged, &StudioDocument::viewsChanged}) {
    connect(m_document, signal, this, [this] {
      if (isRunning()) m_inputsChangedDuringRun = true;
    });
  }
  connect(m_document, &StudioDocument::casePreparationFinished, this, &RegisterStepWidget::onCasePrepared);
  m_speedWatcher = new QFutureWatcher<Speed>(this);
  connect(m_speedWatcher, &QFutureWatcherBase::finished, this, [this] {
    m_speed = m_speedWatcher->result();
    updateEstimate();
  });
  connect(m_document, &StudioDocument::casePreparationFinished, this, &RegisterStepWidget::updateEstimate);
  for (auto signal : {&StudioDocument::initialPoseChanged, &StudioDocument::roiParametersChanged, &StudioDocument::resultChanged,
                      &StudioDocument::registrationOptionsChanged}) {
    connect(m_document, signal, this, &RegisterStepWidget::updateEstimate);
  }
  connect(m_document, &StudioDocument::casePreparationProgressed, this, [this](const QString& step, double fraction) {
    if (!m_pending) return;
    m_progressBar->setValue(0);
    m_progressLabel->setText(tr("Preparing the case: %1 (%2 %)…").arg(step).arg(100.0 * fraction, 0, 'f', 0));
  });
  syncControls();
  updateRunButton();
}

RegisterStepWidget::~RegisterStepWidget() {
  m_speedWatcher->waitForFinished();
  if (m_pending) m_document->cancelCasePreparation();
  if (m_worker) m_worker->cancel();
  endThread();
}

void RegisterStepWidget::attachViews(std::vector<XrayViewWidget*>, std::array<SliceViewWidget*, 3>) {}

void RegisterStepWidget::setActive(bool active) {
  m_active = active;
  updateEstimate();
  if (!active || isRunning()) return;
  const RoiParameters& roi = m_document->roiParameters();
  if (!m_document->initialPose()) {
    showMessage(tr("No initial pose yet: set one in the Initial pose step (landmarks or the supine AP preset)."), true);
    return;
  }
  showMessage(tr("Ready: initial pose from %1; ROIs of %2 px keeping %3 % of the pixels.")
                  .arg(m_document->initialPoseSource().isEmpty() ? tr("the session") : m_document->initialPoseSource())
                  .arg(roi.windowSize)
                  .arg(100.0 * roi.targetFraction, 0, 'f', 1),
              false);
}

RegistrationAblation RegisterStepWidget::ablation() const {
  RegistrationAblation ablation;
  ablation.noDynamicRois = m_noRoisCheck->isChecked();
  ablation.noPyramid = m_noPyramidCheck->isChecked();
  ablation.nccOnly = m_nccOnlyCheck->isChecked();
  ablation.localOnly = m_localOnlyCheck->isChecked();
  ablation.cmaesForGenetic = m_cmaesCheck->isChecked();
  ablation.noTransgraph = m_noTransgraphCheck->isChecked();
  ablation.noCtPyramid = m_noCtPyramidCheck->isChecked();
  return ablation;
}

void RegisterStepWidget::setAblation(const RegistrationAblation& ablation) {
  m_noRoisCheck->setChecked(ablation.noDynamicRois);
  m_noPyramidCheck->setChecked(ablation.noPyramid);
  m_nccOnlyCheck->setChecked(ablation.nccOnly);
  m_localOnlyCheck->setChecked(ablation.localOnly);
  m_cmaesCheck->setChecked(ablation.cmaesForGenetic);
  m_noTransgraphCheck->setChecked(ablation.noTransgraph);
  m_noCtPyramidCheck->setChecked(ablation.noCtPyramid);
}

QString RegisterStepWidget::message() const { return m_message->text(); }

QString RegisterStepWidget::logText() const { return m_log->toPlainText(); }

QString RegisterStepWidget::progressText() const { return m_progressLabel->text(); }

QString RegisterStepWidget::missingInputs() const {
  QStringList missing;
  if (!m_document->ct()) missing << tr("a CT (Data step)");
  if (m_document->views().empty()) missing << tr("X-ray views (Data step)");
  if (!m_document->initialPose()) missing << tr("an initial pose (Initial pose step: landmarks or the supine AP preset)");
  return missing.join(QStringLiteral(", "));
}

void RegisterStepWidget::updateRunButton() {
  const QString missing = missingInputs();
  m_runButton->setEnabled(!isRunning() && missing.isEmpty());
  m_runButton->setToolTip(missing.isEmpty() ? tr("Register the CT to the X-rays from the initial pose")
                                            : tr("Run needs %1").arg(missing));
}

std::optional<double> RegisterStepWidget::estimatedSeconds(const QString& preset) const {
  const std::shared_ptr<RegistrationCase>& prepared = m_document->readyCase();
  if (!prepared || prepared.get() != m_speedCase || m_speed.secondsPerPixel.empty()) return std::nullopt;
  auto schedule = RegistrationSchedule::resolve(preset.toStdString());
  if (!schedule) return std::nullopt;
  const RoiParameters& roi = m_document->roiParameters();
  auto tuned = schedule.value().withRoiPixels(roi.windowSize, roi.targetFraction);  // as Run will use it
  if (!tuned) return std::nullopt;
  auto seconds = RunTimeEstimator::budgetSeconds(tuned.value(), *prepared, m_speed.secondsPerPixel);
  return seconds ? std::optional<double>(seconds.value()) : std::nullopt;
}

QString RegisterStepWidget::estimateText() const { return m_estimateLabel->text(); }

void RegisterStepWidget::updateEstimate() {
  const auto duration = [](double seconds) {
    return seconds < 90.0 ? tr("%1 s").arg(std::max(1.0, seconds), 0, 'f', 0) : tr("%1 min").arg(seconds / 60.0, 0, 'f', 1);
  };
  const std::shared_ptr<RegistrationCase>& prepared = m_document->readyCase();
  if (!m_document->ct() || m_document->views().empty() || !m_document->initialPose()) {
    m_estimateLabel->setText(tr("after the data and an initial pose are set"));
    return;
  }
  if (!prepared) {
    m_estimateLabel->setText(tr("once the case is prepared"));
    if (m_active && !isRunning()) m_document->prepareCaseInBackground();
    return;
  }
  if (prepared.get() != m_speedCase) {
    if (m_speedWatcher->isRunning()) return;  // finished() comes back here
    if (!m_active || isRunning()) return;     // the case is busy with a run; measured when the step is shown again
    m_speedCase = prepared.get();
    m_speed = Speed{};
    m_estimateLabel->setText(tr("measuring the DRR speed on this case…"));
    const Eigen::Isometry3d pose = *m_document->initialPose();
    m_speedWatcher->setFuture(QtConcurrent::run([prepared, pose]() -> Speed {
      try {
        auto measured = RunTimeEstimator::measureSecondsPerPixel(*prepared, pose);
        if (!measured) return Speed{{}, QString::fromStdString(measured.error())};
        return Speed{std::move(measured).value(), QString()};
      } catch (const std::exception& error) {
        return Speed{{}, QString::fromUtf8(error.what())};
      }
    }));
    return;
  }
  if (m_speedWatcher->isRunning()) return;
  if (m_speed.secondsPerPixel.empty()) {
    m_estimateLabel->setText(tr("none: %1").arg(m_speed.error));
    return;
  }
  QStringList parts;
  for (int i = 0; i < m_presetCombo->count(); ++i) {
    const QString preset = m_presetCombo->itemText(i);
    if (const auto seconds = estimatedSeconds(preset)) parts << tr("%1 about %2").arg(preset, duration(*seconds));
  }
  QString text = parts.join(QStringLiteral(" · "));
  const std::string current = m_document->registrationOptions().preset;
  const auto& results = m_document->results();
  for (auto it = results.rbegin(); it != results.rend(); ++it) {
    if (it->result.schedule.name == current && !it->result.cancelled) {
      text += tr("; the last %1 run here took %2").arg(QString::fromStdString(current), duration(it->result.totalSeconds));
      break;
    }
  }
  m_estimateLabel->setText(text);
}

QString RegisterStepWidget::plainStageName(const std::string& stage) {
  const QString name = QString::fromStdString(stage);
  const qsizetype colon = name.lastIndexOf(QLatin1Char('-'));
  const QString level = colon >= 0 ? name.mid(colon + 1) : QString();
  QString plain;
  if (name.contains(QStringLiteral("whole"))) {
    plain = tr("Coarse alignment (whole images)");
  } else if (level == QStringLiteral("1:1")) {
    plain = tr("Final (full resolution)");
  } else {
    plain = level.isEmpty() ? tr("Refinement (bone edges)") : tr("Refinement (bone edges, %1)").arg(level);
  }
  return QStringLiteral("%1 [%2]").arg(plain, name);
}

void RegisterStepWidget::logStages(const RegistrationResult& result) {
  for (const StageReport& stage : result.stages) {
    const std::string startNote = stageStartNote(stage);
    appendLog(QString::fromStdString(fmt::format(
                  "  {}: {} at level {}, {} search, {} evaluations, {} DRRs, similarity {:.4f} -> {:.4f}, {:.1f} s{}{}",
                  plainStageName(stage.name).toStdString(), RegistrationSchedule::metricName(stage.metric), stage.level,
                  RegistrationSchedule::searchName(stage.search), stage.evaluations, stage.drrs, stage.startSimilarity,
                  stage.similarity, stage.seconds,
                  startNote.empty() ? "" : ", " + startNote,
                  stage.cancelled ? " (cancelled)" : "")));
  }
}

void RegisterStepWidget::showDocumentResult() {
  const RegistrationResult* result = m_document->result();
  if (isRunning() || (m_ranHere && result)) return;
  m_ranHere = false;
  m_log->clear();
  if (!result) {
    m_progressBar->setValue(0);
    m_progressLabel->setText(tr("Not started"));
    return;
  }
  const QString summary = tr("Result %1 of %2 of this session: preset %3, %4 DRRs in %5 s%6.")
                              .arg(m_document->currentResultIndex() + 1)
                              .arg(m_document->results().size())
                              .arg(QString::fromStdString(result->schedule.name))
                              .arg(result->totalDrrs)
                              .arg(result->totalSeconds, 0, 'f', 1)
                              .arg(result->cancelled ? tr(", cancelled") : QString());
  m_progressBar->setValue(result->cancelled ? 0 : m_progressBar->maximum());
  m_progressLabel->setText(result->cancelled ? tr("Cancelled") : tr("Finished"));
  appendLog(summary);
  logStages(*result);
  showMessage(summary + tr(" Judge it in the Review step, or run again."), false);
}

void RegisterStepWidget::showMessage(const QString& text, bool error) {
  m_message->setStyleSheet(error ? QStringLiteral("color: #c0392b;") : QString());
  m_message->setText(text);
  emit statusMessage(text);
}

void RegisterStepWidget::appendLog(const QString& line) { m_log->appendPlainText(line); }

void RegisterStepWidget::syncControls() {
  const StudioRegistrationOptions& options = m_document->registrationOptions();
  const QSignalBlocker b1(m_presetCombo), b2(m_seedSpin), b3(m_methodCombo), b4(m_boneContrastSpin);
  const QString preset = QString::fromStdString(options.preset);
  if (m_presetCombo->findText(preset) < 0) m_presetCombo->addItem(preset);
  m_presetCombo->setCurrentText(preset);
  m_seedSpin->setValue(static_cast<int>(options.seed));
  const QString method = QString::fromStdString(options.drrMethod);
  if (m_methodCombo->findText(method) < 0) m_methodCombo->addItem(method);
  m_methodCombo->setCurrentText(method);
  m_boneContrastSpin->setValue(options.boneContrast);
}

void RegisterStepWidget::pushOptions() {
  StudioRegistrationOptions options = m_document->registrationOptions();
  options.preset = m_presetCombo->currentText().toStdString();
  options.seed = static_cast<std::uint32_t>(m_seedSpin->value());
  options.drrMethod = m_methodCombo->currentText().toStdString();
  options.boneContrast = m_boneContrastSpin->value();
  m_document->setRegistrationOptions(options);
}

bool RegisterStepWidget::run() {
  if (isRunning()) {
    showMessage(tr("A registration is already running; cancel it first."), true);
    return false;
  }
  const auto& initial = m_document->initialPose();
  if (const QString missing = missingInputs(); !missing.isEmpty()) {
    showMessage(tr("Not ready to run: it needs %1.").arg(missing), true);
    return false;
  }
  const StudioRegistrationOptions& studioOptions = m_document->registrationOptions();
  auto schedule = RegistrationSchedule::resolve(studioOptions.preset);
  if (!schedule) {
    showMessage(tr("Preset: %1").arg(QString::fromStdString(schedule.error())), true);
    return false;
  }
  const RoiParameters& roi = m_document->roiParameters();
  auto tuned = schedule.value().withRoiPixels(roi.windowSize, roi.targetFraction);
  if (!tuned) {
    showMessage(tr("ROI settings: %1; fix them in the ROIs step.").arg(QString::fromStdString(tuned.error())), true);
    return false;
  }
  RegistrationOptions options;
  options.schedule = std::move(tuned).value();
  options.ablation = ablation();
  options.seed = studioOptions.seed;

  const auto ablations = options.ablation.activeNames();
  appendLog(QString::fromStdString(fmt::format(
      "Run: preset {}, seed {}, DRR {} (bone contrast {:g}), ROIs {} px keeping {:.1f} %, switched off: {}; initial "
      "pose: {}",
      options.schedule.name, options.seed, studioOptions.drrMethod, studioOptions.boneContrast, roi.windowSize,
      100.0 * roi.targetFraction,
      ablations.empty() ? std::string("none") : fmt::format("{}", fmt::join(ablations, ", ")),
      m_document->initialPoseSource().toStdString())));

  m_lastProgress = RegistrationProgress{};
  m_inputsChangedDuringRun = false;
  m_ranHere = true;
  m_pending = Pending{*initial, std::move(options)};
  setRunningUi(true);
  emit runningChanged(true);
  if (m_document->readyCase()) {
    startRegistration();
  } else {
    // The case is prepared on a worker thread first (seconds for a large CT); casePreparationFinished starts the run.
    m_progressBar->setValue(0);
    m_progressLabel->setText(tr("Preparing the case…"));
    showMessage(tr("Preparing the case (the CT for DRRs and the X-rays), then registering…"), false);
    m_document->prepareCaseInBackground();
  }
  return true;
}

void RegisterStepWidget::onCasePrepared(bool prepared, const QString& why) {
  if (!m_pending || m_thread) return;
  if (!prepared && (m_document->isPreparingCase() || m_document->readyCase())) return;  // a newer one is under way
  if (prepared) {
    startRegistration();
    return;
  }
  m_pending.reset();
  const QString text = m_inputsChangedDuringRun
                           ? tr("The CT or the views changed during the run, so it stopped before registering; run "
                                "again.")
                           : tr("Cannot register: %1").arg(why);
  appendLog(text);
  showMessage(text, !m_cancelRequested);
  m_progressLabel->setText(tr("Not started"));
  m_cancelRequested = false;
  setRunningUi(false);
  emit runningChanged(false);
}

void RegisterStepWidget::startRegistration() {
  m_speedWatcher->waitForFinished();  // the DRR speed calibration uses the case too (a fraction of a second)
  m_runTimer.start();
  m_worker = new RegistrationWorker(m_document->readyCase(), m_pending->T_initial, std::move(m_pending->options));
  m_pending.reset();
  m_thread = new QThread(this);
  m_worker->moveToThread(m_thread);
  connect(m_thread, &QThread::started, m_worker, &RegistrationWorker::run);
  connect(m_worker, &RegistrationWorker::progressed, this, &RegisterStepWidget::onProgress);
  connect(m_worker, &RegistrationWorker::finished, this, &RegisterStepWidget::onFinished);
  connect(m_worker, &RegistrationWorker::failed, this, &RegisterStepWidget::onFailed);
  if (m_cancelRequested) m_worker->cancel();
  showMessage(tr("Registering…"), false);
  m_thread->start();
}

void RegisterStepWidget::cancel() {
  if (m_pending) {
    m_cancelRequested = true;
    m_document->cancelCasePreparation();
    m_cancelButton->setEnabled(false);
    showMessage(tr("Cancelling: the case preparation stops at its next step; nothing is registered."), false);
    return;
  }
  if (!m_worker) return;
  m_worker->cancel();
  m_cancelButton->setEnabled(false);
  showMessage(tr("Cancelling: the run stops at the next DRR and keeps the best pose so far."), false);
}

void RegisterStepWidget::onProgress(const RegistrationProgress& progress) {
  if (progress.stageIndex != m_lastProgress.stageIndex || m_lastProgress.stage.empty()) {
    appendLog(tr("Stage %1/%2: %3")
                  .arg(progress.stageIndex + 1)
                  .arg(progress.stageCount)
                  .arg(plainStageName(progress.stage)));
  }
  m_lastProgress = progress;
  m_progressBar->setValue(static_cast<int>(1000.0 * progress.fraction));
  // Time left from the time so far and the run's fraction done (shown once a twentieth is done).
  const double elapsed_s = 1e-3 * static_cast<double>(m_runTimer.elapsed());
  const QString left = progress.fraction >= 0.05 && progress.fraction < 1.0
                           ? tr(" — about %1 s left").arg(elapsed_s * (1.0 - progress.fraction) / progress.fraction, 0,
                                                           'f', 0)
                           : QString();
  m_progressLabel->setText(tr("Stage %1 of %2: %3 — %4 DRRs so far — image match %5 (higher is better)%6")
                               .arg(progress.stageIndex + 1)
                               .arg(progress.stageCount)
                               .arg(plainStageName(progress.stage))
                               .arg(progress.drrs)
                               .arg(progress.bestSimilarity, 0, 'f', 4)
                               .arg(left));
}

void RegisterStepWidget::onFinished(const RegistrationResult& result) {
  endThread();
  logStages(result);
  QString summary = tr("%1 DRRs in %2 s").arg(result.totalDrrs).arg(result.totalSeconds, 0, 'f', 1);
  m_progressLabel->setText(result.cancelled ? tr("Cancelled after %1").arg(summary) : tr("Finished: %1").arg(summary));
  if (result.cancelled) {
    summary = tr("Cancelled: the best pose so far is kept, marked cancelled (%1).").arg(summary);
  } else {
    m_progressBar->setValue(m_progressBar->maximum());
    summary = tr("Registered: %1. Judge the result in the Review step.").arg(summary);
  }
  if (m_inputsChangedDuringRun) {
    summary = tr("The CT or the views changed during the run, so its result (%1) was not kept; run again.")
                  .arg(summary);
    appendLog(summary);
    showMessage(summary, true);
  } else {
    if (!m_document->addResult(result)) {
      summary += tr(" The accepted result stays current; this run is kept as result %1 of the history: compare it in "
                    "the Review step.")
                     .arg(m_document->results().size());
    }
    appendLog(summary);
    showMessage(summary, false);
  }
  setRunningUi(false);
  emit runningChanged(false);
}

void RegisterStepWidget::onFailed(const QString& message) {
  endThread();
  appendLog(tr("Failed: %1").arg(message));
  showMessage(tr("Registration failed: %1").arg(message), true);
  setRunningUi(false);
  emit runningChanged(false);
}

void RegisterStepWidget::endThread() { endWorkerThread(m_thread, m_worker); }

void RegisterStepWidget::setRunningUi(bool running) {
  m_cancelButton->setEnabled(running);
  if (!running) m_cancelRequested = false;
  for (QWidget* control : std::initializer_list<QWidget*>{m_presetCombo, m_seedSpin, m_methodCombo, m_boneContrastSpin,
                                                          m_noRoisCheck, m_noPyramidCheck, m_nccOnlyCheck,
                                                          m_localOnlyCheck, m_cmaesCheck, m_noTransgraphCheck,
                                                          m_noCtPyramidCheck}) {
    control->setEnabled(!running);
  }
  updateRunButton();
}

}  // namespace fct
