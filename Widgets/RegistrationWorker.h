#pragma once
// RegistrationWorker: runs Registration::run on its own thread (the widget moves it to a QThread) and reports through
// queued signals: progress at most every kProgressInterval_ms (and at every stage change), then exactly one of
// finished or failed. Cancelling sets an atomic flag that the registration checks before every DRR set; the run then
// finishes with the best pose so far, marked cancelled. No exception leaves run().

#include <Eigen/Geometry>
#include <QObject>
#include <QString>

#include <atomic>
#include <memory>

#include "Registration/Registration.h"

namespace fct {

/// One registration run, executed by run() on the thread the worker lives in.
class RegistrationWorker : public QObject {
  Q_OBJECT
 public:
  /// Shortest time between two progress signals, ms.
  static constexpr int kProgressInterval_ms = 50;

  /// A run of `options` on `registrationCase` from T_initial (CT LPS mm -> world LPS mm). The case is shared: it must
  /// not be used by another thread while the run lasts.
  RegistrationWorker(std::shared_ptr<RegistrationCase> registrationCase, const Eigen::Isometry3d& T_initial,
                     RegistrationOptions options);

  /// Asks the run to stop; thread-safe, returns at once.
  void cancel() { m_cancel.store(true); }

 public slots:
  /// Runs the registration; emits progressed, then finished or failed.
  void run();

 signals:
  /// Live progress (queued to the GUI thread).
  void progressed(const fct::RegistrationProgress& progress);
  /// The run ended (possibly cancelled: result.cancelled).
  void finished(const fct::RegistrationResult& result);
  /// The run could not be done; the message says why.
  void failed(const QString& message);

 private:
  std::shared_ptr<RegistrationCase> m_case;
  Eigen::Isometry3d m_T_initial;
  RegistrationOptions m_options;
  std::atomic<bool> m_cancel{false};
};

}  // namespace fct

Q_DECLARE_METATYPE(fct::RegistrationProgress)
Q_DECLARE_METATYPE(fct::RegistrationResult)
