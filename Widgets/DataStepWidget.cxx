#include "Widgets/DataStepWidget.h"

#include <fmt/core.h>

#include <QComboBox>
#include <QFileDialog>
#include <QFutureWatcher>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QTableWidget>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrentRun>

#include <optional>

#include "IO/Project/PoseFile.h"
#include "Widgets/StudioDocument.h"

namespace fct {

namespace fs = std::filesystem;

namespace {

QString qs(const std::string& s) { return QString::fromStdString(s); }
QString qs(const fs::path& p) { return QString::fromStdString(p.string()); }

/// What a case folder load brings.
struct LoadedCase {
  LoadedCt ct;
  LoadedViews views;
  std::optional<Eigen::Isometry3d> initialPose;
  fs::path initialPosePath;
};

/// An HTML list of warnings (empty string when none).
QString warningList(const std::vector<std::string>& warnings, const QString& title) {
  if (warnings.empty()) return {};
  QString html = QStringLiteral("<b>%1</b><ul style='margin:0'>").arg(title.toHtmlEscaped());
  for (const std::string& w : warnings) html += QStringLiteral("<li>%1</li>").arg(qs(w).toHtmlEscaped());
  return html + QStringLiteral("</ul>");
}

}  // namespace

DataStepWidget::DataStepWidget(StudioDocument* document, QWidget* parent) : QWidget(parent), m_document(document) {
  auto* layout = new QVBoxLayout(this);

  auto* ctBox = new QGroupBox(tr("CT"), this);
  auto* ctLayout = new QVBoxLayout(ctBox);
  auto* ctButtons = new QHBoxLayout;
  m_openDicom = new QPushButton(tr("Open DICOM folder…"), ctBox);
  m_openDicom->setToolTip(tr("Read a CT series from a folder of DICOM files (searched recursively)"));
  m_openVolume = new QPushButton(tr("Open volume file…"), ctBox);
  m_openVolume->setToolTip(tr("Read a CT from a NIfTI, NRRD or MetaImage file"));
  ctButtons->addWidget(m_openDicom);
  ctButtons->addWidget(m_openVolume);
  ctLayout->addLayout(ctButtons);
  m_seriesRow = new QWidget(ctBox);
  auto* seriesLayout = new QHBoxLayout(m_seriesRow);
  seriesLayout->setContentsMargins(0, 0, 0, 0);
  m_seriesChooser = new QComboBox(m_seriesRow);
  m_seriesChooser->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  m_loadSeries = new QPushButton(tr("Load series"), m_seriesRow);
  seriesLayout->addWidget(new QLabel(tr("Series:"), m_seriesRow));
  seriesLayout->addWidget(m_seriesChooser, 1);
  seriesLayout->addWidget(m_loadSeries);
  m_seriesRow->hide();
  ctLayout->addWidget(m_seriesRow);
  m_ctSummary = new QLabel(ctBox);  // not word-wrapped: wrapped labels get clipped in the step's scroll area
  m_ctSummary->setTextInteractionFlags(Qt::TextSelectableByMouse);
  ctLayout->addWidget(m_ctSummary);
  layout->addWidget(ctBox);

  auto* viewBox = new QGroupBox(tr("X-ray views"), this);
  auto* viewLayout = new QVBoxLayout(viewBox);
  auto* viewButtons = new QHBoxLayout;
  m_openViews = new QPushButton(tr("Open view file…"), viewBox);
  m_openViews->setToolTip(tr("Read a view file (JSON) listing each X-ray with its calibrated C-arm camera"));
  m_addXrays = new QPushButton(tr("Views from DICOM tags…"), viewBox);
  m_addXrays->setToolTip(tr("Pick X-ray DICOM files (XA, RF, DX, CR): one view each, its camera from the C-arm "
                            "geometry tags (distances, pixel spacing, positioner angles, patient orientation)"));
  viewButtons->addWidget(m_openViews);
  viewButtons->addWidget(m_addXrays);
  viewLayout->addLayout(viewButtons);
  m_viewTable = new QTableWidget(0, 5, viewBox);
  m_viewTable->setHorizontalHeaderLabels({tr("View"), tr("Image"), tr("Pixels"), tr("Type"), tr("SID (mm)")});
  m_viewTable->horizontalHeaderItem(4)->setToolTip(tr("Source-to-detector distance of the view's camera, mm"));
  m_viewTable->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  m_viewTable->horizontalHeader()->setSectionResizeMode(1, QHeaderView::Stretch);  // the file name gives way
  m_viewTable->setTextElideMode(Qt::ElideMiddle);
  m_viewTable->verticalHeader()->hide();
  m_viewTable->setEditTriggers(QAbstractItemView::NoEditTriggers);
  m_viewTable->setSelectionMode(QAbstractItemView::NoSelection);
  m_viewTable->setMaximumHeight(150);
  viewLayout->addWidget(m_viewTable);
  m_viewSummary = new QLabel(viewBox);
  viewLayout->addWidget(m_viewSummary);
  layout->addWidget(viewBox);

  m_openCase = new QPushButton(tr("Open case folder…"), this);
  m_openCase->setToolTip(tr("A folder with ct.nrrd (or another volume, or a DICOM folder 'ct'), views.json and "
                            "optionally initial_pose.json and truth_pose.json"));
  layout->addWidget(m_openCase);

  m_busyBar = new QProgressBar(this);
  m_busyBar->setRange(0, 0);
  m_busyBar->hide();
  layout->addWidget(m_busyBar);
  m_warnings = new QLabel(this);
  m_warnings->setWordWrap(true);
  m_warnings->setStyleSheet(QStringLiteral("color: #b8860b;"));
  layout->addWidget(m_warnings);
  m_error = new QLabel(this);
  m_error->setWordWrap(true);
  m_error->setStyleSheet(QStringLiteral("color: #d03030; font-weight: bold;"));
  m_error->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(m_error);
  layout->addStretch(1);

  connect(m_openDicom, &QPushButton::clicked, this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(this, tr("Open a DICOM folder"));
    if (!folder.isEmpty()) openCt(folder);
  });
  connect(m_openVolume, &QPushButton::clicked, this, [this] {
    const QString file = QFileDialog::getOpenFileName(
        this, tr("Open a CT volume file"), {}, tr("Volumes (*.nii *.nii.gz *.nrrd *.nhdr *.mha *.mhd);;All files (*)"));
    if (!file.isEmpty()) openCt(file);
  });
  connect(m_loadSeries, &QPushButton::clicked, this, [this] {
    if (mayChangeInputs()) loadChosenSeries();
  });
  connect(m_openViews, &QPushButton::clicked, this, [this] {
    const QString file = QFileDialog::getOpenFileName(this, tr("Open a view file"), {},
                                                      tr("View files (*.json);;All files (*)"));
    if (!file.isEmpty()) openViewFile(file);
  });
  connect(m_addXrays, &QPushButton::clicked, this, [this] {
    const QStringList files = QFileDialog::getOpenFileNames(this, tr("Views from DICOM tags: pick X-ray DICOM files"));
    if (!files.isEmpty()) addXrayFiles(files);
  });
  connect(m_openCase, &QPushButton::clicked, this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(this, tr("Open a case folder"));
    if (!folder.isEmpty()) openCaseFolder(folder);
  });
  connect(document, &StudioDocument::ctChanged, this, &DataStepWidget::refreshSummary);
  connect(document, &StudioDocument::viewsChanged, this, &DataStepWidget::refreshSummary);
  connect(document, &StudioDocument::truthPoseChanged, this, &DataStepWidget::refreshSummary);
  connect(document, &StudioDocument::initialPoseChanged, this, &DataStepWidget::refreshSummary);
  refreshSummary();
}

QString DataStepWidget::errorText() const { return m_error->text(); }

QString DataStepWidget::summaryText() const {
  return m_ctSummary->text() + QLatin1Char('\n') + m_viewSummary->text() + QLatin1Char('\n') + m_warnings->text();
}

int DataStepWidget::seriesChoiceCount() const { return m_seriesRow->isHidden() ? 0 : m_seriesChooser->count(); }

template <typename T>
void DataStepWidget::runInBackground(const QString& what, std::function<T()> work, std::function<void(T&)> done) {
  setBusy(true, what);
  auto* watcher = new QFutureWatcher<std::shared_ptr<T>>(this);
  connect(watcher, &QFutureWatcherBase::finished, this, [this, watcher, done] {
    const std::shared_ptr<T> outcome = watcher->result();
    watcher->deleteLater();
    setBusy(false);
    done(*outcome);
  });
  watcher->setFuture(QtConcurrent::run([work] { return std::make_shared<T>(work()); }));
}

void DataStepWidget::setBusy(bool busy, const QString& what) {
  m_busy = busy;
  for (QPushButton* button : {m_openDicom, m_openVolume, m_openViews, m_addXrays, m_openCase, m_loadSeries}) {
    button->setEnabled(!busy);
  }
  m_busyBar->setVisible(busy);
  m_busyBar->setFormat(what);
  m_busyBar->setTextVisible(busy);
  if (busy) {
    m_error->clear();
    emit statusMessage(what);
  }
}

bool DataStepWidget::mayChangeInputs() const { return !m_busy && (!m_inputGuard || m_inputGuard()); }

void DataStepWidget::reportError(const QString& what, const std::string& message) {
  const QString text = what + QStringLiteral(": ") + qs(message);
  m_error->setText(text);
  emit statusMessage(text);
  emit loadFinished(false, text);
}

void DataStepWidget::reportSuccess(const QString& message) {
  m_error->clear();
  emit statusMessage(message);
  emit loadFinished(true, message);
}

void DataStepWidget::openCt(const QString& path) {
  if (!mayChangeInputs()) return;
  const fs::path p = path.toStdString();
  std::error_code ec;
  if (!fs::is_directory(p, ec)) {
    m_seriesRow->hide();
    runInBackground<Result<LoadedCt>>(
        tr("Loading the CT %1…").arg(qs(p.filename())), [p] { return StudioDocument::readCt(p); },
        [this](Result<LoadedCt>& loaded) {
          if (!loaded) return reportError(tr("Could not open the CT"), loaded.error());
          m_document->setCt(std::move(loaded).value());
          reportSuccess(tr("Loaded the CT %1").arg(qs(m_document->ctPath().filename())));
        });
    return;
  }
  runInBackground<Result<std::vector<DicomSeriesSummary>>>(
      tr("Looking for DICOM series in %1…").arg(path), [p] { return DicomSeriesReader::scan(p); },
      [this, p](Result<std::vector<DicomSeriesSummary>>& scanned) {
        if (!scanned) {
          m_seriesRow->hide();
          return reportError(tr("Could not open the DICOM folder"), scanned.error());
        }
        m_scannedFolder = p;
        m_series = scanned.value();
        m_seriesChooser->clear();
        for (const DicomSeriesSummary& s : m_series) {
          m_seriesChooser->addItem(tr("%1 %2 — %3 images %4×%5")
                                       .arg(qs(s.modality), qs(s.seriesDescription.empty() ? "(no description)"
                                                                                           : s.seriesDescription))
                                       .arg(s.fileCount)
                                       .arg(s.cols)
                                       .arg(s.rows));
        }
        if (m_series.size() == 1) {
          m_seriesRow->hide();
          loadChosenSeries();
          return;
        }
        m_seriesRow->show();
        const QString message = tr("%1 series found in %2: choose one and press Load series")
                                    .arg(m_series.size())
                                    .arg(qs(p.filename()));
        emit statusMessage(message);
        emit loadFinished(true, message);
      });
}

void DataStepWidget::chooseSeries(int index) {
  if (index >= 0 && index < m_seriesChooser->count()) m_seriesChooser->setCurrentIndex(index);
}

void DataStepWidget::loadChosenSeries() {
  const int index = m_seriesChooser->currentIndex();
  if (m_busy || index < 0 || index >= static_cast<int>(m_series.size())) return;
  DicomSeriesReadOptions options;
  options.seriesInstanceUid = m_series[static_cast<std::size_t>(index)].seriesInstanceUid;
  const fs::path folder = m_scannedFolder;
  runInBackground<Result<LoadedCt>>(
      tr("Loading the DICOM series…"), [folder, options] { return StudioDocument::readCt(folder, options); },
      [this](Result<LoadedCt>& loaded) {
        if (!loaded) return reportError(tr("Could not read the DICOM series"), loaded.error());
        m_document->setCt(std::move(loaded).value());
        reportSuccess(tr("Loaded the CT series from %1").arg(qs(m_document->ctPath().filename())));
      });
}

void DataStepWidget::openViewFile(const QString& path) {
  if (!mayChangeInputs()) return;
  const fs::path p = path.toStdString();
  runInBackground<Result<LoadedViews>>(
      tr("Loading the views of %1…").arg(qs(p.filename())), [p] { return StudioDocument::readViews(p); },
      [this](Result<LoadedViews>& loaded) {
        if (!loaded) return reportError(tr("Could not open the view file"), loaded.error());
        m_document->setViews(std::move(loaded).value());
        reportSuccess(tr("Loaded %1 views from %2")
                          .arg(m_document->views().size())
                          .arg(qs(m_document->viewFilePath().filename())));
      });
}

void DataStepWidget::addXrayFiles(const QStringList& paths) {
  if (paths.isEmpty() || !mayChangeInputs()) return;
  std::vector<fs::path> files;
  for (const QString& path : paths) files.push_back(path.toStdString());
  using Views = Result<std::vector<RegistrationView>>;
  runInBackground<Views>(
      tr("Loading %1 X-ray file(s)…").arg(paths.size()),
      [files]() -> Views {
        std::vector<RegistrationView> views;
        std::vector<std::string> warnings;
        for (const fs::path& file : files) {
          auto view = StudioDocument::readXrayFile(file);
          if (!view) return fail(view.error());
          warnings.insert(warnings.end(), view.warnings().begin(), view.warnings().end());
          views.push_back(std::move(view).value());
        }
        Views result(std::move(views));
        for (std::string& warning : warnings) result.addWarning(std::move(warning));
        return result;
      },
      [this](Views& loaded) {
        if (!loaded) return reportError(tr("Could not add the X-rays"), loaded.error());
        const Status added = m_document->addXrayViews(loaded.value(), loaded.warnings());
        if (!added) return reportError(tr("Could not add the X-rays"), added.error());
        reportSuccess(tr("Added %1 X-ray view(s)").arg(loaded.value().size()));
      });
}

Result<DataStepWidget::CaseFiles> DataStepWidget::findCaseFiles(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    return fail(fmt::format("{} is not a folder; give a case folder with ct.nrrd and views.json", folder.string()));
  }
  CaseFiles files;
  for (const char* name : {"ct.nrrd", "ct.nhdr", "ct.mha", "ct.mhd", "ct.nii.gz", "ct.nii", "ct"}) {
    if (fs::exists(folder / name, ec)) {
      files.ct = folder / name;
      break;
    }
  }
  if (files.ct.empty()) {
    return fail(fmt::format("{} has no CT: put it there as ct.nrrd (or ct.nii.gz, ct.mha, or a DICOM folder 'ct')",
                            folder.string()));
  }
  files.views = folder / "views.json";
  if (!fs::exists(files.views, ec)) {
    return fail(fmt::format("{} has no views.json; put the view file of the X-rays there", folder.string()));
  }
  if (fs::exists(folder / "initial_pose.json", ec)) files.initialPose = folder / "initial_pose.json";
  return files;
}

void DataStepWidget::openCaseFolder(const QString& folder) {
  if (!mayChangeInputs()) return;
  auto files = findCaseFiles(folder.toStdString());
  if (!files) return reportError(tr("Could not open the case folder"), files.error());
  const CaseFiles f = files.value();
  runInBackground<Result<LoadedCase>>(
      tr("Loading the case %1…").arg(folder),
      [f]() -> Result<LoadedCase> {
        auto ct = StudioDocument::readCt(f.ct);
        if (!ct) return fail(ct.error());
        auto views = StudioDocument::readViews(f.views);
        if (!views) return fail(views.error());
        LoadedCase loaded{std::move(ct).value(), std::move(views).value(), std::nullopt, f.initialPose};
        if (!f.initialPose.empty()) {
          auto pose = PoseFile::read(f.initialPose);
          if (!pose) return fail(pose.error());
          loaded.initialPose = pose.value();
        }
        return loaded;
      },
      [this, folder](Result<LoadedCase>& loaded) {
        if (!loaded) return reportError(tr("Could not open the case folder"), loaded.error());
        LoadedCase& c = loaded.value();
        m_document->setSessionPath({});  // another case: saving must not overwrite the old case's session file
        m_document->setCt(std::move(c.ct));
        m_document->setViews(std::move(c.views));
        if (c.initialPose) {
          m_document->setInitialPose(c.initialPose, tr("pose file %1").arg(qs(c.initialPosePath.filename())));
        }
        reportSuccess(tr("Opened the case %1").arg(folder));
      });
}

void DataStepWidget::refreshSummary() {
  if (const auto& ct = m_document->ct()) {
    const auto [low, high] = ct->valueRange();
    const Eigen::Vector3d size_mm = ct->spacing_mm().cwiseProduct(ct->dims().cast<double>());
    m_ctSummary->setText(tr("<b>%1</b><br>%2 × %3 × %4 voxels of %5 × %6 × %7 mm<br>(%8 × %9 × %10 mm), values %11 to "
                            "%12 HU<br><small>%13</small>")
                             .arg(qs(m_document->ctPath().filename()).toHtmlEscaped())
                             .arg(ct->dims().x())
                             .arg(ct->dims().y())
                             .arg(ct->dims().z())
                             .arg(ct->spacing_mm().x(), 0, 'f', 2)
                             .arg(ct->spacing_mm().y(), 0, 'f', 2)
                             .arg(ct->spacing_mm().z(), 0, 'f', 2)
                             .arg(size_mm.x(), 0, 'f', 0)
                             .arg(size_mm.y(), 0, 'f', 0)
                             .arg(size_mm.z(), 0, 'f', 0)
                             .arg(low, 0, 'f', 0)
                             .arg(high, 0, 'f', 0)
                             .arg(qs(ct->description).left(60).toHtmlEscaped()));
    m_ctSummary->setToolTip(qs(ct->description));
  } else {
    m_ctSummary->setText(tr("No CT loaded.<br>Open a DICOM folder or a volume file."));
  }

  const auto& views = m_document->views();
  m_viewTable->setRowCount(static_cast<int>(views.size()));
  for (std::size_t v = 0; v < views.size(); ++v) {
    const RegistrationView& view = views[v];
    const int row = static_cast<int>(v);
    m_viewTable->setItem(row, 0, new QTableWidgetItem(qs(view.name)));
    m_viewTable->setItem(row, 1, new QTableWidgetItem(qs(fs::path(view.xray.sourcePath).filename())));
    m_viewTable->setItem(row, 2, new QTableWidgetItem(QStringLiteral("%1×%2").arg(view.xray.cols).arg(view.xray.rows)));
    m_viewTable->setItem(row, 3, new QTableWidgetItem(qs(view.xray.modality)));
    m_viewTable->setItem(row, 4, new QTableWidgetItem(
                                     QString::number(view.camera.intrinsics().sourceToDetector_mm, 'f', 0)));
  }
  QString viewText;
  if (views.empty()) {
    viewText = tr("No X-ray views loaded. Open a view file<br>(or X-ray DICOMs with C-arm geometry).");
  } else {
    viewText = m_document->viewFilePath().empty()
                   ? tr("%1 view(s) from X-ray files").arg(views.size())
                   : tr("%1 view(s) from %2").arg(views.size()).arg(qs(m_document->viewFilePath().filename()));
    if (m_document->truthPose()) {
      viewText += tr("<br>Ground truth pose known (simulated case):<br>the Review step shows the error against it.");
    }
    viewText += m_document->initialPose()
                    ? tr("<br>Initial pose from %1.").arg(m_document->initialPoseSource().toHtmlEscaped())
                    : tr("<br>No initial pose yet: set one in the Initial pose step.");
  }
  m_viewSummary->setText(viewText);
  m_warnings->setText(warningList(m_document->ctWarnings(), tr("CT warnings")) +
                      warningList(m_document->viewWarnings(), tr("View warnings")));
}

}  // namespace fct
