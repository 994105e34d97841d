#include "Widgets/CasePreparation.h"

#include <QMetaObject>
#include <QtConcurrent/QtConcurrentRun>

#include <exception>

namespace fct {

CasePreparation::CasePreparation(std::shared_ptr<const Volume> ct, std::vector<RegistrationView> views,
                                 RegistrationCaseOptions options, QObject* parent)
    : QObject(parent) {
  connect(&m_watcher, &QFutureWatcherBase::finished, this, &CasePreparation::finished);
  // The worker reports through queued calls on this object, which outlives it (the destructor waits).
  const auto report = [this](const ProgressUpdate& update) {
    const QString step = QString::fromStdString(update.message.empty() ? update.stage : update.message);
    const double fraction = update.fraction;
    QMetaObject::invokeMethod(this, [this, step, fraction] { emit progressed(step, fraction); }, Qt::QueuedConnection);
  };
  m_watcher.setFuture(QtConcurrent::run([ct = std::move(ct), views = std::move(views), options = std::move(options),
                                         cancel = m_cancel, report]() -> Outcome {
    Outcome outcome;
    try {
      auto created = RegistrationCase::create(*ct, views, options, ProgressMonitor(report, cancel.get()));
      if (!created) {
        outcome.error = created.error();
      } else {
        outcome.warnings = created.warnings();
        outcome.prepared = std::make_shared<RegistrationCase>(std::move(created).value());
      }
    } catch (const std::exception& error) {
      outcome.error = std::string("the case preparation stopped on an internal error: ") + error.what();
    } catch (...) {
      outcome.error = "the case preparation stopped on an unknown internal error";
    }
    return outcome;
  }));
}

CasePreparation::~CasePreparation() {
  cancel();
  m_watcher.waitForFinished();
}

CasePreparation::Outcome CasePreparation::wait() {
  m_watcher.waitForFinished();
  Outcome outcome = m_watcher.result();
  if (m_cancel->load() && outcome.prepared) {  // cancelled after the worker's last step: the request still wins
    outcome = Outcome{};
    outcome.error = RegistrationCase::kCancelledError;
  }
  return outcome;
}

}  // namespace fct
