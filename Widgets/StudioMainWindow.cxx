#include "Widgets/StudioMainWindow.h"

#include <QApplication>
#include <QCloseEvent>
#include <QDateTime>
#include <QFileDialog>
#include <QFileInfo>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QScrollArea>
#include <QSettings>
#include <QSplitter>
#include <QStatusBar>
#include <QToolBox>
#include <QVBoxLayout>

#include <algorithm>

#include "Widgets/DataStepWidget.h"
#include "Widgets/LandmarkStepWidget.h"
#include "Widgets/RegisterStepWidget.h"
#include "Widgets/ReviewStepWidget.h"
#include "Widgets/TrackStepWidget.h"
#include "Widgets/RoiStepWidget.h"
#include "Widgets/Scene3DWidget.h"
#include "Widgets/SessionAutosave.h"
#include "Widgets/SliceViewWidget.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/StudioSession.h"
#include "Widgets/XrayViewWidget.h"

namespace fct {

namespace {

constexpr int kMaxRecentSessions = 8;
const QString kRecentKey = QStringLiteral("recentSessions");

QString qs(const std::filesystem::path& p) { return QString::fromStdString(p.string()); }

/// A step title as a command-line name: lower case, spaces as '-' ("Initial pose" -> "initial-pose").
QString slug(const QString& title) { return title.toLower().replace(QLatin1Char(' '), QLatin1Char('-')); }

}  // namespace

StudioMainWindow::StudioMainWindow(std::filesystem::path autosavePath, QWidget* parent) : QMainWindow(parent) {
  resize(1500, 920);
  m_document = new StudioDocument(this);
  m_autosave = new SessionAutosave(m_document, autosavePath.empty() ? SessionAutosave::defaultPath() : autosavePath,
                                   this);

  // Module panel (left).
  auto* panel = new QWidget(this);
  auto* panelLayout = new QVBoxLayout(panel);
  panelLayout->setContentsMargins(6, 6, 6, 6);
  auto* heading = new QLabel(tr("<b>FluoroCT Studio</b><br><small>CT to fluoroscopy registration</small>"), panel);
  panelLayout->addWidget(heading);
  m_steps = new QToolBox(panel);
  panelLayout->addWidget(m_steps, 1);
  panel->setMinimumWidth(400);  // the ROI spin boxes fit without a scrollbar

  // Views (right): X-rays on top; slices and 3D below.
  auto* viewArea = new QWidget(this);
  auto* viewLayout = new QVBoxLayout(viewArea);
  viewLayout->setContentsMargins(0, 0, 0, 0);
  viewLayout->setSpacing(2);
  m_messageBar = new QLabel(viewArea);
  m_messageBar->setWordWrap(true);
  m_messageBar->setStyleSheet(QStringLiteral("background: #5a1d1d; color: white; padding: 6px;"));
  m_messageBar->setTextInteractionFlags(Qt::TextSelectableByMouse);
  m_messageBar->hide();
  viewLayout->addWidget(m_messageBar);
  auto* rows = new QSplitter(Qt::Vertical, viewArea);
  m_xrayRow = new QSplitter(Qt::Horizontal, rows);
  m_xrayPlaceholder = new QLabel(tr("No X-ray views: open a view file or a case folder in the Data step"), m_xrayRow);
  m_xrayPlaceholder->setAlignment(Qt::AlignCenter);
  m_xrayPlaceholder->setStyleSheet(QStringLiteral("background: #0c0c0e; color: #969696;"));
  m_xrayRow->addWidget(m_xrayPlaceholder);
  auto* lowerRow = new QSplitter(Qt::Horizontal, rows);
  const SliceOrientation orientations[3] = {SliceOrientation::Axial, SliceOrientation::Coronal,
                                            SliceOrientation::Sagittal};
  for (int i = 0; i < 3; ++i) {
    auto* slice = new SliceViewWidget(orientations[i], lowerRow);
    m_sliceViews[static_cast<std::size_t>(i)] = slice;
    lowerRow->addWidget(slice);
    connect(slice, &SliceViewWidget::pointClicked, this, &StudioMainWindow::setCrosshair);
    connect(slice, &SliceViewWidget::crosshairMoved, this, &StudioMainWindow::setCrosshair);
    connect(slice, &SliceViewWidget::ctPointHovered, this, [this, slice](const Eigen::Vector3d& p, float value) {
      m_hover->setText(tr("%1: %2  %3 HU")
                           .arg(SliceViewWidget::orientationName(slice->orientation()), SliceViewWidget::positionText(p))
                           .arg(value, 0, 'f', 0));
    });
  }
  if (Scene3DWidget::openGlAvailable()) {
    m_scene = new Scene3DWidget(m_document, lowerRow);
    lowerRow->addWidget(m_scene);
  } else {
    auto* no3d = new QLabel(tr("3D view: no OpenGL 3.2 on this display"), lowerRow);
    no3d->setAlignment(Qt::AlignCenter);
    no3d->setWordWrap(true);
    no3d->setStyleSheet(QStringLiteral("background: #1a1c24; color: #969696;"));
    lowerRow->addWidget(no3d);
  }
  rows->addWidget(m_xrayRow);
  rows->addWidget(lowerRow);
  rows->setSizes({460, 420});
  viewLayout->addWidget(rows, 1);

  auto* splitter = new QSplitter(Qt::Horizontal, this);
  splitter->addWidget(panel);
  splitter->addWidget(viewArea);
  splitter->setStretchFactor(1, 1);
  splitter->setSizes({420, 1080});
  setCentralWidget(splitter);

  m_hover = new QLabel(this);
  statusBar()->addPermanentWidget(m_hover);
  statusBar()->showMessage(tr("Ready"));

  connect(m_document, &StudioDocument::ctChanged, this, [this] {
    for (SliceViewWidget* slice : m_sliceViews) slice->setVolume(m_document->ct());
  });
  connect(m_document, &StudioDocument::viewsChanged, this, &StudioMainWindow::rebuildXrayViews);
  connect(m_document, &StudioDocument::xrayWindowsChanged, this, [this] {
    const auto& views = m_document->views();
    for (std::size_t v = 0; v < m_xrayViews.size() && v < views.size(); ++v) {
      const auto saved = m_document->xrayWindows().find(views[v].name);
      if (saved != m_document->xrayWindows().end()) m_xrayViews[v]->setWindowLevel(saved->second.window, saved->second.level);
    }
  });
  connect(m_document, &StudioDocument::modifiedChanged, this, &StudioMainWindow::updateTitle);
  connect(m_autosave, &SessionAutosave::failed, this, [this](const QString& message) {
    showStatus(tr("Autosave failed: %1").arg(message));
  });
  connect(m_steps, &QToolBox::currentChanged, this, [this](int index) {
    if (m_activeStep >= 0 && m_activeStep < static_cast<int>(m_stepHooks.size()) &&
        m_stepHooks[static_cast<std::size_t>(m_activeStep)].setActive) {
      m_stepHooks[static_cast<std::size_t>(m_activeStep)].setActive(false);
    }
    m_activeStep = index;
    if (index >= 0 && index < static_cast<int>(m_stepHooks.size()) && m_stepHooks[static_cast<std::size_t>(index)].setActive) {
      m_stepHooks[static_cast<std::size_t>(index)].setActive(true);
    }
  });

  m_dataStep = new DataStepWidget(m_document, this);
  m_dataStep->setInputGuard([this] { return mayReplaceInputs(); });
  connect(m_dataStep, &DataStepWidget::statusMessage, this, &StudioMainWindow::showStatus);
  connect(m_dataStep, &DataStepWidget::loadFinished, this, [this](bool ok, const QString& message) {
    updateTitle();
    if (ok) {
      m_messageBar->hide();
    } else {
      showError(message);
    }
  });
  // The workflow steps, in order: one line each.
  addStep(tr("Data"), m_dataStep);
  addStep(tr("Initial pose"), new LandmarkStepWidget(m_document, this));
  addStep(tr("ROIs"), new RoiStepWidget(m_document, this));
  auto* registration = addStep(tr("Register"), new RegisterStepWidget(m_document, this));
  connect(registration, &RegisterStepWidget::statusMessage, this, &StudioMainWindow::showStatus);
  addStep(tr("Review"), new ReviewStepWidget(m_document, this));
  addStep(tr("Track"), new TrackStepWidget(m_document, this));

  buildMenus();
  updateTitle();
}

StudioMainWindow::~StudioMainWindow() = default;

void StudioMainWindow::addStepWidget(const QString& title, QWidget* step, StepHooks hooks) {
  auto* scroll = new QScrollArea(m_steps);
  scroll->setWidget(step);
  scroll->setWidgetResizable(true);
  scroll->setFrameShape(QFrame::NoFrame);
  m_stepHooks.push_back(std::move(hooks));
  const int index = m_steps->addItem(scroll, QStringLiteral("%1. %2").arg(m_steps->count() + 1).arg(title));
  m_steps->setItemToolTip(index, title);
  if (m_stepHooks.back().attachViews) m_stepHooks.back().attachViews(m_xrayViews, m_sliceViews);
}

int StudioMainWindow::stepCount() const { return m_steps->count(); }

QString StudioMainWindow::stepTitle(int index) const { return m_steps->itemToolTip(index); }

int StudioMainWindow::currentStep() const { return m_steps->currentIndex(); }

void StudioMainWindow::showStep(int index) {
  if (index >= 0 && index < m_steps->count()) m_steps->setCurrentIndex(index);
}

bool StudioMainWindow::showStepNamed(const QString& name) {
  for (int i = 0; i < m_steps->count(); ++i) {
    if (slug(stepTitle(i)) == name.toLower()) {
      showStep(i);
      return true;
    }
  }
  return false;
}

void StudioMainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->addAction(tr("&New session"), QKeySequence::New, this, [this] { newSession(); });
  file->addAction(tr("&Open session…"), QKeySequence::Open, this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Open a session"), {},
                                                      tr("FluoroCT sessions (*.fctsession.json *.json)"));
    if (!path.isEmpty()) openSession(path);
  });
  m_recentMenu = file->addMenu(tr("Open &recent"));
  file->addAction(tr("&Save session"), QKeySequence::Save, this, [this] { saveSession(); });
  file->addAction(tr("Save session &as…"), QKeySequence::SaveAs, this, [this] { saveSessionAs(); });
  file->addSeparator();
  file->addAction(tr("Open &case folder…"), this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(this, tr("Open a case folder"));
    if (!folder.isEmpty()) {
      showStep(0);
      m_dataStep->openCaseFolder(folder);
    }
  });
  file->addSeparator();
  file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);
  rebuildRecentMenu();

  QMenu* view = menuBar()->addMenu(tr("&View"));
  view->addAction(tr("CT window: &bone"), this, [this] {
    for (SliceViewWidget* slice : m_sliceViews) slice->applyWindowPreset(SliceWindowPreset::Bone);
  });
  view->addAction(tr("CT window: &soft tissue"), this, [this] {
    for (SliceViewWidget* slice : m_sliceViews) slice->applyWindowPreset(SliceWindowPreset::SoftTissue);
  });
  for (const XrayWindowPreset preset :
       {XrayWindowPreset::Automatic, XrayWindowPreset::WholeField, XrayWindowPreset::FullRange}) {
    view->addAction(tr("X-ray window: %1").arg(XrayViewWidget::presetName(preset)), this, [this, preset] {
      for (XrayViewWidget* xray : m_xrayViews) xray->applyWindowPreset(preset);
    });
  }
  view->addSeparator();
  view->addAction(tr("&Reset views"), this, [this] {
    for (SliceViewWidget* slice : m_sliceViews) slice->resetView();
    for (XrayViewWidget* xray : m_xrayViews) xray->resetView();
    if (m_scene) {
      m_scene->resetCamera();
      m_scene->update();
    }
  });

  QMenu* help = menuBar()->addMenu(tr("&Help"));
  help->addAction(tr("&Mouse and keys"), this, [this] {
    QMessageBox::information(
        this, tr("Mouse and keys"),
        tr("<b>Slice views</b>: wheel scrolls slices, Ctrl+wheel zooms, middle or right drag pans, Ctrl+left drag "
           "sets window/level, a click moves the crosshair.<br><b>X-ray views</b>: wheel zooms, left, middle or "
           "right drag pans, Ctrl+left drag sets window/level.<br><b>3D view</b>: left drag rotates, middle drag "
           "pans, wheel zooms."));
  });
}

void StudioMainWindow::rebuildXrayViews() {
  const std::vector<XrayViewWidget*> old = m_xrayViews;
  m_xrayViews.clear();
  for (const RegistrationView& view : m_document->views()) {
    auto* widget = new XrayViewWidget(m_xrayRow);
    widget->setTitle(QString::fromStdString(view.name));
    widget->setImage(view.xray);
    if (const auto saved = m_document->xrayWindows().find(view.name); saved != m_document->xrayWindows().end()) {
      widget->setWindowLevel(saved->second.window, saved->second.level);
    }
    connect(widget, &ImageViewWidget::windowLevelChanged, this, [this, name = view.name](double window, double level) {
      m_document->setXrayWindow(name, {window, level});
    });
    const QString name = QString::fromStdString(view.name);
    connect(widget, &ImageViewWidget::pixelHovered, this, [this, name](const Eigen::Vector2d& uv, float value) {
      m_hover->setText(tr("%1: pixel (%2, %3)  value %4").arg(name).arg(uv.x(), 0, 'f', 1).arg(uv.y(), 0, 'f', 1).arg(value));
    });
    m_xrayRow->addWidget(widget);
    m_xrayViews.push_back(widget);
  }
  m_xrayPlaceholder->setVisible(m_xrayViews.empty());
  for (const StepHooks& hooks : m_stepHooks) {
    if (hooks.attachViews) hooks.attachViews(m_xrayViews, m_sliceViews);
  }
  for (XrayViewWidget* widget : old) {
    widget->hide();
    widget->deleteLater();  // not now: the change may come from one of its own signals
  }
}

void StudioMainWindow::setCrosshair(const Eigen::Vector3d& p_ct_mm) {
  for (SliceViewWidget* slice : m_sliceViews) slice->setCrosshair_ct_mm(p_ct_mm);
}

void StudioMainWindow::updateTitle() {
  const auto& path = m_document->sessionPath();
  const QString name = path.empty() ? tr("untitled session") : qs(path.filename());
  setWindowTitle(QStringLiteral("%1[*] — FluoroCT Studio").arg(name));
  setWindowModified(m_document->isModified());
}

void StudioMainWindow::showError(const QString& message) {
  m_lastMessage = message;
  m_messageBar->setText(message);
  m_messageBar->show();
  statusBar()->showMessage(message);
}

void StudioMainWindow::showStatus(const QString& message) {
  m_lastMessage = message;
  statusBar()->showMessage(message);
}

bool StudioMainWindow::newSession() {
  if (!maybeSave()) return false;
  m_document->clear();
  m_messageBar->hide();
  updateTitle();
  showStatus(tr("New session"));
  return true;
}

bool StudioMainWindow::openSession(const QString& path) {
  if (!maybeSave()) return false;
  const Status opened = StudioSession::open(*m_document, path.toStdString());
  if (!opened) {
    showError(tr("Could not open the session: %1").arg(QString::fromStdString(opened.error())));
    return false;
  }
  m_messageBar->hide();
  addRecentSession(path);
  updateTitle();
  showStatus(tr("Opened the session %1").arg(QFileInfo(path).fileName()));
  return true;
}

bool StudioMainWindow::saveSession() {
  if (m_document->sessionPath().empty()) return saveSessionAs();
  return saveSessionTo(qs(m_document->sessionPath()));
}

bool StudioMainWindow::saveSessionAs() {
  QString path = QFileDialog::getSaveFileName(this, tr("Save the session"), m_document->suggestedPath(tr("session.fctsession.json")),
                                              tr("FluoroCT sessions (*.fctsession.json)"));
  if (path.isEmpty()) return false;
  if (!path.endsWith(QStringLiteral(".json"))) path += QString::fromLatin1(StudioSession::kSuffix);
  return saveSessionTo(path);
}

bool StudioMainWindow::saveSessionTo(const QString& path) {
  const Status saved = StudioSession::save(*m_document, path.toStdString());
  if (!saved) {
    showError(tr("Could not save the session: %1").arg(QString::fromStdString(saved.error())));
    return false;
  }
  addRecentSession(path);
  updateTitle();
  showStatus(tr("Saved the session to %1").arg(path));
  return true;
}

bool StudioMainWindow::restoreAutosave() {
  if (!m_autosave->exists()) return false;
  m_autosave->setEnabled(false);
  const Status opened = StudioSession::open(*m_document, m_autosave->path());
  m_autosave->setEnabled(true);
  if (!opened) {
    showError(tr("Could not restore the unsaved session (%1): %2")
                  .arg(qs(m_autosave->path()), QString::fromStdString(opened.error())));
    return false;
  }
  (void)m_autosave->writeNow();  // now with the restored state complete
  updateTitle();
  showStatus(tr("Restored the unsaved session; save it to keep it"));
  return true;
}

void StudioMainWindow::offerAutosave() {
  if (!m_autosave->exists()) return;
  const QFileInfo info(qs(m_autosave->path()));
  const auto owner = StudioSession::autosaveOwner(m_autosave->path());
  const QString of = owner.empty() ? tr("an untitled session") : qs(owner.filename());
  const auto answer = QMessageBox::question(
      this, tr("Restore unsaved changes?"),
      tr("FluoroCT Studio did not close normally. Unsaved changes of %1 from %2 were kept.\n\nRestore them?")
          .arg(of, info.lastModified().toString(QStringLiteral("yyyy-MM-dd hh:mm:ss"))),
      QMessageBox::Yes | QMessageBox::Discard, QMessageBox::Yes);
  if (answer == QMessageBox::Yes) {
    restoreAutosave();
  } else {
    m_autosave->discard();
  }
}

QString StudioMainWindow::contentSummary() const {
  const StudioDocument& d = *m_document;
  QStringList parts;
  if (d.ct()) parts << tr("the CT %1").arg(qs(d.ctPath().filename()));
  if (!d.views().empty()) parts << tr("%n X-ray view(s)", nullptr, static_cast<int>(d.views().size()));
  if (!d.landmarks().ct.empty()) parts << tr("%n landmark(s)", nullptr, static_cast<int>(d.landmarks().ct.size()));
  if (d.initialPose()) parts << tr("an initial pose (%1)").arg(d.initialPoseSource());
  if (!d.results().empty()) {
    const auto accepted = std::count_if(d.results().begin(), d.results().end(), [](const StudioResult& r) {
      return r.verdict == ResultVerdict::Accepted;
    });
    parts << tr("%n registration result(s)", nullptr, static_cast<int>(d.results().size())) +
                 (accepted > 0 ? tr(" (%n accepted)", nullptr, static_cast<int>(accepted)) : QString());
  }
  return parts.isEmpty() ? tr("nothing yet") : parts.join(QStringLiteral(", "));
}

bool StudioMainWindow::maybeSave() { return askToSave({}); }

bool StudioMainWindow::askToSave(const QString& lead) {
  if (!m_document->isModified()) return true;
  const QString name = m_document->sessionPath().empty() ? tr("The untitled session")
                                                         : tr("The session %1").arg(qs(m_document->sessionPath().filename()));
  const auto answer = QMessageBox::warning(
      this, tr("Unsaved changes"),
      lead + tr("%1 has unsaved changes. It holds %2.\n\nSave it first?").arg(name, contentSummary()),
      QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, QMessageBox::Save);
  if (answer == QMessageBox::Save) return saveSession();
  return answer == QMessageBox::Discard;
}

bool StudioMainWindow::mayReplaceInputs() {
  if (!m_document->hasDerivedState()) return true;
  return askToSave(tr("New images replace the current ones: their landmarks, initial pose and registration results "
                      "are dropped.\n\n"));
}

void StudioMainWindow::closeEvent(QCloseEvent* event) {
  if (!maybeSave()) {
    event->ignore();
    return;
  }
  m_autosave->discard();
  event->accept();
}

QString StudioMainWindow::hoverText() const { return m_hover->text(); }

QStringList StudioMainWindow::recentSessions() const { return QSettings().value(kRecentKey).toStringList(); }

void StudioMainWindow::addRecentSession(const QString& path) {
  const QString absolute = QFileInfo(path).absoluteFilePath();
  QStringList recent = recentSessions();
  recent.removeAll(absolute);
  recent.prepend(absolute);
  while (recent.size() > kMaxRecentSessions) recent.removeLast();
  QSettings().setValue(kRecentKey, recent);
  rebuildRecentMenu();
}

void StudioMainWindow::rebuildRecentMenu() {
  m_recentMenu->clear();
  const QStringList recent = recentSessions();
  for (const QString& path : recent) {
    m_recentMenu->addAction(QFileInfo(path).fileName() + QStringLiteral("  (") + QFileInfo(path).absolutePath() +
                                QStringLiteral(")"),
                            this, [this, path] { openSession(path); });
  }
  m_recentMenu->setEnabled(!recent.isEmpty());
}

}  // namespace fct
