#pragma once
// ProgressMonitor: how a long Logic operation reports progress and learns that the user cancelled.
// Callers (CLI progress bar, GUI worker thread) pass one in; the operation calls report() and checks cancelled().

#include <atomic>
#include <functional>
#include <string>

namespace fct {

/// One progress report: which stage, how far (0..1), and a short human-readable message.
struct ProgressUpdate {
  std::string stage;
  double fraction = 0.0;
  std::string message;
};

/// Forwards progress reports to an optional callback and exposes an optional shared cancel flag.
class ProgressMonitor {
 public:
  using Callback = std::function<void(const ProgressUpdate&)>;

  /// A monitor that reports nowhere and is never cancelled.
  ProgressMonitor() = default;
  /// A monitor with a callback (may be empty) and a cancel flag owned by the caller (may be null).
  ProgressMonitor(Callback callback, const std::atomic<bool>* cancelFlag);

  /// Sends a report to the callback, if any. Thread-safe only if the callback is.
  void report(const std::string& stage, double fraction, const std::string& message = {}) const;
  /// True once the caller has set the cancel flag.
  bool cancelled() const { return m_cancelFlag && m_cancelFlag->load(std::memory_order_relaxed); }

 private:
  Callback m_callback;
  const std::atomic<bool>* m_cancelFlag = nullptr;
};

}  // namespace fct
