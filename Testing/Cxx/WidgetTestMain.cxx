// main() of the widget test program: one QApplication for the whole run (offscreen), then GoogleTest.
#include <gtest/gtest.h>

#include <QApplication>

#include <cstdio>
#include <exception>

#include "EventLoopExceptions.h"

namespace {

int g_eventLoopExceptions = 0;

/// Counts and prints an exception that would cross the event loop instead of letting it end the program.
class ExceptionCountingApplication : public QApplication {
 public:
  using QApplication::QApplication;
  bool notify(QObject* receiver, QEvent* event) override {
    try {
      return QApplication::notify(receiver, event);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "exception across the event loop: %s\n", e.what());
    } catch (...) {
      std::fprintf(stderr, "exception across the event loop (not a std::exception)\n");
    }
    ++g_eventLoopExceptions;
    return false;
  }
};

}  // namespace

int fct::test::eventLoopExceptionCount() { return g_eventLoopExceptions; }

int main(int argc, char** argv) {
  // Offscreen unless a platform is asked for; xcb (for the OpenGL render tests) only when there is a display.
  const QByteArray platform = qgetenv("QT_QPA_PLATFORM");
  const bool noDisplay = platform == "xcb" && qgetenv("DISPLAY").isEmpty();
  qputenv("QT_QPA_PLATFORM", platform.isEmpty() || noDisplay ? QByteArray("offscreen") : platform);
  ExceptionCountingApplication app(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
