#pragma once
// CasePreparation: one RegistrationCase::create on a pool thread (QtConcurrent) with its own copies of the inputs,
// so the GUI thread stays responsive while a large CT and its X-rays are prepared. Progress comes back as queued
// signals; cancel() stops it at the next preparation step; no exception leaves the worker (it becomes the error).
// The destructor cancels and waits, so a preparation never outlives its owner.

#include <QFutureWatcher>
#include <QObject>
#include <QString>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "Image/Volume.h"
#include "Registration/RegistrationCase.h"

namespace fct {

/// A registration case being prepared on a worker thread.
class CasePreparation : public QObject {
  Q_OBJECT
 public:
  /// What a preparation produced: the case, or the error in words; the warnings of RegistrationCase::create.
  struct Outcome {
    std::shared_ptr<RegistrationCase> prepared;
    std::string error;
    std::vector<std::string> warnings;
  };

  /// Starts preparing the case of `ct` and `views` with `options` at once.
  CasePreparation(std::shared_ptr<const Volume> ct, std::vector<RegistrationView> views,
                  RegistrationCaseOptions options, QObject* parent = nullptr);
  /// Cancels and waits for the worker.
  ~CasePreparation() override;

  /// Asks the worker to stop at its next step (it then ends with a "cancelled" error); returns at once.
  void cancel() { m_cancel->store(true); }
  /// Blocks until the worker is done and returns its outcome; after cancel() it is always the "cancelled" error, even
  /// when the worker had finished its last step before it saw the request.
  Outcome wait();

 signals:
  /// A preparation step started: what it does in words and the fraction done (0..1).
  void progressed(const QString& step, double fraction);
  /// The worker is done: wait() returns at once now.
  void finished();

 private:
  std::shared_ptr<std::atomic<bool>> m_cancel = std::make_shared<std::atomic<bool>>(false);
  QFutureWatcher<Outcome> m_watcher;
};

}  // namespace fct
