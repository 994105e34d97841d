#include "Widgets/TrackingWorker.h"

#include <exception>

#include "Base/ProgressMonitor.h"

namespace fct {

TrackingWorker::TrackingWorker(std::shared_ptr<const Volume> ct, std::shared_ptr<const TrackingSequence> sequence,
                               const Eigen::Isometry3d& T_start, RegistrationCaseOptions caseOptions,
                               CineTrackerOptions trackerOptions)
    : m_ct(std::move(ct)),
      m_sequence(std::move(sequence)),
      m_T_start(T_start),
      m_caseOptions(std::move(caseOptions)),
      m_trackerOptions(std::move(trackerOptions)) {}

void TrackingWorker::run() {
  try {
    track();
  } catch (const std::exception& error) {
    emit failed(tr("tracking stopped on an internal error: %1").arg(QString::fromUtf8(error.what())));
  } catch (...) {
    emit failed(tr("tracking stopped on an unknown internal error"));
  }
}

void TrackingWorker::track() {
  auto registrationCase =
      RegistrationCase::create(*m_ct, m_sequence->views, m_caseOptions, ProgressMonitor({}, &m_cancel));
  if (!registrationCase) {
    if (m_cancel.load()) {
      emit finished(0, true);
    } else {
      emit failed(QString::fromStdString(registrationCase.error()));
    }
    return;
  }
  emit caseReady(registrationCase.value().rotationCentre_ct_mm());
  auto tracker = CineTracker::create(registrationCase.value(), m_trackerOptions);
  if (!tracker) {
    emit failed(QString::fromStdString(tracker.error()));
    return;
  }
  const auto& frames = m_sequence->frames;
  int done = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    auto frame = f == 0 ? tracker.value().trackFirst(m_T_start, &m_cancel) : tracker.value().trackNext(frames[f], &m_cancel);
    if (!frame) {
      emit failed(tr("frame %1: %2").arg(f).arg(QString::fromStdString(frame.error())));
      return;
    }
    ++done;
    emit frameTracked(frame.value());
    if (frame.value().cancelled || m_cancel.load()) {
      emit finished(done, true);
      return;
    }
  }
  emit finished(done, false);
}

}  // namespace fct
