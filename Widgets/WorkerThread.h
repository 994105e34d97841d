#pragma once
// WorkerThread: the end of a step's run on its own QThread (RegistrationWorker, TrackingWorker): the thread's event
// loop is quit and joined, then the worker and the thread are deleted and both pointers cleared.

#include <QThread>

namespace fct {

/// Quits and joins `thread` and deletes it and `worker` (both set to null); nothing when there is no thread.
template <typename Worker>
void endWorkerThread(QThread*& thread, Worker*& worker) {
  if (thread == nullptr) return;
  thread->quit();
  thread->wait();
  delete worker;
  delete thread;
  worker = nullptr;
  thread = nullptr;
}

}  // namespace fct
