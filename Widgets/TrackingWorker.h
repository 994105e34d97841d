#pragma once
// TrackingWorker: runs a CineTracker over a loaded fluoroscopy sequence on its own thread (the Track step moves it to
// a QThread): prepares a RegistrationCase on frame 0's images (the CT, its renderers and bone surface once), registers
// frame 0 from the start pose, then tracks every later frame, and reports through queued signals: one frameTracked
// per frame, in order, then exactly one of finished or failed. Cancelling sets an atomic flag that the preparation and
// the tracker check; the run then finishes with the frames done so far (the last one marked cancelled). No exception
// leaves run().

#include <Eigen/Geometry>
#include <QObject>
#include <QString>

#include <atomic>
#include <memory>
#include <vector>

#include "Image/Volume.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationView.h"
#include "Tracking/CineTracker.h"

namespace fct {

/// A fluoroscopy sequence in memory: frames[f][v] is frame f of view v (every frame has one image per view).
struct TrackingSequence {
  std::vector<RegistrationView> views;             ///< the views (names, cameras, spheres) with frame 0's images
  std::vector<std::vector<XrayImage>> frames;      ///< frames[f][v], f = 0 .. frameCount-1 (frame 0 included)
};

/// One tracking run, executed by run() on the thread the worker lives in.
class TrackingWorker : public QObject {
  Q_OBJECT
 public:
  /// A run over `sequence` of `ct` from T_start (CT LPS mm -> world LPS mm) with the case and tracker options.
  TrackingWorker(std::shared_ptr<const Volume> ct, std::shared_ptr<const TrackingSequence> sequence,
                 const Eigen::Isometry3d& T_start, RegistrationCaseOptions caseOptions,
                 CineTrackerOptions trackerOptions);

  /// Asks the run to stop; thread-safe, returns at once.
  void cancel() { m_cancel.store(true); }

 public slots:
  /// Prepares the case and tracks every frame; emits caseReady, frameTracked per frame, then finished or failed.
  void run();

 signals:
  /// The case is prepared: the rotation centre (CT LPS mm) the pose parameters are taken about.
  void caseReady(const Eigen::Vector3d& rotationCentre_ct_mm);
  /// A frame is done (queued to the GUI thread).
  void frameTracked(const fct::TrackedFrame& frame);
  /// The run ended after `frames` frames; `cancelled` when the cancel flag stopped it early.
  void finished(int frames, bool cancelled);
  /// The run could not go on; the message says why (frames reported so far stay valid).
  void failed(const QString& message);

 private:
  /// The run without the exception guard.
  void track();

  std::shared_ptr<const Volume> m_ct;
  std::shared_ptr<const TrackingSequence> m_sequence;
  Eigen::Isometry3d m_T_start;
  RegistrationCaseOptions m_caseOptions;
  CineTrackerOptions m_trackerOptions;
  std::atomic<bool> m_cancel{false};
};

}  // namespace fct

Q_DECLARE_METATYPE(fct::TrackedFrame)
