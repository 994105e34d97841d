#include "Widgets/LandmarkStepWidget.h"

#include <QAction>
#include <QEvent>
#include <QFileDialog>
#include <QMouseEvent>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QTableWidget>
#include <QUndoStack>
#include <QVBoxLayout>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "Image/BoneSurface.h"
#include "InitialPose/SetupPose.h"
#include "IO/Project/LandmarkFile.h"
#include "Widgets/LandmarkEditCommand.h"
#include "Widgets/SliceViewWidget.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/XrayViewWidget.h"

namespace fct {

namespace {

enum Column { kName, kCt, kViews, kResidualPx, kResidualMm, kColumnCount };

const QColor kClickColour(255, 220, 0);
const QColor kSelectedColour(0, 220, 255);
const QColor kProjectedColour(255, 60, 200);

std::map<std::string, Camera> camerasOf(const StudioDocument& document) {
  std::map<std::string, Camera> cameras;
  for (const RegistrationView& view : document.views()) cameras.emplace(view.name, view.camera);
  return cameras;
}

bool nameInUse(const Landmarks& landmarks, const std::string& name) {
  const auto sameName = [&name](const auto& landmark) { return landmark.name == name; };
  if (std::any_of(landmarks.ct.begin(), landmarks.ct.end(), sameName)) return true;
  return std::any_of(landmarks.imageByView.begin(), landmarks.imageByView.end(), [&](const auto& entry) {
    return std::any_of(entry.second.begin(), entry.second.end(), sameName);
  });
}

QTableWidgetItem* readOnlyItem(const QString& text) {
  auto* item = new QTableWidgetItem(text);
  item->setFlags(item->flags() & ~Qt::ItemIsEditable);
  return item;
}

}  // namespace

LandmarkStepWidget::LandmarkStepWidget(StudioDocument* document, QWidget* parent)
    : QWidget(parent), m_document(document) {
  auto* layout = new QVBoxLayout(this);
  auto* help = new QLabel(tr("Click a point in a CT slice view to add a landmark, then click its partner in one or more "
                             "X-ray views (drag either to move it; Ctrl+Z undoes). ") + ruleText(),
                          this);
  help->setWordWrap(true);
  layout->addWidget(help);

  m_table = new QTableWidget(0, kColumnCount, this);
  m_table->setHorizontalHeaderLabels({tr("Name"), tr("CT (LPS mm)"), tr("X-ray views"), tr("Reprojection"),
                                      tr("3-D")});
  m_table->horizontalHeaderItem(kResidualPx)->setToolTip(tr("Largest reprojection error over the landmark's views, "
                                                            "pixels"));
  m_table->horizontalHeaderItem(kResidualMm)->setToolTip(tr("Distance to the landmark triangulated from two or more "
                                                            "views, mm"));
  m_table->setSelectionBehavior(QAbstractItemView::SelectRows);
  m_table->setSelectionMode(QAbstractItemView::SingleSelection);
  m_table->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  m_table->horizontalHeader()->setStretchLastSection(true);
  m_table->verticalHeader()->setVisible(false);
  m_table->setTextElideMode(Qt::ElideRight);
  m_table->horizontalHeader()->setMaximumSectionSize(kMaxColumnWidth_px);  // a long name is elided (full in its tooltip)
  m_table->viewport()->installEventFilter(this);
  layout->addWidget(m_table, 1);
  m_missing = new QLabel(this);
  m_missing->setWordWrap(true);
  layout->addWidget(m_missing);

  auto* editRow = new QHBoxLayout();
  m_deleteButton = new QPushButton(tr("Delete landmark"), this);
  auto* loadButton = new QPushButton(tr("Load…"), this);
  auto* saveButton = new QPushButton(tr("Save…"), this);
  editRow->addWidget(m_deleteButton);
  editRow->addStretch(1);
  editRow->addWidget(loadButton);
  editRow->addWidget(saveButton);
  layout->addLayout(editRow);

  auto* poseRow = new QHBoxLayout();
  m_computeButton = new QPushButton(tr("Compute pose"), this);
  auto* presetButton = new QPushButton(tr("Supine AP preset"), this);
  presetButton->setToolTip(tr("Patient as in the CT, bone centre at the C-arm isocentre (no landmarks needed)"));
  poseRow->addWidget(m_computeButton);
  poseRow->addWidget(presetButton);
  layout->addLayout(poseRow);

  m_message = new QLabel(this);
  m_message->setWordWrap(true);
  m_message->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(m_message);

  connect(m_table, &QTableWidget::currentCellChanged, this, [this](int row, int, int, int) {
    if (m_refreshing) return;
    m_selected = row >= 0 && m_table->item(row, kName) ? m_table->item(row, kName)->text() : QString();
    jumpTo(m_selected);
    updateLayers();
  });
  m_undo = new QUndoStack(this);
  m_undoAction = new QAction(tr("Undo landmark edit"), this);
  m_undoAction->setShortcut(QKeySequence::Undo);
  m_redoAction = new QAction(tr("Redo landmark edit"), this);
  m_redoAction->setShortcuts({QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_Z), QKeySequence::Redo});
  for (QAction* action : {m_undoAction, m_redoAction}) {
    action->setShortcutContext(Qt::WindowShortcut);
    action->setEnabled(false);
    addAction(action);
  }
  connect(m_undoAction, &QAction::triggered, this, &LandmarkStepWidget::undo);
  connect(m_redoAction, &QAction::triggered, this, &LandmarkStepWidget::redo);
  connect(m_table, &QTableWidget::cellChanged, this, &LandmarkStepWidget::onItemChanged);
  connect(m_deleteButton, &QPushButton::clicked, this, [this] { deleteLandmark(QString(m_selected)); });
  connect(loadButton, &QPushButton::clicked, this, &LandmarkStepWidget::loadWithDialog);
  connect(saveButton, &QPushButton::clicked, this, &LandmarkStepWidget::saveWithDialog);
  connect(m_computeButton, &QPushButton::clicked, this, &LandmarkStepWidget::computePose);
  connect(presetButton, &QPushButton::clicked, this, &LandmarkStepWidget::applySetupPose);
  // A pose estimate belongs to the landmarks and cameras it came from; landmarks replaced from elsewhere (a session,
  // new images) start a new undo history.
  for (auto signal : {&StudioDocument::landmarksChanged, &StudioDocument::viewsChanged}) {
    connect(m_document, signal, this, [this] {
      m_estimate.reset();
      if (!m_editing) m_undo->clear();
      refresh();
    });
  }
  connect(m_document, &StudioDocument::initialPoseChanged, this, &LandmarkStepWidget::restoreEstimate);
  refresh();
}

void LandmarkStepWidget::attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3> sliceViews) {
  const bool wasActive = m_active;
  setActive(false);
  m_xrayViews = std::move(xrayViews);
  m_sliceViews = sliceViews;
  setActive(wasActive);
}

void LandmarkStepWidget::setActive(bool active) {
  for (const QMetaObject::Connection& connection : m_viewConnections) disconnect(connection);
  m_viewConnections.clear();
  m_active = active;
  m_undoAction->setEnabled(active && m_undo->canUndo());
  m_redoAction->setEnabled(active && m_undo->canRedo());
  if (active) {
    for (SliceViewWidget* view : m_sliceViews) {
      if (!view) continue;
      m_viewConnections.push_back(
          connect(view, &SliceViewWidget::pointClicked, this, &LandmarkStepWidget::addCtLandmark));
      m_viewConnections.push_back(connect(view, &SliceViewWidget::ctPointClicked, this, [this](const QString& layer, int index) {
        const auto& ct = m_document->landmarks().ct;
        if (layer == kClickLayer && index >= 0 && index < static_cast<int>(ct.size())) {
          selectLandmark(QString::fromStdString(ct[static_cast<std::size_t>(index)].name));
        }
      }));
      m_viewConnections.push_back(connect(
          view, &SliceViewWidget::ctPointDragged, this, [this](const QString& layer, int index, const Eigen::Vector3d& p) {
            const auto& ct = m_document->landmarks().ct;
            if (layer == kClickLayer && index >= 0 && index < static_cast<int>(ct.size())) {
              moveCtLandmark(QString::fromStdString(ct[static_cast<std::size_t>(index)].name), p);
            }
          }));
    }
    for (std::size_t v = 0; v < m_xrayViews.size(); ++v) {
      const int viewIndex = static_cast<int>(v);
      m_viewConnections.push_back(connect(m_xrayViews[v], &XrayViewWidget::pixelClicked, this,
                                          [this, viewIndex](const Eigen::Vector2d& uv_px) {
                                            setImagePoint(viewIndex, uv_px);
                                          }));
      m_viewConnections.push_back(connect(m_xrayViews[v], &XrayViewWidget::markerClicked, this,
                                          [this, viewIndex](const QString& layer, int index) {
                                            const auto& names = m_clickLayerNames[static_cast<std::size_t>(viewIndex)];
                                            if (layer == kClickLayer && index >= 0 && index < static_cast<int>(names.size())) {
                                              selectLandmark(names[static_cast<std::size_t>(index)]);
                                            }
                                          }));
      m_viewConnections.push_back(
          connect(m_xrayViews[v], &XrayViewWidget::pointDragged, this,
                  [this, viewIndex](const QString& layer, int index, const Eigen::Vector2d& uv_px) {
                    onPointDragged(viewIndex, layer, index, uv_px);
                  }));
    }
  }
  updateLayers();
}

QString LandmarkStepWidget::ruleText() {
  return tr("A pose needs at least 4 landmarks, not on one line, each clicked in at least one X-ray view, and either 4 "
            "of them clicked in the same view or 3 of them clicked in two views each.");
}

QString LandmarkStepWidget::missingText() const {
  const Landmarks& landmarks = m_document->landmarks();
  const auto clickedIn = [&landmarks](const std::string& view, const std::string& name) {
    const auto found = landmarks.imageByView.find(view);
    return found != landmarks.imageByView.end() &&
           std::any_of(found->second.begin(), found->second.end(), [&](const ImageLandmark& p) { return p.name == name; });
  };
  QStringList todo;
  const int count = static_cast<int>(landmarks.ct.size());
  if (count < 4) todo << tr("add %n more landmark(s) in a CT slice view", nullptr, 4 - count);
  QStringList unclicked;
  int inTwoViews = 0;
  for (const CtLandmark& landmark : landmarks.ct) {
    int views = 0;
    for (const RegistrationView& view : m_document->views()) views += clickedIn(view.name, landmark.name) ? 1 : 0;
    if (views == 0) unclicked << QString::fromStdString(landmark.name);
    if (views >= 2) ++inTwoViews;
  }
  if (!unclicked.isEmpty()) todo << tr("click %1 in an X-ray view (or delete it)").arg(unclicked.join(QStringLiteral(", ")));
  int most = 0;
  QString mostView;
  QStringList perView;
  for (const RegistrationView& view : m_document->views()) {
    const int clicked = static_cast<int>(std::count_if(landmarks.ct.begin(), landmarks.ct.end(), [&](const CtLandmark& l) {
      return clickedIn(view.name, l.name);
    }));
    perView << QStringLiteral("%1 %2").arg(QString::fromStdString(view.name)).arg(clicked);
    if (clicked > most || mostView.isEmpty()) {
      most = clicked;
      mostView = QString::fromStdString(view.name);
    }
  }
  if (!m_document->views().empty() && most < 4 && inTwoViews < 3) {
    todo << tr("click %n more landmark(s) in view '%1' (it has %2 of the 4 one view needs)", nullptr, 4 - most)
                .arg(mostView)
                .arg(most) +
                tr(", or %n more in a second view (%1 of 3 are clicked in two views)", nullptr, 3 - inTwoViews)
                    .arg(inTwoViews);
  }
  if (todo.isEmpty()) return {};
  QString text = todo.join(QStringLiteral("; ")) + QLatin1Char('.');
  if (!perView.isEmpty()) text += tr(" Clicked per view: %1.").arg(perView.join(QStringLiteral(", ")));
  return text;
}

QString LandmarkStepWidget::selectedLandmark() const { return m_selected; }

QString LandmarkStepWidget::message() const { return m_message->text(); }

void LandmarkStepWidget::showMessage(const QString& text, bool error) {
  m_message->setStyleSheet(error ? QStringLiteral("color: #c0392b;") : QString());
  m_message->setText(text);
}

void LandmarkStepWidget::addCtLandmark(const Eigen::Vector3d& p_ct_mm) {
  if (!m_document->ct()) {
    showMessage(tr("No CT loaded: open a CT in the Data step before placing landmarks."), true);
    return;
  }
  Landmarks landmarks = m_document->landmarks();
  std::string name;
  for (std::size_t n = landmarks.ct.size() + 1;; ++n) {
    name = fmt::format("L{}", n);
    if (!nameInUse(landmarks, name)) break;
  }
  landmarks.ct.push_back(CtLandmark{name, p_ct_mm});
  m_selected = QString::fromStdString(name);
  commit(std::move(landmarks), tr("Add %1").arg(m_selected));
  showMessage(tr("Added %1 at %2; now click its partner in the X-ray views.")
                  .arg(m_selected, SliceViewWidget::positionText(p_ct_mm)),
              false);
}

void LandmarkStepWidget::setImagePoint(int viewIndex, const Eigen::Vector2d& uv_px) {
  const auto& views = m_document->views();
  if (viewIndex < 0 || viewIndex >= static_cast<int>(views.size())) {
    showMessage(tr("X-ray view %1 does not exist (%2 views are loaded).").arg(viewIndex + 1).arg(views.size()), true);
    return;
  }
  if (m_selected.isEmpty()) {
    showMessage(tr("Select a landmark in the table (or add one in a CT slice view) before clicking in an X-ray view."),
                true);
    return;
  }
  Landmarks landmarks = m_document->landmarks();
  const std::string name = m_selected.toStdString();
  std::vector<ImageLandmark>& points = landmarks.imageByView[views[static_cast<std::size_t>(viewIndex)].name];
  auto found = std::find_if(points.begin(), points.end(), [&](const ImageLandmark& p) { return p.name == name; });
  const QString viewName = QString::fromStdString(views[static_cast<std::size_t>(viewIndex)].name);
  const bool moved = found != points.end();
  if (moved) {
    found->uv_px = uv_px;
  } else {
    points.push_back(ImageLandmark{name, uv_px});
  }
  commit(std::move(landmarks), (moved ? tr("Move %1 in %2") : tr("Place %1 in %2")).arg(m_selected, viewName),
         moved ? m_selected + QLatin1Char('@') + viewName : QString());
  showMessage(tr("%1 placed in view '%2' at (%3, %4) px.")
                  .arg(m_selected, QString::fromStdString(views[static_cast<std::size_t>(viewIndex)].name))
                  .arg(uv_px.x(), 0, 'f', 1)
                  .arg(uv_px.y(), 0, 'f', 1),
              false);
}

void LandmarkStepWidget::selectLandmark(const QString& name) {
  m_selected = rowOf(name) >= 0 ? name : QString();
  refresh();
}

bool LandmarkStepWidget::renameLandmark(const QString& oldName, const QString& newName) {
  const std::string from = oldName.toStdString();
  const std::string to = newName.trimmed().toStdString();
  Landmarks landmarks = m_document->landmarks();
  if (to.empty() || (to != from && nameInUse(landmarks, to))) {
    showMessage(to.empty() ? tr("A landmark name cannot be empty.")
                           : tr("The name '%1' is already used; choose another.").arg(QString::fromStdString(to)),
                true);
    refresh();
    return false;
  }
  for (CtLandmark& landmark : landmarks.ct) {
    if (landmark.name == from) landmark.name = to;
  }
  for (auto& [view, points] : landmarks.imageByView) {
    for (ImageLandmark& point : points) {
      if (point.name == from) point.name = to;
    }
  }
  if (m_selected == oldName) m_selected = QString::fromStdString(to);
  commit(std::move(landmarks), tr("Rename %1 to %2").arg(oldName, QString::fromStdString(to)));
  return true;
}

void LandmarkStepWidget::deleteLandmark(const QString& name) {
  if (name.isEmpty()) {
    showMessage(tr("Select the landmark to delete in the table."), true);
    return;
  }
  const std::string target = name.toStdString();
  Landmarks landmarks = m_document->landmarks();
  const auto named = [&target](const auto& landmark) { return landmark.name == target; };
  std::erase_if(landmarks.ct, named);
  for (auto& [view, points] : landmarks.imageByView) std::erase_if(points, named);
  std::erase_if(landmarks.imageByView, [](const auto& entry) { return entry.second.empty(); });
  if (m_selected == name) m_selected.clear();
  commit(std::move(landmarks), tr("Delete %1").arg(name));
  showMessage(tr("Deleted %1 (Ctrl+Z brings it back).").arg(name), false);
}

void LandmarkStepWidget::moveCtLandmark(const QString& name, const Eigen::Vector3d& p_ct_mm) {
  Landmarks landmarks = m_document->landmarks();
  const std::string target = name.toStdString();
  auto found = std::find_if(landmarks.ct.begin(), landmarks.ct.end(), [&](const CtLandmark& l) { return l.name == target; });
  if (found == landmarks.ct.end() || !p_ct_mm.allFinite()) return;
  found->p_ct_mm = p_ct_mm;
  m_selected = name;
  commit(std::move(landmarks), tr("Move %1 in the CT").arg(name), name + QStringLiteral("@ct"));
  showMessage(tr("Moved %1 to %2.").arg(name, SliceViewWidget::positionText(p_ct_mm)), false);
}

void LandmarkStepWidget::commit(Landmarks landmarks, const QString& text, const QString& dragKey) {
  m_editing = true;
  m_undo->push(new LandmarkEditCommand(m_document, m_document->landmarks(), std::move(landmarks), text, dragKey));
  m_editing = false;
  m_undoAction->setEnabled(m_active && m_undo->canUndo());
  m_redoAction->setEnabled(m_active && m_undo->canRedo());
}

void LandmarkStepWidget::undo() {
  if (!m_undo->canUndo()) return;
  const QString text = m_undo->undoText();
  m_editing = true;
  m_undo->undo();
  m_editing = false;
  m_undoAction->setEnabled(m_active && m_undo->canUndo());
  m_redoAction->setEnabled(m_active && m_undo->canRedo());
  showMessage(tr("Undid: %1.").arg(text), false);
}

void LandmarkStepWidget::redo() {
  if (!m_undo->canRedo()) return;
  const QString text = m_undo->redoText();
  m_editing = true;
  m_undo->redo();
  m_editing = false;
  m_undoAction->setEnabled(m_active && m_undo->canUndo());
  m_redoAction->setEnabled(m_active && m_undo->canRedo());
  showMessage(tr("Redid: %1.").arg(text), false);
}

void LandmarkStepWidget::jumpTo(const QString& name) {
  const int row = rowOf(name);
  if (row < 0) return;
  const Eigen::Vector3d p_ct_mm = m_document->landmarks().ct[static_cast<std::size_t>(row)].p_ct_mm;
  for (SliceViewWidget* view : m_sliceViews) {
    if (view) view->setCrosshair_ct_mm(p_ct_mm);
  }
}

bool LandmarkStepWidget::eventFilter(QObject* watched, QEvent* event) {
  if (watched == m_table->viewport() && event->type() == QEvent::MouseButtonPress) {
    const auto* press = static_cast<QMouseEvent*>(event);
    if (!m_table->itemAt(press->position().toPoint())) {
      selectLandmark({});
      return true;
    }
  }
  return QWidget::eventFilter(watched, event);
}

void LandmarkStepWidget::restoreEstimate() {
  const auto& pose = m_document->initialPose();
  if (m_estimate || !pose || !m_document->initialPoseSource().startsWith(QStringLiteral("landmarks"))) return;
  auto estimate = LandmarkPoseEstimator::fromReprojection(m_document->landmarks(), camerasOf(*m_document));
  if (!estimate || !estimate.value().T_world_from_ct.isApprox(*pose, 1e-6)) return;  // the landmarks moved since
  m_estimate = std::move(estimate).value();
  refresh();
}

bool LandmarkStepWidget::computePose() {
  if (m_document->views().empty()) {
    showMessage(tr("No X-ray views loaded: open a view file in the Data step first."), true);
    return false;
  }
  if (const QString missing = missingText(); !missing.isEmpty()) {
    showMessage(tr("Not enough clicks for a pose yet. To do: %1").arg(missing), true);
    return false;
  }
  auto estimate = LandmarkPoseEstimator::fromReprojection(m_document->landmarks(), camerasOf(*m_document));
  if (!estimate) {
    showMessage(tr("Cannot compute the pose: %1. Move or replace a landmark and compute again.")
                    .arg(QString::fromStdString(estimate.error())),
                true);
    return false;
  }
  m_estimate = std::move(estimate).value();
  const QString source = tr("landmarks (%1 pairs, %2)")
                             .arg(m_estimate->residuals.size())
                             .arg(QString::fromStdString(m_estimate->method));
  m_document->setInitialPose(m_estimate->T_world_from_ct, source);
  QString text = tr("Initial pose from %1 landmarks (%2): RMS reprojection %3 px")
                     .arg(m_estimate->residuals.size())
                     .arg(QString::fromStdString(m_estimate->method))
                     .arg(m_estimate->rmsReprojection_px, 0, 'f', 2);
  if (std::isfinite(m_estimate->rms3d_mm)) text += tr(", RMS 3-D %1 mm").arg(m_estimate->rms3d_mm, 0, 'f', 2);
  showMessage(text + QLatin1Char('.'), false);
  refresh();
  return true;
}

bool LandmarkStepWidget::applySetupPose() {
  const auto& ct = m_document->ct();
  if (!ct) {
    showMessage(tr("No CT loaded: open a CT in the Data step first."), true);
    return false;
  }
  std::vector<Camera> cameras;
  for (const RegistrationView& view : m_document->views()) cameras.push_back(view.camera);
  auto bone = BoneSurface::extract(*ct);
  const Eigen::Vector3d centre_ct_mm = bone ? bone.value().centroid_ct_mm() : ct->centre_lps_mm();
  auto pose = SetupPose::supineAtIsocentre(centre_ct_mm, cameras);
  if (!pose) {
    showMessage(tr("Cannot set the supine AP pose: %1").arg(QString::fromStdString(pose.error())), true);
    return false;
  }
  m_estimate.reset();
  m_document->setInitialPose(pose.value(), tr("preset supine AP"));
  showMessage(tr("Initial pose: supine AP, %1 at the C-arm isocentre.")
                  .arg(bone ? tr("bone centre") : tr("CT centre (no bone found)")),
              false);
  refresh();
  return true;
}

bool LandmarkStepWidget::loadLandmarks(const QString& ctPath, const QString& imagePath) {
  auto ct = LandmarkFile::readCt(ctPath.toStdString());
  if (!ct) {
    showMessage(tr("Cannot load the CT landmarks: %1").arg(QString::fromStdString(ct.error())), true);
    return false;
  }
  Landmarks landmarks;
  landmarks.ct = std::move(ct).value();
  if (!imagePath.isEmpty()) {
    auto image = LandmarkFile::readImage(imagePath.toStdString());
    if (!image) {
      showMessage(tr("Cannot load the X-ray landmarks: %1").arg(QString::fromStdString(image.error())), true);
      return false;
    }
    landmarks.imageByView = std::move(image).value();
  }
  m_selected.clear();
  const std::size_t count = landmarks.ct.size();
  commit(std::move(landmarks), tr("Load landmarks"));
  showMessage(tr("Loaded %1 CT landmarks.").arg(count), false);
  return true;
}

bool LandmarkStepWidget::saveLandmarks(const QString& ctPath, const QString& imagePath) {
  const Landmarks& landmarks = m_document->landmarks();
  if (Status written = LandmarkFile::writeCt(landmarks.ct, ctPath.toStdString()); !written) {
    showMessage(tr("Cannot save the CT landmarks: %1").arg(QString::fromStdString(written.error())), true);
    return false;
  }
  if (!imagePath.isEmpty()) {
    if (Status written = LandmarkFile::writeImage(landmarks.imageByView, imagePath.toStdString()); !written) {
      showMessage(tr("Cannot save the X-ray landmarks: %1").arg(QString::fromStdString(written.error())), true);
      return false;
    }
  }
  showMessage(tr("Saved %1 landmarks to %2.").arg(landmarks.ct.size()).arg(ctPath), false);
  return true;
}

int LandmarkStepWidget::rowOf(const QString& name) const {
  const auto& ct = m_document->landmarks().ct;
  for (std::size_t i = 0; i < ct.size(); ++i) {
    if (QString::fromStdString(ct[i].name) == name) return static_cast<int>(i);
  }
  return -1;
}

void LandmarkStepWidget::refresh() {
  m_refreshing = true;
  const Landmarks& landmarks = m_document->landmarks();
  if (rowOf(m_selected) < 0) m_selected.clear();
  m_table->setRowCount(static_cast<int>(landmarks.ct.size()));
  for (std::size_t i = 0; i < landmarks.ct.size(); ++i) {
    const CtLandmark& landmark = landmarks.ct[i];
    const int row = static_cast<int>(i);
    auto* nameItem = new QTableWidgetItem(QString::fromStdString(landmark.name));
    nameItem->setToolTip(nameItem->text());
    m_table->setItem(row, kName, nameItem);
    m_table->setItem(row, kCt, readOnlyItem(QStringLiteral("%1, %2, %3")
                                                .arg(landmark.p_ct_mm.x(), 0, 'f', 1)
                                                .arg(landmark.p_ct_mm.y(), 0, 'f', 1)
                                                .arg(landmark.p_ct_mm.z(), 0, 'f', 1)));
    QStringList views;
    for (const auto& [view, points] : landmarks.imageByView) {
      const bool has = std::any_of(points.begin(), points.end(),
                                   [&](const ImageLandmark& p) { return p.name == landmark.name; });
      if (has) views << QString::fromStdString(view);
    }
    m_table->setItem(row, kViews, readOnlyItem(views.isEmpty() ? tr("none yet") : views.join(QStringLiteral(", "))));
    QString residualPx = QStringLiteral("—");
    QString residualMm = QStringLiteral("—");
    if (m_estimate) {
      for (const LandmarkResidual& residual : m_estimate->residuals) {
        if (residual.name != landmark.name) continue;
        double worst_px = 0.0;
        for (const auto& [view, px] : residual.reprojection_px) worst_px = std::max(worst_px, px);
        residualPx = tr("%1 px").arg(worst_px, 0, 'f', 2);
        if (std::isfinite(residual.distance_mm)) residualMm = tr("%1 mm").arg(residual.distance_mm, 0, 'f', 2);
      }
    }
    m_table->setItem(row, kResidualPx, readOnlyItem(residualPx));
    m_table->setItem(row, kResidualMm, readOnlyItem(residualMm));
  }
  const int selectedRow = rowOf(m_selected);
  if (selectedRow >= 0) {
    m_table->setCurrentCell(selectedRow, kName);
  } else {
    m_table->clearSelection();
  }
  m_deleteButton->setEnabled(!landmarks.ct.empty());
  m_missing->setText(missingText().isEmpty() ? tr("Enough clicks for a pose: press Compute pose.")
                                             : tr("Still to do: %1").arg(missingText()));
  m_refreshing = false;
  updateLayers();
}

void LandmarkStepWidget::updateLayers() {
  const Landmarks& landmarks = m_document->landmarks();
  const auto& views = m_document->views();
  m_clickLayerNames.assign(m_xrayViews.size(), {});
  for (std::size_t v = 0; v < m_xrayViews.size(); ++v) {
    XrayViewWidget* xrayView = m_xrayViews[v];
    if (!m_active || v >= views.size()) {
      xrayView->setLayerVisible(kClickLayer, false);
      xrayView->setLayerVisible(kProjectedLayer, false);
      continue;
    }
    std::vector<OverlayPoint> clicks;
    if (auto found = landmarks.imageByView.find(views[v].name); found != landmarks.imageByView.end()) {
      for (const ImageLandmark& point : found->second) {
        const QString name = QString::fromStdString(point.name);
        clicks.push_back(OverlayPoint{point.uv_px, name, name == m_selected ? kSelectedColour : kClickColour});
        m_clickLayerNames[v].push_back(name);
      }
    }
    xrayView->setPointLayer(kClickLayer, std::move(clicks), true);
    std::vector<OverlayPoint> projected;
    if (m_estimate) {
      for (const CtLandmark& landmark : landmarks.ct) {
        bool inFront = false;
        const Eigen::Vector2d uv_px = views[v].camera.project(m_estimate->T_world_from_ct * landmark.p_ct_mm, &inFront);
        if (inFront) projected.push_back(OverlayPoint{uv_px, QString::fromStdString(landmark.name) + "'", kProjectedColour});
      }
    }
    xrayView->setPointLayer(kProjectedLayer, std::move(projected));
  }
  for (SliceViewWidget* sliceView : m_sliceViews) {
    if (!sliceView) continue;
    std::vector<SlicePoint> points;
    if (m_active) {
      for (const CtLandmark& landmark : landmarks.ct) {
        const QString name = QString::fromStdString(landmark.name);
        points.push_back(SlicePoint{landmark.p_ct_mm, name, name == m_selected ? kSelectedColour : kClickColour});
      }
    }
    sliceView->setCtPointLayer(kClickLayer, std::move(points), /*draggable=*/true);
  }
}

void LandmarkStepWidget::onPointDragged(int viewIndex, const QString& layer, int index, const Eigen::Vector2d& uv_px) {
  if (layer != kClickLayer || viewIndex < 0 || viewIndex >= static_cast<int>(m_clickLayerNames.size())) return;
  const auto& names = m_clickLayerNames[static_cast<std::size_t>(viewIndex)];
  if (index < 0 || index >= static_cast<int>(names.size())) return;
  m_selected = names[static_cast<std::size_t>(index)];
  setImagePoint(viewIndex, uv_px);
}

void LandmarkStepWidget::onItemChanged(int row, int column) {
  if (m_refreshing || column != kName) return;
  const auto& ct = m_document->landmarks().ct;
  if (row < 0 || row >= static_cast<int>(ct.size())) return;
  renameLandmark(QString::fromStdString(ct[static_cast<std::size_t>(row)].name), m_table->item(row, kName)->text());
}

void LandmarkStepWidget::loadWithDialog() {
  const QString ctPath = QFileDialog::getOpenFileName(this, tr("Open CT landmarks"), QString(),
                                                      tr("Slicer markups (*.mrk.json *.json)"));
  if (ctPath.isEmpty()) return;
  const QString imagePath = QFileDialog::getOpenFileName(this, tr("Open X-ray landmarks (cancel for none)"), QString(),
                                                         tr("X-ray landmarks (*.json)"));
  loadLandmarks(ctPath, imagePath);
}

void LandmarkStepWidget::saveWithDialog() {
  const QString ctPath = QFileDialog::getSaveFileName(this, tr("Save CT landmarks"), m_document->suggestedPath(QStringLiteral("landmarks.mrk.json")),
                                                      tr("Slicer markups (*.mrk.json)"));
  if (ctPath.isEmpty()) return;
  const QString imagePath = QFileDialog::getSaveFileName(this, tr("Save X-ray landmarks (cancel for none)"),
                                                         m_document->suggestedPath(QStringLiteral("landmarks_xray.json")),
                                                         tr("X-ray landmarks (*.json)"));
  saveLandmarks(ctPath, imagePath);
}

}  // namespace fct
