#pragma once
// RegisterStepWidget: the "Register" step. Preset, seed, DRR method and the paper's ablation switches; Run starts a
// RegistrationWorker on its own thread from the document's initial pose, with the document's ROI window and
// fraction in every ROI stage; a progress bar (stage, DRRs, best similarity) and a log follow it through queued
// signals while the window stays responsive. Cancel stops the run at the next DRR set; the best pose so far is kept
// and marked cancelled. The result (finished or cancelled) joins the document's result history, unless the CT or the
// views changed during the run (then it is reported and dropped); it becomes the current result unless the current one
// is accepted, which only the user replaces (Review step).

#include <QElapsedTimer>
#include <QFutureWatcher>
#include <QString>
#include <QWidget>

#include <array>
#include <optional>
#include <vector>

#include "Registration/Registration.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QPlainTextEdit;
class QProgressBar;
class QPushButton;
class QSpinBox;
class QThread;

namespace fct {

class RegistrationWorker;
class SliceViewWidget;
class StudioDocument;
class XrayViewWidget;

/// The Register step: runs and cancels registrations with progress.
class RegisterStepWidget : public QWidget {
  Q_OBJECT
 public:
  /// A step running registrations on `document`.
  explicit RegisterStepWidget(StudioDocument* document, QWidget* parent = nullptr);
  /// Cancels a running registration and waits for its thread.
  ~RegisterStepWidget() override;

  /// The views (this step draws nothing on them; kept for the common step interface).
  void attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3> sliceViews);
  /// Activating shows whether the step is ready (initial pose, ROI settings); a started run goes on either way.
  void setActive(bool active);

  /// True while a run prepares its case or registers.
  bool isRunning() const { return m_thread != nullptr || m_pending.has_value(); }
  /// The ablation switches in effect.
  RegistrationAblation ablation() const;
  /// Sets the ablation switches' check boxes.
  void setAblation(const RegistrationAblation& ablation);
  /// The last progress report of the current or last run.
  const RegistrationProgress& lastProgress() const { return m_lastProgress; }
  /// The message line, as shown.
  QString message() const;
  /// The log text.
  QString logText() const;
  /// What Run still needs, in words ("a CT (Data step), an initial pose (Initial pose step)"); empty when ready.
  QString missingInputs() const;
  /// The bone contrast control (RegistrationCaseOptions::boneContrast of the case).
  QDoubleSpinBox* boneContrastSpin() const { return m_boneContrastSpin; }
  /// The Run button (disabled while inputs are missing, its tooltip naming them).
  QPushButton* runButton() const { return m_runButton; }
  /// The progress line under the bar, as shown.
  QString progressText() const;
  /// The estimated run time of `preset` (a built-in name) on the current case, seconds, once the DRR speed has been
  /// measured on it (see RunTimeEstimator); nullopt before.
  std::optional<double> estimatedSeconds(const QString& preset) const;
  /// The estimate line beside the preset chooser, as shown.
  QString estimateText() const;
  /// A preset stage's name in words for the progress line and log: "whole" stages are the coarse alignment on whole
  /// images, a 1:1 ROI stage the final one at full resolution, other ROI stages the refinement on bone edges; the
  /// preset's own name is kept in brackets ("Refinement (bone edges, 1:4) [vlnc-rois-1:4]").
  static QString plainStageName(const std::string& stage);

 public slots:
  /// Starts a registration; false (with the reason shown) when one runs already or the CT, views, initial pose,
  /// preset or ROI settings are missing or wrong.
  bool run();
  /// Asks the running registration to stop (no effect when none runs).
  void cancel();

 signals:
  /// A run started (true) or ended (false).
  void runningChanged(bool running);
  /// The step's message changed (for the status line).
  void statusMessage(const QString& message);

 private:
  /// The document's background case preparation ended: starts the pending run, or ends it with the reason.
  void onCasePrepared(bool prepared, const QString& why);
  /// Starts the pending run on the document's ready case, on a worker thread.
  void startRegistration();
  /// Shows the time estimate of every preset; prepares the case and measures the DRR speed on it when needed.
  void updateEstimate();
  void onProgress(const RegistrationProgress& progress);
  void onFinished(const RegistrationResult& result);
  void onFailed(const QString& message);
  /// Stops and deletes the worker thread (its run has returned or is about to).
  void endThread();
  /// Enables the controls for the running state.
  void setRunningUi(bool running);
  /// Enables Run when nothing runs and no input is missing; its tooltip says what is missing.
  void updateRunButton();
  /// Copies the document's options into the controls.
  void syncControls();
  /// Writes the controls' options into the document.
  void pushOptions();
  void appendLog(const QString& line);
  /// Appends one line per stage of `result` to the log.
  void logStages(const RegistrationResult& result);
  /// When no run of this step is shown (e.g. after a session was opened), shows the document's current result: its
  /// summary, a full bar and its stages in the log.
  void showDocumentResult();
  void showMessage(const QString& text, bool error);

  StudioDocument* m_document;
  QThread* m_thread = nullptr;
  RegistrationWorker* m_worker = nullptr;
  RegistrationProgress m_lastProgress;
  /// A run waiting for its case: its start pose and options.
  struct Pending {
    Eigen::Isometry3d T_initial;
    RegistrationOptions options;
  };
  std::optional<Pending> m_pending;
  bool m_cancelRequested = false;         ///< Cancel was pressed while the case was prepared
  bool m_inputsChangedDuringRun = false;  ///< the CT or views changed while the run went on: its result is stale
  bool m_ranHere = false;                 ///< a run of this widget is shown (not a result from the session)
  QElapsedTimer m_runTimer;               ///< since the current run started (for the time left)
  bool m_active = false;
  /// The DRR speed calibration: seconds per pixel per level (empty and an error on failure).
  struct Speed {
    std::vector<double> secondsPerPixel;
    QString error;
  };
  QFutureWatcher<Speed>* m_speedWatcher;
  const RegistrationCase* m_speedCase = nullptr;  ///< the case m_speed was measured on (compared, never used)
  Speed m_speed;

  QComboBox* m_presetCombo;
  QLabel* m_estimateLabel;
  QSpinBox* m_seedSpin;
  QComboBox* m_methodCombo;
  QDoubleSpinBox* m_boneContrastSpin;
  QCheckBox* m_noRoisCheck;
  QCheckBox* m_noPyramidCheck;
  QCheckBox* m_nccOnlyCheck;
  QCheckBox* m_localOnlyCheck;
  QCheckBox* m_cmaesCheck;
  QCheckBox* m_noTransgraphCheck;
  QCheckBox* m_noCtPyramidCheck;
  QPushButton* m_runButton;
  QPushButton* m_cancelButton;
  QProgressBar* m_progressBar;
  QLabel* m_progressLabel;
  QLabel* m_message;
  QPlainTextEdit* m_log;
};

}  // namespace fct
