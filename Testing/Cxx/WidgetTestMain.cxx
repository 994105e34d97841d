// main() of the widget test program: one QApplication for the whole run (offscreen), then GoogleTest.
#include <gtest/gtest.h>

#include <QApplication>

int main(int argc, char** argv) {
  // Offscreen unless a platform is asked for; xcb (for the OpenGL render tests) only when there is a display.
  const QByteArray platform = qgetenv("QT_QPA_PLATFORM");
  const bool noDisplay = platform == "xcb" && qgetenv("DISPLAY").isEmpty();
  qputenv("QT_QPA_PLATFORM", platform.isEmpty() || noDisplay ? QByteArray("offscreen") : platform);
  QApplication app(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
