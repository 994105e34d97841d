// Studio soak test: 600 random user actions with a fixed seed on the whole window (switching steps, clicks, drags and
// wheel turns on every view, loading good and bad files, starting and cancelling registrations, saving and reopening
// sessions), offscreen. Passes when nothing crashed, no exception reached the event loop and no worker is left.
// Any question box is answered by the test (Discard / No / Cancel, never a file dialog).
#include <gtest/gtest.h>

#include <QApplication>
#include <QStandardPaths>
#include <QTest>
#include <QThreadPool>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "DialogAnswerer.h"
#include "EventLoopExceptions.h"
#include "StepTestSession.h"
#include "StudioTestCase.h"
#include "TestSupport.h"
#include "Widgets/DataStepWidget.h"
#include "Widgets/RegisterStepWidget.h"
#include "Widgets/SliceViewWidget.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/StudioMainWindow.h"
#include "Widgets/XrayViewWidget.h"

namespace {

namespace fs = std::filesystem;

QString qs(const fs::path& path) { return QString::fromStdString(path.string()); }

/// Files a user might open by mistake: garbage, a truncated CT, a broken view file, an empty folder.
struct BadInputs {
  fs::path garbageCt, truncatedCt, brokenViews, emptyFolder, missing, brokenSession;
};

BadInputs makeBadInputs(const fs::path& dir, const fs::path& caseDir) {
  BadInputs bad{dir / "garbage.nrrd",     dir / "truncated.nrrd", dir / "broken_views.json",
                dir / "empty_case",       dir / "missing.nrrd",   dir / "broken.fctsession.json"};
  std::ofstream(bad.garbageCt) << "NRRD0004\nsizes: 9999999 2\ntype: float\n\nnot voxels";
  const std::string ct = fct::test::readText(caseDir / "ct.nrrd");
  std::ofstream(bad.truncatedCt, std::ios::binary) << ct.substr(0, ct.size() / 2);
  std::ofstream(bad.brokenViews) << R"({"views": [{"name": "AP", "image": "nope.png"}]})";
  fs::create_directories(bad.emptyFolder);
  std::ofstream(bad.brokenSession) << R"({"format": "fluoroct-session", "version": 1, "ct": )";
  return bad;
}

/// A point inside `widget`, uniformly at random.
QPoint randomPoint(QWidget* widget, std::mt19937& random) {
  std::uniform_int_distribution<int> x(0, std::max(0, widget->width() - 1));
  std::uniform_int_distribution<int> y(0, std::max(0, widget->height() - 1));
  return QPoint(x(random), y(random));
}

/// A click, a drag (with any button) or a wheel turn at random points of `view`.
void mouseAction(QWidget* view, std::mt19937& random) {
  const QPoint from = randomPoint(view, random);
  const Qt::MouseButton buttons[] = {Qt::LeftButton, Qt::RightButton, Qt::MiddleButton};
  const Qt::MouseButton button = buttons[random() % 3];
  const Qt::KeyboardModifiers modifiers = random() % 4 == 0 ? Qt::ShiftModifier : Qt::NoModifier;
  switch (random() % 3) {
    case 0:
      QTest::mouseClick(view, button, modifiers, from);
      break;
    case 1: {
      QTest::mousePress(view, button, modifiers, from);
      for (int i = 0; i < 3; ++i) QTest::mouseMove(view, randomPoint(view, random));
      QTest::mouseRelease(view, button, modifiers, randomPoint(view, random));
      break;
    }
    default: {
      QWheelEvent wheel(QPointF(from), QPointF(view->mapToGlobal(from)), QPoint(), QPoint(0, random() % 2 ? 120 : -120),
                        Qt::NoButton, modifiers, Qt::NoScrollPhase, false);
      QApplication::sendEvent(view, &wheel);
      break;
    }
  }
}

}  // namespace

TEST(StudioSoak, SixHundredRandomActionsWithoutACrashAnEscapedExceptionOrALeftWorker) {
  QStandardPaths::setTestModeEnabled(true);
  const fs::path caseDir = fct::test::builtinCaseDir();
  ASSERT_FALSE(caseDir.empty());
  const fs::path dir = fct::test::scratchDir();
  const BadInputs bad = makeBadInputs(dir, caseDir);
  const int exceptionsBefore = fct::test::eventLoopExceptionCount();
  const fct::test::DialogAnswerer answerer;

  std::mt19937 random(20261201);
  int actions = 0, loads = 0, runs = 0, cancels = 0, saves = 0, reopens = 0;
  {
    fct::StudioMainWindow window(dir / "autosave.fctsession.json");
    window.resize(1400, 900);
    window.show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
    fct::DataStepWidget* data = window.dataStep();
    auto* registration = window.findChild<fct::RegisterStepWidget*>();
    ASSERT_NE(registration, nullptr);
    const auto waitForLoad = [&] { ASSERT_TRUE(fct::test::waitUntil([&] { return !data->isBusy(); }, 60000)); };
    data->openCaseFolder(qs(caseDir));
    waitForLoad();

    for (; actions < 600; ++actions) {
      const unsigned kind = random() % 20;
      if (kind < 3) {
        window.showStep(static_cast<int>(random() % static_cast<unsigned>(window.stepCount())));
      } else if (kind < 7 && !window.xrayViews().empty()) {
        mouseAction(window.xrayViews()[random() % window.xrayViews().size()], random);
      } else if (kind < 10) {
        mouseAction(window.sliceViews()[random() % 3], random);
      } else if (kind == 10) {
        data->openCaseFolder(qs(caseDir));
        ++loads;
      } else if (kind == 11) {
        const fs::path files[] = {bad.garbageCt, bad.truncatedCt, bad.missing};
        data->openCt(qs(files[random() % 3]));
        ++loads;
      } else if (kind == 12) {
        if (random() % 2) {
          data->openViewFile(qs(bad.brokenViews));
        } else {
          data->openCaseFolder(qs(bad.emptyFolder));
        }
        ++loads;
      } else if (kind == 13 || kind == 14) {
        fct::StudioRegistrationOptions options = window.document()->registrationOptions();
        options.preset = random() % 3 == 0 ? "paper" : "fast";
        window.document()->setRegistrationOptions(options);
        if (registration->run()) ++runs;
      } else if (kind == 15) {
        registration->cancel();
        ++cancels;
      } else if (kind == 16) {
        if (window.saveSessionTo(qs(dir / "soak.fctsession.json"))) ++saves;
      } else if (kind == 17) {
        const bool good = random() % 3 != 0 && fs::exists(dir / "soak.fctsession.json");
        if (window.openSession(qs(good ? dir / "soak.fctsession.json" : bad.brokenSession))) ++reopens;
      } else {
        QTest::qWait(static_cast<int>(random() % 40));  // let a load or a run go on
      }
      QApplication::processEvents();
      if (data->isBusy() && random() % 2) waitForLoad();
    }
    registration->cancel();
    ASSERT_TRUE(fct::test::waitUntil([&] { return !registration->isRunning() && !data->isBusy(); }, 120000))
        << "a registration or a load did not end after the soak";
    std::printf("soak: %d actions, %d loads, %d registrations started, %d cancels, %d sessions saved, %d reopened, "
                "%d questions answered\n",
                actions, loads, runs, cancels, saves, reopens, answerer.answered());
  }
  EXPECT_EQ(actions, 600);
  EXPECT_GT(runs, 0);
  EXPECT_GT(saves, 0);
  EXPECT_GT(reopens, 0);
  EXPECT_EQ(fct::test::eventLoopExceptionCount(), exceptionsBefore);
  EXPECT_TRUE(QThreadPool::globalInstance()->waitForDone(60000)) << "a background load is still running";
  EXPECT_EQ(QThreadPool::globalInstance()->activeThreadCount(), 0);
}
