#pragma once
// DataStepWidget: the Data step of the workflow: open a CT (DICOM folder, choosing among its series, or a volume
// file), a view file with its X-rays, views from the C-arm tags of X-ray DICOM files, or a whole case folder; show what
// was loaded and any warnings in words. Loading runs on a worker thread with a busy bar; a failure shows the message
// in the step (and the status line) and leaves the document as it was. Before a load replaces an input, the input
// guard (set by the main window) may ask whether the work derived from the old inputs may go.

#include <QString>
#include <QStringList>
#include <QWidget>

#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "Base/Result.h"
#include "IO/Dicom/DicomSeriesReader.h"

class QComboBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QTableWidget;
class QWidget;

namespace fct {

class StudioDocument;

/// The Data step.
class DataStepWidget : public QWidget {
  Q_OBJECT
 public:
  /// A Data step working on `document`.
  explicit DataStepWidget(StudioDocument* document, QWidget* parent = nullptr);

  /// True while a load runs in the background.
  bool isBusy() const { return m_busy; }
  /// The error shown in the step (empty when the last action succeeded).
  QString errorText() const;
  /// The description of the loaded CT and views, as shown.
  QString summaryText() const;
  /// Number of series offered in the series chooser (0 when hidden).
  int seriesChoiceCount() const;

  /// The files of a case folder: DIR/views.json, a CT (DIR/ct.nrrd, .nhdr, .mha, .mhd, .nii, .nii.gz, or the DICOM
  /// folder DIR/ct), and optionally DIR/initial_pose.json. Fails naming what is missing.
  struct CaseFiles {
    std::filesystem::path ct;
    std::filesystem::path views;
    std::filesystem::path initialPose;  ///< empty if absent
  };
  static Result<CaseFiles> findCaseFiles(const std::filesystem::path& folder);

  /// Sets the function asked before any load that replaces or adds an input; a load goes on only if it returns true
  /// (none set: always).
  void setInputGuard(std::function<bool()> guard) { m_inputGuard = std::move(guard); }

 public slots:
  /// Opens a CT: a folder is scanned for DICOM series (one series is loaded at once; several are offered in the
  /// series chooser), a file is read as a volume. Runs in the background; loadFinished() reports the outcome.
  void openCt(const QString& path);
  /// Loads the series chosen in the series chooser from the scanned folder.
  void loadChosenSeries();
  /// Chooses series `index` (0-based, largest first) in the chooser.
  void chooseSeries(int index);
  /// Opens a view file and its X-rays (background; loadFinished()).
  void openViewFile(const QString& path);
  /// "Views from DICOM tags": adds one view per X-ray DICOM file, its camera from the file's C-arm geometry tags
  /// (StudioDocument::readXrayFile), in the background (loadFinished()).
  void addXrayFiles(const QStringList& paths);
  /// Opens a case folder (findCaseFiles): CT, views and initial pose together (background; loadFinished()).
  void openCaseFolder(const QString& folder);

 signals:
  /// A load ended: ok, and the message shown (what was loaded, or the error).
  void loadFinished(bool ok, const QString& message);
  /// A one-line message for the status line.
  void statusMessage(const QString& message);

 private:
  /// Runs `work` on a worker thread with the busy bar showing `what`, then `done` on the GUI thread.
  template <typename T>
  void runInBackground(const QString& what, std::function<T()> work, std::function<void(T&)> done);
  void setBusy(bool busy, const QString& what = {});
  /// True when no load runs and the input guard lets the inputs change.
  bool mayChangeInputs() const;
  /// Shows an error in the step and the status line and reports loadFinished(false).
  void reportError(const QString& what, const std::string& message);
  /// Reports success in the status line and loadFinished(true).
  void reportSuccess(const QString& message);
  /// Refreshes the description of the document's CT and views.
  void refreshSummary();

  StudioDocument* m_document;
  bool m_busy = false;
  std::function<bool()> m_inputGuard;
  std::filesystem::path m_scannedFolder;
  std::vector<DicomSeriesSummary> m_series;

  QPushButton* m_openDicom = nullptr;
  QPushButton* m_openVolume = nullptr;
  QPushButton* m_openViews = nullptr;
  QPushButton* m_addXrays = nullptr;
  QPushButton* m_openCase = nullptr;
  QWidget* m_seriesRow = nullptr;
  QComboBox* m_seriesChooser = nullptr;
  QPushButton* m_loadSeries = nullptr;
  QLabel* m_ctSummary = nullptr;
  QTableWidget* m_viewTable = nullptr;
  QLabel* m_viewSummary = nullptr;
  QLabel* m_warnings = nullptr;
  QLabel* m_error = nullptr;
  QProgressBar* m_busyBar = nullptr;
};

}  // namespace fct
