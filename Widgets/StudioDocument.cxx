#include "Widgets/StudioDocument.h"

#include <fmt/core.h>

#include <QMetaObject>

#include <algorithm>
#include <set>
#include <utility>

#include "Drr/DrrRendererFactory.h"
#include "Widgets/CasePreparation.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/CtLoader.h"
#include "IO/Xray/XrayLoader.h"
#include "IO/Project/DicomViewBuilder.h"
#include "Registration/RegistrationViewLoader.h"

namespace fct {

namespace fs = std::filesystem;

StudioDocument::StudioDocument(QObject* parent) : QObject(parent) {}

StudioDocument::~StudioDocument() = default;

void StudioDocument::touch() {
  setModified(true);
  emit changed();
}

void StudioDocument::setModified(bool modified) {
  if (modified == m_modified) return;
  m_modified = modified;
  emit modifiedChanged(modified);
}

Result<LoadedCt> StudioDocument::readCt(const fs::path& path, const DicomSeriesReadOptions& options) {
  auto ct = CtLoader::load(path, options);
  if (!ct) return fail(ct.error());
  std::vector<std::string> warnings = ct.warnings();
  return LoadedCt{std::make_shared<const Volume>(std::move(ct).value()), path, options.seriesInstanceUid,
                  std::move(warnings)};
}

Status StudioDocument::loadCt(const fs::path& path, const DicomSeriesReadOptions& options) {
  auto loaded = readCt(path, options);
  if (!loaded) return fail(loaded.error());
  setCt(std::move(loaded).value());
  return Ok{};
}

void StudioDocument::setCt(LoadedCt loaded) {
  setCt(std::move(loaded.ct), std::move(loaded.path), std::move(loaded.warnings), std::move(loaded.seriesUid));
}

void StudioDocument::setCt(std::shared_ptr<const Volume> ct, fs::path path, std::vector<std::string> warnings,
                           std::string seriesUid) {
  m_ct = std::move(ct);
  m_ctPath = std::move(path);
  m_ctWarnings = std::move(warnings);
  m_ctSeriesUid = std::move(seriesUid);
  invalidateCase();
  emit ctChanged();
  if (!m_landmarks.ct.empty() || !m_landmarks.imageByView.empty()) {
    m_landmarks = {};
    emit landmarksChanged();
  }
  dropPoseAndResults();
  touch();
}

Result<LoadedViews> StudioDocument::readViews(const fs::path& viewFile) {
  auto loaded = RegistrationViewLoader::load(viewFile);
  if (!loaded) return fail(loaded.error());
  std::vector<std::string> warnings = loaded.warnings();
  std::vector<RegistrationView> views = std::move(loaded).value();
  std::optional<Eigen::Isometry3d> truth;
  const fs::path truthPath = viewFile.parent_path() / "truth_pose.json";
  std::error_code ec;
  if (fs::exists(truthPath, ec)) {
    auto pose = PoseFile::read(truthPath);
    if (pose) {
      truth = pose.value();
    } else {
      warnings.push_back("ground truth not used: " + pose.error());
    }
  }
  return LoadedViews{std::move(views), viewFile, std::move(warnings), truth};
}

Status StudioDocument::loadViews(const fs::path& viewFile) {
  auto loaded = readViews(viewFile);
  if (!loaded) return fail(loaded.error());
  setViews(std::move(loaded).value());
  return Ok{};
}

void StudioDocument::setViews(LoadedViews loaded) {
  setViews(std::move(loaded.views), std::move(loaded.viewFile), std::move(loaded.warnings));
  setTruthPose(loaded.truthPose);
}

Result<RegistrationView> StudioDocument::readXrayFile(const fs::path& path) {
  const std::string advice = "open a view file that lists this image with its calibrated camera instead";
  if (XrayLoader::isPlainImageFile(path)) {
    return fail(fmt::format("{} has no C-arm geometry (a PNG/TIFF carries no DICOM distance and angle tags); {}",
                            path.string(), advice));
  }
  auto spec = DicomViewBuilder::build({path});
  if (!spec) return fail(fmt::format("{}; {}", spec.error(), advice));
  auto view = RegistrationViewLoader::loadView(spec.value().front());
  if (!view) return fail(view.error());
  for (const std::string& warning : spec.warnings()) view.addWarning(warning);
  return view;
}

Status StudioDocument::addXrayFile(const fs::path& path) {
  auto read = readXrayFile(path);
  if (!read) return fail(read.error());
  const std::vector<std::string> warnings = read.warnings();
  std::vector<RegistrationView> views;
  views.push_back(std::move(read).value());
  return addXrayViews(std::move(views), warnings);
}

Status StudioDocument::addXrayViews(std::vector<RegistrationView> added, const std::vector<std::string>& warnings) {
  if (!m_viewFilePath.empty()) {
    const std::string file = added.empty() ? std::string("the X-rays") : added.front().xray.sourcePath;
    return fail(fmt::format("the views come from the view file {}; list {} in that file, or open the X-ray files "
                            "alone after File > New session",
                            m_viewFilePath.string(), file));
  }
  std::set<std::string> names;
  for (const RegistrationView& existing : m_views) names.insert(existing.name);
  std::vector<RegistrationView> views = m_views;
  for (RegistrationView& view : added) {
    const std::string stem = view.name;
    for (int n = 2; names.count(view.name); ++n) view.name = fmt::format("{}-{}", stem, n);
    names.insert(view.name);
    views.push_back(std::move(view));
  }
  std::vector<std::string> allWarnings = m_viewWarnings;
  allWarnings.insert(allWarnings.end(), warnings.begin(), warnings.end());
  setViews(std::move(views), {}, std::move(allWarnings));
  return Ok{};
}

void StudioDocument::setViews(std::vector<RegistrationView> views, fs::path viewFile, std::vector<std::string> warnings) {
  // The old views' X-ray landmarks and windows survive only when the old views are kept as they were (views added).
  const auto sameView = [](const RegistrationView& a, const RegistrationView& b) {
    return a.name == b.name && a.xray.sourcePath == b.xray.sourcePath;
  };
  const bool appended = viewFile == m_viewFilePath && views.size() >= m_views.size() &&
                        std::equal(m_views.begin(), m_views.end(), views.begin(), sameView);
  m_views = std::move(views);
  m_viewFilePath = std::move(viewFile);
  m_viewWarnings = std::move(warnings);
  invalidateCase();
  emit viewsChanged();
  if (!appended) {
    m_xrayWindows.clear();
    if (!m_landmarks.imageByView.empty()) {
      m_landmarks.imageByView.clear();
      emit landmarksChanged();
    }
  }
  dropPoseAndResults();
  touch();
}

void StudioDocument::dropPoseAndResults() {
  if (m_initialPose) {
    m_initialPose.reset();
    m_initialPoseSource.clear();
    emit initialPoseChanged();
  }
  if (!m_results.empty()) {
    m_results.clear();
    m_currentResult = -1;
    emit resultChanged();
  }
  if (m_truthPose) {
    m_truthPose.reset();
    emit truthPoseChanged();
  }
}

QString StudioDocument::suggestedPath(const QString& fileName) const {
  fs::path folder;
  if (!m_sessionPath.empty()) {
    folder = m_sessionPath.parent_path();
  } else if (!m_viewFilePath.empty()) {
    folder = m_viewFilePath.parent_path();
  } else if (!m_views.empty() && !m_views.front().xray.sourcePath.empty()) {
    folder = fs::path(m_views.front().xray.sourcePath).parent_path();
  } else if (!m_ctPath.empty()) {
    folder = m_ctPath.parent_path();  // a DICOM folder's parent, too
  }
  if (folder.empty()) return fileName;
  return QString::fromStdString((folder / fileName.toStdString()).string());
}

bool StudioDocument::hasDerivedState() const {
  return !m_landmarks.ct.empty() || !m_landmarks.imageByView.empty() || m_initialPose || !m_results.empty();
}

void StudioDocument::setXrayWindow(const std::string& viewName, const DisplayWindow& window) {
  const auto found = m_xrayWindows.find(viewName);
  if (found != m_xrayWindows.end() && found->second == window) return;
  m_xrayWindows[viewName] = window;
  emit xrayWindowsChanged();
  touch();
}

int StudioDocument::viewIndex(const std::string& name) const {
  for (std::size_t v = 0; v < m_views.size(); ++v) {
    if (m_views[v].name == name) return static_cast<int>(v);
  }
  return -1;
}

void StudioDocument::setLandmarks(Landmarks landmarks) {
  m_landmarks = std::move(landmarks);
  emit landmarksChanged();
  touch();
}

void StudioDocument::setInitialPose(std::optional<Eigen::Isometry3d> T_world_from_ct, QString source) {
  m_initialPose = std::move(T_world_from_ct);
  m_initialPoseSource = m_initialPose ? std::move(source) : QString();
  emit initialPoseChanged();
  touch();
}

void StudioDocument::setRoiParameters(const RoiParameters& parameters) {
  if (parameters == m_roi) return;
  const bool exclusionsChanged = parameters.margin_px != m_roi.margin_px ||
                                 parameters.detectFieldOfView != m_roi.detectFieldOfView ||
                                 parameters.detectSpheres != m_roi.detectSpheres ||
                                 parameters.sphereMargin_px != m_roi.sphereMargin_px ||
                                 parameters.cutFaceMargin_mm != m_roi.cutFaceMargin_mm;
  m_roi = parameters;
  if (exclusionsChanged) invalidateCase();
  emit roiParametersChanged();
  touch();
}

void StudioDocument::setRegistrationOptions(const StudioRegistrationOptions& options) {
  if (options == m_options) return;
  if (options.drrMethod != m_options.drrMethod || options.boneContrast != m_options.boneContrast) invalidateCase();
  m_options = options;
  emit registrationOptionsChanged();
  touch();
}

XrayPreparationOptions StudioDocument::preparationOptions() const {
  XrayPreparationOptions preparation;
  preparation.detectFieldOfView = m_roi.detectFieldOfView;
  preparation.margin_px = m_roi.margin_px;
  preparation.detectSpheres = m_roi.detectSpheres;
  preparation.sphereMargin_px = m_roi.sphereMargin_px;
  return preparation;
}

Result<RegistrationCaseOptions> StudioDocument::caseOptions() const {
  if (!m_ct) return fail("no CT loaded; open a CT in the Data step first");
  if (m_views.empty()) return fail("no X-ray views loaded; open a view file in the Data step first");
  auto method = DrrRendererFactory::parseMethod(m_options.drrMethod);
  if (!method) return fail(method.error());
  RegistrationCaseOptions options;
  options.drr.method = method.value();
  options.preparation = preparationOptions();
  options.cutFaceMargin_mm = m_roi.cutFaceMargin_mm;
  options.boneContrast = m_options.boneContrast;
  return options;
}

Result<std::shared_ptr<RegistrationCase>> StudioDocument::preparedCase() {
  if (m_case) return m_case;
  if (m_preparation) {
    const Status adopted = adoptPreparation();
    if (!adopted) return fail(adopted.error());
    return m_case;
  }
  auto options = caseOptions();
  if (!options) return fail(options.error());
  auto created = RegistrationCase::create(*m_ct, m_views, options.value());
  if (!created) return fail(created.error());
  Result<std::shared_ptr<RegistrationCase>> prepared(std::make_shared<RegistrationCase>(std::move(created).value()));
  for (const std::string& warning : created.warnings()) prepared.addWarning(warning);
  m_case = prepared.value();
  emit casePreparationFinished(true, QString());
  return prepared;
}

void StudioDocument::prepareCaseInBackground() {
  if (m_case || m_preparation) return;
  auto options = caseOptions();
  if (!options) {
    const QString why = QString::fromStdString(options.error());
    QMetaObject::invokeMethod(this, [this, why] { emit casePreparationFinished(false, why); }, Qt::QueuedConnection);
    return;
  }
  m_preparation = new CasePreparation(m_ct, m_views, options.value(), this);
  connect(m_preparation, &CasePreparation::progressed, this, &StudioDocument::casePreparationProgressed);
  connect(m_preparation, &CasePreparation::finished, this, [this] {
    if (m_preparation) (void)adoptPreparation();  // its failure reaches the views through casePreparationFinished
  });
}

void StudioDocument::cancelCasePreparation() {
  if (m_preparation) m_preparation->cancel();
}

Status StudioDocument::adoptPreparation() {
  CasePreparation::Outcome outcome = m_preparation->wait();
  m_preparation->deleteLater();
  m_preparation = nullptr;
  if (!outcome.prepared) {
    emit casePreparationFinished(false, QString::fromStdString(outcome.error));
    return fail(outcome.error);
  }
  m_case = std::move(outcome.prepared);
  emit casePreparationFinished(true, QString());
  return Ok{};
}

void StudioDocument::invalidateCase() {
  m_case.reset();
  if (!m_preparation) return;
  // The old inputs' preparation goes on to its next step, then deletes itself; its case is never used.
  CasePreparation* stale = m_preparation;
  m_preparation = nullptr;
  stale->disconnect(this);
  stale->cancel();
  connect(stale, &CasePreparation::finished, stale, &QObject::deleteLater);
  const QString why = tr("the CT, the views, the exclusions or the DRR method changed while the case was prepared");
  QMetaObject::invokeMethod(this, [this, why] { emit casePreparationFinished(false, why); }, Qt::QueuedConnection);
}

const RegistrationResult* StudioDocument::result() const {
  return m_currentResult >= 0 ? &m_results[static_cast<std::size_t>(m_currentResult)].result : nullptr;
}

ResultVerdict StudioDocument::resultVerdict() const {
  return m_currentResult >= 0 ? m_results[static_cast<std::size_t>(m_currentResult)].verdict : ResultVerdict::Undecided;
}

bool StudioDocument::addResult(RegistrationResult result) {
  m_results.push_back(StudioResult{std::move(result), ResultVerdict::Undecided});
  const bool becomesCurrent = resultVerdict() != ResultVerdict::Accepted;
  if (becomesCurrent) m_currentResult = static_cast<int>(m_results.size()) - 1;
  emit resultChanged();
  touch();
  return becomesCurrent;
}

void StudioDocument::setCurrentResult(int index) {
  if (index < 0 || index >= static_cast<int>(m_results.size()) || index == m_currentResult) return;
  m_currentResult = index;
  emit resultChanged();
  touch();
}

void StudioDocument::setResults(std::vector<StudioResult> results, int current) {
  m_results = std::move(results);
  m_currentResult = m_results.empty() ? -1 : std::clamp(current, 0, static_cast<int>(m_results.size()) - 1);
  emit resultChanged();
  touch();
}

void StudioDocument::setResultVerdict(ResultVerdict verdict) {
  if (m_currentResult < 0 || verdict == resultVerdict()) return;
  m_results[static_cast<std::size_t>(m_currentResult)].verdict = verdict;
  emit resultChanged();
  touch();
}

void StudioDocument::setTruthPose(std::optional<Eigen::Isometry3d> T_world_from_ct) {
  m_truthPose = std::move(T_world_from_ct);
  emit truthPoseChanged();
  touch();
}

void StudioDocument::clear() {
  m_ct.reset();
  m_ctPath.clear();
  m_ctSeriesUid.clear();
  m_ctWarnings.clear();
  m_views.clear();
  m_viewFilePath.clear();
  m_viewWarnings.clear();
  m_landmarks = {};
  m_initialPose.reset();
  m_initialPoseSource.clear();
  m_roi = {};
  m_options = {};
  m_results.clear();
  m_currentResult = -1;
  m_xrayWindows.clear();
  m_truthPose.reset();
  m_sessionPath.clear();
  invalidateCase();
  emit ctChanged();
  emit viewsChanged();
  emit landmarksChanged();
  emit initialPoseChanged();
  emit roiParametersChanged();
  emit registrationOptionsChanged();
  emit resultChanged();
  emit truthPoseChanged();
  emit changed();
  setModified(false);
}

}  // namespace fct
