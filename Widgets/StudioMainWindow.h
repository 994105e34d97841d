#pragma once
// StudioMainWindow: the FluoroCT Studio main window, laid out as 3D Slicer is: the module panel on the left with the
// workflow steps (Data, Initial pose, ROIs, Register, Review, Track; one widget each), the views on the right (one view per
// X-ray on top; the axial, coronal and sagittal CT slices and the 3D view below, crosshair linked across the slices)
// and a status line. It owns the StudioDocument, its session file (save, open, recent sessions) and its autosave
// side file; unsaved changes are never dropped without asking.

#include <Eigen/Core>
#include <QMainWindow>
#include <QString>
#include <QStringList>

#include <array>
#include <filesystem>
#include <functional>
#include <vector>

class QLabel;
class QMenu;
class QSplitter;
class QToolBox;

namespace fct {

class DataStepWidget;
class Scene3DWidget;
class SessionAutosave;
class SliceViewWidget;
class StudioDocument;
class XrayViewWidget;

/// The desktop program's top-level window.
class StudioMainWindow : public QMainWindow {
  Q_OBJECT
 public:
  /// Builds the window with an empty document, the Data step and the views; `autosavePath` is the autosave side
  /// file (SessionAutosave::defaultPath() when empty).
  explicit StudioMainWindow(std::filesystem::path autosavePath = {}, QWidget* parent = nullptr);
  ~StudioMainWindow() override;

  /// The session state shared by every step and view.
  StudioDocument* document() const { return m_document; }
  /// The Data step.
  DataStepWidget* dataStep() const { return m_dataStep; }

  /// Adds a workflow step to the module panel (in order). A step widget may have `void setActive(bool)` (called when
  /// its page is shown or left) and `void attachViews(std::vector<XrayViewWidget*>, std::array<SliceViewWidget*, 3>)`
  /// (called now and whenever the X-ray views are rebuilt, e.g. after a new view file). Returns `step`.
  template <typename Step>
  Step* addStep(const QString& title, Step* step) {
    StepHooks hooks;
    if constexpr (requires { step->setActive(true); }) hooks.setActive = [step](bool active) { step->setActive(active); };
    if constexpr (requires { step->attachViews(std::vector<XrayViewWidget*>{}, std::array<SliceViewWidget*, 3>{}); }) {
      hooks.attachViews = [step](const std::vector<XrayViewWidget*>& xrays, const std::array<SliceViewWidget*, 3>& slices) {
        step->attachViews(xrays, slices);
      };
    }
    addStepWidget(title, step, std::move(hooks));
    return step;
  }
  /// Number of steps in the module panel.
  int stepCount() const;
  /// Title of step `index`.
  QString stepTitle(int index) const;
  /// Index of the step shown.
  int currentStep() const;

  /// The X-ray views (one per document view, in order).
  const std::vector<XrayViewWidget*>& xrayViews() const { return m_xrayViews; }
  /// The slice views: axial, coronal, sagittal.
  const std::array<SliceViewWidget*, 3>& sliceViews() const { return m_sliceViews; }
  /// The 3D view (null when the display has no OpenGL 3.2, e.g. Qt's offscreen platform).
  Scene3DWidget* sceneView() const { return m_scene; }
  /// The autosave of the document.
  SessionAutosave* autosave() const { return m_autosave; }

  /// The position readout of the status line (CT point and value, or X-ray pixel and value), as shown.
  QString hoverText() const;
  /// The last message shown in the message bar or status line.
  const QString& lastMessage() const { return m_lastMessage; }
  /// Recent session files, most recent first (QSettings "recentSessions").
  QStringList recentSessions() const;

 public slots:
  /// Shows step `index` (out-of-range indices are ignored).
  void showStep(int index);
  /// Shows the step whose title, lower-cased with spaces as '-', is `name` ("data", "initial-pose"); false if none.
  bool showStepNamed(const QString& name);
  /// Starts an empty session, after asking about unsaved changes. False if the user cancelled.
  bool newSession();
  /// Opens a session file, after asking about unsaved changes. A bad file shows the message and keeps the current
  /// session. False on cancel or failure.
  bool openSession(const QString& path);
  /// Saves to the session file (asks for a name the first time). False on cancel or failure.
  bool saveSession();
  /// Saves to `path` (adds it to the recent sessions). False on failure, with the message shown.
  bool saveSessionTo(const QString& path);
  /// Asks for a file name and saves there. False on cancel or failure.
  bool saveSessionAs();
  /// Restores the autosave side file left by a run that did not close normally (no question). False if there is
  /// none or it cannot be read (the message says why; the side file is kept).
  bool restoreAutosave();
  /// If an autosave side file exists, asks whether to restore it (restore or discard it). Call once at start-up.
  void offerAutosave();
  /// Asks whether to save unsaved changes (Save / Discard / Cancel), saying what the session holds. True when it is
  /// fine to drop the session.
  bool maybeSave();
  /// Before an input (CT, views) is replaced: when unsaved work derived from the inputs (landmarks, initial pose,
  /// results) would be dropped, asks as maybeSave() does. True when the inputs may change.
  bool mayReplaceInputs();
  /// What the session holds, in words ("the CT ct.nrrd, 2 X-ray views, 4 landmarks, …"), for the save questions.
  QString contentSummary() const;
  /// Shows an error in the message bar above the views and the status line.
  void showError(const QString& message);
  /// Shows a message in the status line.
  void showStatus(const QString& message);

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  struct StepHooks {
    std::function<void(bool)> setActive;
    std::function<void(const std::vector<XrayViewWidget*>&, const std::array<SliceViewWidget*, 3>&)> attachViews;
  };
  void addStepWidget(const QString& title, QWidget* step, StepHooks hooks);
  /// maybeSave() with `lead` (a paragraph saying why it asks) before the question.
  bool askToSave(const QString& lead);
  void buildMenus();
  /// Rebuilds the X-ray views from the document's views and re-attaches them to the steps.
  void rebuildXrayViews();
  /// Sets the window title from the session file and the modified flag.
  void updateTitle();
  void addRecentSession(const QString& path);
  void rebuildRecentMenu();
  /// Links the crosshair of the three slice views to p_ct_mm.
  void setCrosshair(const Eigen::Vector3d& p_ct_mm);

  StudioDocument* m_document = nullptr;
  SessionAutosave* m_autosave = nullptr;
  DataStepWidget* m_dataStep = nullptr;
  QToolBox* m_steps = nullptr;
  std::vector<StepHooks> m_stepHooks;
  int m_activeStep = -1;
  QSplitter* m_xrayRow = nullptr;
  QLabel* m_xrayPlaceholder = nullptr;  ///< shown instead of the X-ray views while there are none
  std::vector<XrayViewWidget*> m_xrayViews;
  std::array<SliceViewWidget*, 3> m_sliceViews{};
  Scene3DWidget* m_scene = nullptr;
  QLabel* m_messageBar = nullptr;
  QLabel* m_hover = nullptr;
  QMenu* m_recentMenu = nullptr;
  QString m_lastMessage;
};

}  // namespace fct
