#include "Base/ProgressMonitor.h"

#include <algorithm>

namespace fct {

ProgressMonitor::ProgressMonitor(Callback callback, const std::atomic<bool>* cancelFlag)
    : m_callback(std::move(callback)), m_cancelFlag(cancelFlag) {}

void ProgressMonitor::report(const std::string& stage, double fraction, const std::string& message) const {
  if (m_callback) m_callback(ProgressUpdate{stage, std::clamp(fraction, 0.0, 1.0), message});
}

}  // namespace fct
