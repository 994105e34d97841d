#include <gtest/gtest.h>

#include <QMenuBar>
#include <QStatusBar>
#include <QTest>

#include "MainWindow.h"

TEST(MainWindow, ShowsTitleMenuAndReadyStatusOffscreen) {
  fct::MainWindow window;
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  EXPECT_EQ(window.windowTitle(), QStringLiteral("FluoroCT Studio"));
  EXPECT_FALSE(window.menuBar()->actions().isEmpty());
  EXPECT_EQ(window.statusBar()->currentMessage(), QStringLiteral("Ready"));
}
