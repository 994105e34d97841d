#pragma once
// StudioDocument: the state of one FluoroCT Studio session, shared by every step widget and view: the CT, the C-arm
// views with their X-rays, the landmarks, the initial pose, the ROI parameters, the registration options, the history
// of registration results with the user's verdicts, and the X-ray display windows. Setters emit one specific signal
// per part and `changed()`; any change marks the document modified. Replacing the CT or the views drops everything
// derived from them (landmarks of the replaced input, initial pose, results, ground truth), so no result outlives the
// images it was made from. Loading goes through CtLoader, RegistrationViewLoader and XrayLoader and never throws:
// failures come back as a Status whose message says what to do, and leave the document as it was.

#include <Eigen/Geometry>
#include <QObject>
#include <QString>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Landmarks.h"
#include "Image/Volume.h"
#include "IO/Dicom/DicomSeriesReader.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationCase.h"

namespace fct {

class CasePreparation;

/// How the dynamic ROIs are chosen and which pixels are excluded (full-resolution pixels unless said otherwise).
struct RoiParameters {
  int windowSize = 7;               ///< w of the w x w windows, pixels of the level they are chosen on
  bool useThreshold = false;        ///< true: keep windows with normalized variance >= varianceThreshold
  double targetFraction = 0.12;     ///< false: keep this fraction of the valid pixels (0 < f <= 1)
  double varianceThreshold = 1.0;   ///< normalized-variance threshold (window variance / image variance)
  int margin_px = 8;                ///< band along the image borders excluded
  bool detectFieldOfView = true;    ///< detect the circular / collimated field of view and exclude outside it
  bool detectSpheres = false;       ///< also detect calibration-sphere shadows (view-file spheres are always used)
  double sphereMargin_px = 2.0;     ///< added to each sphere's radius when excluding it
  /// Rays passing within this distance of the CT's end faces (mm) are not compared: beyond them the X-ray shows
  /// anatomy the CT lacks (RegistrationCaseOptions::cutFaceMargin_mm, the CLI's --cut-face-margin-mm); negative: off.
  double cutFaceMargin_mm = RegistrationCaseOptions::kDefaultCutFaceMargin_mm;

  bool operator==(const RoiParameters&) const = default;
};

/// What the Register step runs.
struct StudioRegistrationOptions {
  std::string preset = RegistrationSchedule::kDefaultPreset;  ///< built-in preset name or a preset JSON file
  std::uint32_t seed = 1;            ///< seed of the random searches
  std::string drrMethod = "siddon";  ///< DRR method (DrrRendererFactory names)
  double boneContrast = RegistrationCaseOptions::kDefaultBoneContrast;  ///< the DRRs' bone contrast (case option)

  bool operator==(const StudioRegistrationOptions&) const = default;
};

/// The user's verdict on a registration result.
enum class ResultVerdict { Undecided, Accepted, Rejected };

/// One entry of the session's result history: a registration result and the user's verdict on it.
struct StudioResult {
  RegistrationResult result;
  ResultVerdict verdict = ResultVerdict::Undecided;
};

/// A display window of an image view: width and centre, in the image's units.
struct DisplayWindow {
  double window = 1.0;
  double level = 0.5;

  bool operator==(const DisplayWindow&) const = default;
};

/// A CT read from disk, ready to be put into a document (see StudioDocument::readCt).
struct LoadedCt {
  std::shared_ptr<const Volume> ct;
  std::filesystem::path path;
  std::string seriesUid;
  std::vector<std::string> warnings;
};

/// Views read from a view file with their X-rays, ready to be put into a document (see StudioDocument::readViews).
struct LoadedViews {
  std::vector<RegistrationView> views;
  std::filesystem::path viewFile;
  std::vector<std::string> warnings;
  std::optional<Eigen::Isometry3d> truthPose;  ///< truth_pose.json beside the view file, if present
};

/// The workstation state of one session.
class StudioDocument : public QObject {
  Q_OBJECT
 public:
  /// An empty, unmodified document.
  explicit StudioDocument(QObject* parent = nullptr);
  ~StudioDocument() override;

  // --- CT -------------------------------------------------------------------------------------------------------
  /// The CT (HU, LPS mm), or null when none is loaded.
  const std::shared_ptr<const Volume>& ct() const { return m_ct; }
  /// The file or folder the CT was loaded from (empty if none or set in memory).
  const std::filesystem::path& ctPath() const { return m_ctPath; }
  /// DICOM series UID chosen when the CT came from a folder (empty: the largest series).
  const std::string& ctSeriesUid() const { return m_ctSeriesUid; }
  /// Warnings of the CT load (resampling, ...), in words.
  const std::vector<std::string>& ctWarnings() const { return m_ctWarnings; }
  /// Reads a CT file or DICOM folder through CtLoader without touching any document (safe on a worker thread).
  static Result<LoadedCt> readCt(const std::filesystem::path& path, const DicomSeriesReadOptions& options = {});
  /// readCt() then setCt(). On failure the document is unchanged and the Status says why.
  Status loadCt(const std::filesystem::path& path, const DicomSeriesReadOptions& options = {});
  /// Puts a CT read by readCt() into the document (see the next setCt); emits ctChanged().
  void setCt(LoadedCt loaded);
  /// Replaces the CT (null clears it) with its source and warnings, dropping every landmark, the initial pose, the
  /// results and the ground truth (they belong to the old CT); emits ctChanged() and the signals of what was dropped.
  void setCt(std::shared_ptr<const Volume> ct, std::filesystem::path path = {}, std::vector<std::string> warnings = {},
             std::string seriesUid = {});

  // --- Views ----------------------------------------------------------------------------------------------------
  /// The C-arm views with their X-ray images and cameras.
  const std::vector<RegistrationView>& views() const { return m_views; }
  /// The view file they came from (empty if added otherwise).
  const std::filesystem::path& viewFilePath() const { return m_viewFilePath; }
  /// Warnings of the view load, in words.
  const std::vector<std::string>& viewWarnings() const { return m_viewWarnings; }
  /// Reads a view file and every view's image (RegistrationViewLoader), and truth_pose.json beside the view file as the
  /// ground truth if present, without touching any document (safe on a worker thread). Fails naming the view.
  static Result<LoadedViews> readViews(const std::filesystem::path& viewFile);
  /// readViews() then setViews(). On failure the document is unchanged and the Status says why.
  Status loadViews(const std::filesystem::path& viewFile);
  /// Puts views read by readViews() into the document with their ground truth (see the next setViews); emits
  /// viewsChanged() and truthPoseChanged().
  void setViews(LoadedViews loaded);
  /// Reads one X-ray DICOM file as a view named after the file, its camera from the C-arm geometry tags
  /// (DicomViewBuilder; a mirrored image is flipped), without touching any document. Fails when the file cannot be
  /// read or lacks geometry (naming the tag), or is a PNG/TIFF; the message says to use a view file.
  static Result<RegistrationView> readXrayFile(const std::filesystem::path& path);
  /// Adds one X-ray file (DICOM or PNG/TIFF) as a view; it needs its own geometry (DICOM C-arm tags), otherwise the
  /// Status says to use a view file. The view is named after the file (made unique). Refused while the views come
  /// from a view file. Emits viewsChanged().
  Status addXrayFile(const std::filesystem::path& path);
  /// Adds views read by readXrayFile() (names made unique) and their warnings; refused while the views come from a
  /// view file. Emits viewsChanged() once.
  Status addXrayViews(std::vector<RegistrationView> views, const std::vector<std::string>& warnings = {});
  /// Replaces the views and the view file path, dropping the X-ray landmarks of views no longer present (all of them
  /// when the view file changes), the initial pose, the results, the ground truth and the X-ray windows of the old
  /// views; emits viewsChanged() and the signals of what was dropped.
  void setViews(std::vector<RegistrationView> views, std::filesystem::path viewFile = {},
                std::vector<std::string> warnings = {});
  /// Index of the view with this name, or -1.
  int viewIndex(const std::string& name) const;

  // --- Landmarks and initial pose ------------------------------------------------------------------------------
  /// CT landmarks and, per view name, their clicked X-ray partners.
  const Landmarks& landmarks() const { return m_landmarks; }
  /// Replaces the landmarks; emits landmarksChanged().
  void setLandmarks(Landmarks landmarks);
  /// The initial pose T_world_from_ct (LPS mm), if set.
  const std::optional<Eigen::Isometry3d>& initialPose() const { return m_initialPose; }
  /// Where the initial pose came from, in words ("landmarks (4 pairs)", "preset supine AP", "pose file ...").
  const QString& initialPoseSource() const { return m_initialPoseSource; }
  /// Sets (or clears, with nullopt) the initial pose; emits initialPoseChanged().
  void setInitialPose(std::optional<Eigen::Isometry3d> T_world_from_ct, QString source = {});

  // --- ROI parameters and registration options ------------------------------------------------------------------
  /// The dynamic-ROI parameters and exclusions.
  const RoiParameters& roiParameters() const { return m_roi; }
  /// Replaces them; emits roiParametersChanged() when they differ.
  void setRoiParameters(const RoiParameters& parameters);
  /// The registration options.
  const StudioRegistrationOptions& registrationOptions() const { return m_options; }
  /// Replaces them; emits registrationOptionsChanged() when they differ.
  void setRegistrationOptions(const StudioRegistrationOptions& options);
  /// The XrayPreparation options of the ROI parameters' exclusions (view spheres are added per view by the case).
  XrayPreparationOptions preparationOptions() const;
  /// The options of the case of the current inputs; fails when the CT or the views are missing or the method is bad.
  Result<RegistrationCaseOptions> caseOptions() const;
  /// The registration case of the current CT, views, exclusions and DRR method, prepared on first call and kept
  /// until one of those changes. Slow on first call (seconds for a large CT; the widgets use
  /// prepareCaseInBackground() instead); joins a background preparation under way. Shared with whoever runs on it:
  /// do not call while a registration runs on another thread. Fails when the CT or the views are missing, or as
  /// RegistrationCase::create.
  Result<std::shared_ptr<RegistrationCase>> preparedCase();
  /// The prepared case when it is ready, else null (nothing is started).
  const std::shared_ptr<RegistrationCase>& readyCase() const { return m_case; }
  /// Prepares the case on a worker thread unless it is ready or under way: casePreparationProgressed() follows it,
  /// casePreparationFinished() ends it (queued, also when it cannot start: no CT, no views, an unknown DRR method).
  /// A change of the CT, the views, the exclusions or the DRR method meanwhile drops it (finished with an error).
  void prepareCaseInBackground();
  /// True while a background preparation is under way.
  bool isPreparingCase() const { return m_preparation != nullptr; }
  /// Stops a background preparation at its next step (it finishes with a "cancelled" error); no effect when none.
  void cancelCasePreparation();

  // --- Results and ground truth -----------------------------------------------------------------------------------
  /// Every registration result of the session with its verdict, oldest first.
  const std::vector<StudioResult>& results() const { return m_results; }
  /// Index in results() of the result shown and judged (-1: none).
  int currentResultIndex() const { return m_currentResult; }
  /// The current result, or null when there is none.
  const RegistrationResult* result() const;
  /// The user's verdict on the current result (Undecided when there is none).
  ResultVerdict resultVerdict() const;
  /// Appends a result (verdict Undecided) to the history. It becomes the current result unless the current one is
  /// accepted: an accepted result is only left by setCurrentResult(). Returns true if it became current. Emits
  /// resultChanged().
  bool addResult(RegistrationResult result);
  /// Makes results()[index] the current result (out of range: ignored); emits resultChanged().
  void setCurrentResult(int index);
  /// Replaces the whole history and the current index (clamped; -1 for none), as read from a session file; emits
  /// resultChanged().
  void setResults(std::vector<StudioResult> results, int current);
  /// Records accept or reject of the current result (no current result: ignored); emits resultChanged().
  void setResultVerdict(ResultVerdict verdict);
  /// The known true pose of a simulated case (T_world_from_ct), if any.
  const std::optional<Eigen::Isometry3d>& truthPose() const { return m_truthPose; }
  /// Sets or clears the ground truth; emits truthPoseChanged().
  void setTruthPose(std::optional<Eigen::Isometry3d> T_world_from_ct);

  // --- Display ---------------------------------------------------------------------------------------------------
  /// The window/level of each X-ray view the user set or that was read from the session, by view name.
  const std::map<std::string, DisplayWindow>& xrayWindows() const { return m_xrayWindows; }
  /// Records view `viewName`'s window/level (saved in the session); emits xrayWindowsChanged() when it differs.
  void setXrayWindow(const std::string& viewName, const DisplayWindow& window);

  /// True when the document holds work derived from its inputs (landmarks, an initial pose or results), which
  /// replacing the CT or the views would drop.
  bool hasDerivedState() const;

  // --- Session bookkeeping ------------------------------------------------------------------------------------------
  /// True when there are changes not saved to the session file.
  bool isModified() const { return m_modified; }
  /// Sets the modified flag; emits modifiedChanged() when it changes.
  void setModified(bool modified);
  /// The session file this document was last saved to or opened from (empty if none).
  const std::filesystem::path& sessionPath() const { return m_sessionPath; }
  /// `fileName` in the case folder, where save and export dialogs start: the session file's folder, else the view
  /// file's, else the first X-ray's, else the CT's (a bare file name, in the working folder, when there is none).
  QString suggestedPath(const QString& fileName) const;
  /// Sets the session file path (does not save).
  void setSessionPath(std::filesystem::path path) { m_sessionPath = std::move(path); }
  /// Empties the document (new session): every part cleared, not modified, no session path. Emits every signal.
  void clear();

 signals:
  /// The CT was replaced or cleared.
  void ctChanged();
  /// The views (X-rays and cameras) were replaced or added to.
  void viewsChanged();
  /// The landmarks were replaced.
  void landmarksChanged();
  /// The initial pose was set or cleared.
  void initialPoseChanged();
  /// The ROI parameters changed.
  void roiParametersChanged();
  /// The registration options changed.
  void registrationOptionsChanged();
  /// The result history, the current result or its verdict changed.
  void resultChanged();
  /// The ground truth was set or cleared.
  void truthPoseChanged();
  /// An X-ray view's recorded window/level changed.
  void xrayWindowsChanged();
  /// Emitted after any change of the content (for autosave and the title bar).
  void changed();
  /// The document became modified (true) or saved (false).
  void modifiedChanged(bool modified);
  /// A background case preparation started a step (in words) and is this far (0..1).
  void casePreparationProgressed(const QString& step, double fraction);
  /// The case became ready (prepared true), or a preparation failed, was cancelled or dropped (the message says why).
  void casePreparationFinished(bool prepared, const QString& message);

 private:
  /// Marks modified and emits changed().
  void touch();
  /// Drops the prepared case, and a background preparation of the old inputs.
  void invalidateCase();
  /// Takes the outcome of the background preparation (waiting for it), keeps its case and emits
  /// casePreparationFinished(); fails with its error.
  Status adoptPreparation();
  /// Drops the initial pose, the results and the ground truth after an input changed, emitting what changed.
  void dropPoseAndResults();

  std::shared_ptr<const Volume> m_ct;
  std::filesystem::path m_ctPath;
  std::string m_ctSeriesUid;
  std::vector<std::string> m_ctWarnings;
  std::vector<RegistrationView> m_views;
  std::filesystem::path m_viewFilePath;
  std::vector<std::string> m_viewWarnings;
  Landmarks m_landmarks;
  std::optional<Eigen::Isometry3d> m_initialPose;
  QString m_initialPoseSource;
  RoiParameters m_roi;
  StudioRegistrationOptions m_options;
  std::vector<StudioResult> m_results;
  int m_currentResult = -1;
  std::map<std::string, DisplayWindow> m_xrayWindows;
  std::optional<Eigen::Isometry3d> m_truthPose;
  bool m_modified = false;
  std::filesystem::path m_sessionPath;
  std::shared_ptr<RegistrationCase> m_case;
  CasePreparation* m_preparation = nullptr;  ///< the background preparation of the current inputs (child), or null
};

}  // namespace fct
