#include <gtest/gtest.h>

#include <QMenuBar>
#include <QStatusBar>
#include <QTest>

#include "StudioMainWindow.h"
#include "TestSupport.h"

namespace {

TEST(StudioMainWindow, ShowsTitleMenusDataStepAndReadyStatusOffscreen) {
  fct::StudioMainWindow window(fct::test::scratchDir() / "autosave.json");
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  EXPECT_TRUE(window.windowTitle().contains(QStringLiteral("FluoroCT Studio")));
  EXPECT_FALSE(window.menuBar()->actions().isEmpty());
  EXPECT_EQ(window.statusBar()->currentMessage(), QStringLiteral("Ready"));
  ASSERT_EQ(window.stepCount(), 5);
  EXPECT_EQ(window.stepTitle(0), QStringLiteral("Data"));
  EXPECT_EQ(window.stepTitle(1), QStringLiteral("Initial pose"));
  EXPECT_EQ(window.stepTitle(4), QStringLiteral("Review"));
  EXPECT_TRUE(window.xrayViews().empty());
}

}  // namespace
