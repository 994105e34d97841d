#pragma once
// TrackStepWidget: the "Track" step after Review: follows the bone through a fluoroscopy sequence of the open case's
// C-arm views. The user loads a sequence (a view file whose views give "sequence" frames; its views must be the case's,
// by name and detector size), runs the tracker (TrackingWorker on its own thread: frame 0 registered with the default
// schedule from the current result's pose, or the initial pose; every later frame tracked from the previous one) with
// a progress bar and Cancel, then scrubs the frames with a slider: each X-ray view shows that frame with the projected
// bone outline at its tracked pose (ContourOverlay), and a chart plots the six pose parameters against the frame.

#include <QImage>
#include <QString>
#include <QWidget>

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/ContourOverlay.h"
#include "Image/Volume.h"
#include "Tracking/CineTracker.h"
#include "Widgets/TrackingWorker.h"

class QCheckBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QSlider;
class QThread;

namespace fct {

class SliceViewWidget;
class StudioDocument;
class XrayViewWidget;

/// The Track step: sequence loading, the tracking run, the frame slider with outlines, and the pose chart.
class TrackStepWidget : public QWidget {
  Q_OBJECT
 public:
  /// The X-ray layer of this step: the bone outline at the shown frame's tracked pose.
  static inline const QString kTrackLayer = QStringLiteral("track-outline");

  /// A step tracking sequences of `document`'s case.
  explicit TrackStepWidget(StudioDocument* document, QWidget* parent = nullptr);
  /// Cancels a run and waits for its thread.
  ~TrackStepWidget() override;

  /// The views this step draws on (X-ray view i shows document view i); slice views are not used.
  void attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3> sliceViews);
  /// While active the step shows the chosen frame and its outline; inactive it gives the views back the case's X-rays.
  void setActive(bool active);

  /// Reads the sequence of a view file and loads every frame. Fails, with the reason shown too, on a bad view file,
  /// views without "sequence", views other than the case's (names, detector sizes), or a frame that does not load;
  /// the loaded sequence, if any, then stays. Refused while tracking.
  Status loadSequence(const std::filesystem::path& viewFile);
  /// Number of frames of the loaded sequence (0: none).
  int frameCount() const;
  /// The frames tracked by the last run, in order (a cancelled run: those done).
  const std::vector<TrackedFrame>& trackedFrames() const { return m_tracked; }
  /// True while a run is under way.
  bool isRunning() const { return m_thread != nullptr; }
  /// The frame the slider shows.
  int shownFrame() const;
  /// The pose chart as shown (null before a run).
  const QImage& poseChart() const { return m_chart; }
  /// The message line, as shown.
  QString message() const;

 public slots:
  /// Starts tracking the loaded sequence; refused (with a message) without a CT, a sequence, a start pose, or while
  /// running.
  void startTracking();
  /// Asks a run to stop; the frames done so far are kept.
  void cancel();
  /// Shows frame `index` (clamped) in the X-ray views with its outline.
  void showFrame(int index);

 signals:
  /// A run started (true) or ended (false).
  void runningChanged(bool running);
  /// A frame of the run was tracked (trackedFrames() holds it now).
  void frameDone(int index);

 private:
  void onCaseReady(const Eigen::Vector3d& rotationCentre_ct_mm);
  void onFrameTracked(const fct::TrackedFrame& frame);
  void onFinished(int frames, bool cancelled);
  void onFailed(const QString& message);
  /// Quits and deletes the run's thread and worker.
  void endThread();
  /// Redraws the pose chart from the tracked frames.
  void updateChart();
  /// The start pose of a run: the current result's, else the initial pose.
  std::optional<Eigen::Isometry3d> startPose() const;
  /// Builds the outline projector for the document's CT when it changed; false with a message.
  bool ensureOverlay();
  /// Gives the views back the case's X-rays and removes the outline layer.
  void restoreViews();
  void setRunningUi(bool running);
  void showMessage(const QString& text, bool error);

  StudioDocument* m_document;
  std::vector<XrayViewWidget*> m_xrayViews;
  bool m_active = false;

  std::shared_ptr<const TrackingSequence> m_sequence;
  std::vector<TrackedFrame> m_tracked;
  Eigen::Vector3d m_rotationCentre_ct_mm = Eigen::Vector3d::Zero();
  std::shared_ptr<const Volume> m_overlayCt;  ///< CT of m_overlay
  std::optional<ContourOverlay> m_overlay;
  QImage m_chart;
  bool m_sequenceWindowed = false;  ///< the views have the window of a shown frame (else the next one sets it)

  TrackingWorker* m_worker = nullptr;
  QThread* m_thread = nullptr;

  QPushButton* m_loadButton;
  QLabel* m_sequenceLabel;
  QPushButton* m_trackButton;
  QPushButton* m_cancelButton;
  QProgressBar* m_progressBar;
  QSlider* m_frameSlider;
  QLabel* m_frameLabel;
  QCheckBox* m_outlineCheck;
  QLabel* m_chartLabel;
  QLabel* m_message;
};

}  // namespace fct
