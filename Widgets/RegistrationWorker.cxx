#include "Widgets/RegistrationWorker.h"

#include <chrono>
#include <exception>

namespace fct {

RegistrationWorker::RegistrationWorker(std::shared_ptr<RegistrationCase> registrationCase,
                                       const Eigen::Isometry3d& T_initial, RegistrationOptions options)
    : m_case(std::move(registrationCase)), m_T_initial(T_initial), m_options(std::move(options)) {}

void RegistrationWorker::run() {
  using Clock = std::chrono::steady_clock;
  Clock::time_point lastReport{};
  int lastStage = -1;
  const auto onProgress = [&](const RegistrationProgress& progress) {
    const Clock::time_point now = Clock::now();
    if (progress.stageIndex == lastStage && now - lastReport < std::chrono::milliseconds(kProgressInterval_ms)) return;
    lastStage = progress.stageIndex;
    lastReport = now;
    emit progressed(progress);
  };
  try {
    auto result = Registration::run(*m_case, m_T_initial, m_options, onProgress, &m_cancel);
    if (!result) {
      emit failed(QString::fromStdString(result.error()));
      return;
    }
    emit finished(result.value());
  } catch (const std::exception& error) {
    emit failed(tr("the registration stopped on an internal error: %1").arg(QString::fromUtf8(error.what())));
  } catch (...) {
    emit failed(tr("the registration stopped on an unknown internal error"));
  }
}

}  // namespace fct
