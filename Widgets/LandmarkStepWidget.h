#pragma once
// LandmarkStepWidget: the "Initial pose" step. A click in a CT slice view adds a CT landmark (named L1, L2, ...); a
// click in an X-ray view places the selected landmark's partner in that view. A table lists the landmarks (name
// editable, CT position, which views have a partner, residuals with their units); selecting a row moves every slice
// view to that landmark, clicking empty table space deselects. Landmarks can be dragged in the CT slices and the
// X-rays; a click on a marker selects it without moving it. Every edit can be undone and redone (Ctrl+Z,
// Ctrl+Shift+Z). The rule for a pose is stated above the table, and what is still missing (per landmark and per
// view) is shown below it and in the refusal, as what to do. "Compute pose" runs
// LandmarkPoseEstimator and draws the CT landmarks projected at the pose in every X-ray view; "Supine AP" places the
// bone centre at the C-arm isocentre (SetupPose). Landmarks load from and save to a Slicer .mrk.json (CT) and a 2-D
// landmark JSON (LandmarkFile). Errors are shown in the widget and leave the landmarks and the pose as they were.

#include <Eigen/Core>
#include <QMetaObject>
#include <QString>
#include <QWidget>

#include <array>
#include <optional>
#include <vector>

#include "InitialPose/LandmarkPoseEstimator.h"

class QAction;
class QLabel;
class QPushButton;
class QTableWidget;
class QUndoStack;

namespace fct {

class SliceViewWidget;
class StudioDocument;
class XrayViewWidget;

/// The Initial pose step: landmark pairs by clicking, pose from landmarks or from the setup.
class LandmarkStepWidget : public QWidget {
  Q_OBJECT
 public:
  /// Name of the X-ray point layer of the clicked partners (draggable).
  static inline const QString kClickLayer = QStringLiteral("landmarks");
  /// Widest a table column gets, pixels: a longer name is elided (the full name is its tooltip).
  static constexpr int kMaxColumnWidth_px = 160;
  /// Name of the X-ray point layer of the CT landmarks projected at the computed pose.
  static inline const QString kProjectedLayer = QStringLiteral("landmarks-projected");

  /// A step editing `document`'s landmarks and initial pose.
  explicit LandmarkStepWidget(StudioDocument* document, QWidget* parent = nullptr);

  /// The views this step draws on and takes clicks from: X-ray view i shows document view i.
  void attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3> sliceViews);
  /// While active the step listens to clicks in the views and shows its layers; inactive it does neither.
  void setActive(bool active);

  /// The landmark whose X-ray partners the next X-ray clicks place (empty: none selected).
  QString selectedLandmark() const;
  /// The message line (errors and results), as shown.
  QString message() const;
  /// The last pose estimate (residuals), if the current landmarks have one.
  const std::optional<LandmarkPoseEstimate>& estimate() const { return m_estimate; }
  /// What is still missing for a pose, in words ("" when the clicks suffice), as shown under the table.
  QString missingText() const;
  /// The undo history of the landmark edits.
  QUndoStack* undoStack() const { return m_undo; }
  /// The landmark table.
  QTableWidget* table() const { return m_table; }

  /// The rule for a pose, as stated above the table (that of LandmarkPoseEstimator::fromReprojection).
  static QString ruleText();

 public slots:
  /// Adds a CT landmark at p_ct_mm (LPS mm) named L<n> (the first unused n >= count + 1) and selects it.
  void addCtLandmark(const Eigen::Vector3d& p_ct_mm);
  /// Places (or moves) the selected landmark's partner in X-ray view `viewIndex` at uv_px; a message if none is
  /// selected or the view does not exist.
  void setImagePoint(int viewIndex, const Eigen::Vector2d& uv_px);
  /// Selects a landmark by name (empty clears the selection).
  void selectLandmark(const QString& name);
  /// Renames a landmark in the CT and every view; false (with a message) on an empty or used name.
  bool renameLandmark(const QString& oldName, const QString& newName);
  /// Deletes a landmark from the CT and every view.
  void deleteLandmark(const QString& name);
  /// Moves a CT landmark to p_ct_mm (LPS mm); merged with the next move of the same landmark into one undo step.
  void moveCtLandmark(const QString& name, const Eigen::Vector3d& p_ct_mm);
  /// Undoes / redoes the last landmark edit (Ctrl+Z / Ctrl+Shift+Z while the step is shown).
  void undo();
  void redo();
  /// Estimates the initial pose from the landmarks (joint reprojection); on success the document's initial pose is
  /// set, residuals fill the table and projected landmarks are drawn. False with the reason shown on failure.
  bool computePose();
  /// Sets the supine AP setup pose (bone centre at the views' isocentre). False with the reason on failure.
  bool applySetupPose();
  /// Replaces the landmarks by a CT .mrk.json and (optional, may be empty) an X-ray landmark JSON. False with the
  /// reason on failure (the landmarks unchanged).
  bool loadLandmarks(const QString& ctPath, const QString& imagePath);
  /// Writes the CT landmarks (.mrk.json) and, when imagePath is not empty, the X-ray landmarks. False on failure.
  bool saveLandmarks(const QString& ctPath, const QString& imagePath);

 private:
  /// Shows a message; `error` makes it red.
  void showMessage(const QString& text, bool error);
  /// Puts `landmarks` into the document as one undoable edit named `text` (see LandmarkEditCommand for dragKey).
  void commit(Landmarks landmarks, const QString& text, const QString& dragKey = {});
  /// Moves every slice view's crosshair to landmark `name`.
  void jumpTo(const QString& name);
  /// After a session is opened: the estimate of the landmarks again when the initial pose is theirs (residuals and
  /// projected landmarks come back).
  void restoreEstimate();
  /// Deselects on a click in empty table space.
  bool eventFilter(QObject* watched, QEvent* event) override;
  /// Rebuilds the table and the view layers from the document.
  void refresh();
  /// Redraws the landmark layers of every view.
  void updateLayers();
  /// Moves a clicked partner after a drag in X-ray view v.
  void onPointDragged(int viewIndex, const QString& layer, int index, const Eigen::Vector2d& uv_px);
  /// A table cell was edited (a rename).
  void onItemChanged(int row, int column);
  /// The CT landmark's row in the table, or -1.
  int rowOf(const QString& name) const;
  /// Asks for file names, then loads or saves.
  void loadWithDialog();
  void saveWithDialog();

  StudioDocument* m_document;
  std::vector<XrayViewWidget*> m_xrayViews;
  std::array<SliceViewWidget*, 3> m_sliceViews{};
  std::vector<QMetaObject::Connection> m_viewConnections;
  bool m_active = false;
  bool m_refreshing = false;
  bool m_editing = false;  ///< the landmarks change through this step's undo stack
  QString m_selected;
  std::optional<LandmarkPoseEstimate> m_estimate;
  std::vector<std::vector<QString>> m_clickLayerNames;  ///< per X-ray view: landmark name of each layer point

  QTableWidget* m_table;
  QLabel* m_missing;
  QLabel* m_message;
  QUndoStack* m_undo;
  QAction* m_undoAction;
  QAction* m_redoAction;
  QPushButton* m_computeButton;
  QPushButton* m_deleteButton;
};

}  // namespace fct
