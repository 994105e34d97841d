#include <gtest/gtest.h>

#include <QAbstractButton>
#include <QComboBox>
#include <QTableWidget>
#include <QApplication>
#include <QMenuBar>
#include <QMessageBox>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTest>
#include <QTimer>

#include <algorithm>
#include <fstream>

#include "StudioTestCase.h"
#include "TestSupport.h"
#include "Widgets/DataStepWidget.h"
#include "Widgets/LandmarkStepWidget.h"
#include "Widgets/RegisterStepWidget.h"
#include "Widgets/ReviewStepWidget.h"
#include "Widgets/SessionAutosave.h"
#include "Widgets/SliceViewWidget.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/StudioMainWindow.h"
#include "Widgets/XrayViewWidget.h"

namespace {

using fct::StudioMainWindow;

/// Opens the built-in case through the Data step and waits for it.
void openBuiltinCase(StudioMainWindow& window) {
  QSignalSpy finished(window.dataStep(), &fct::DataStepWidget::loadFinished);
  window.dataStep()->openCaseFolder(QString::fromStdString(fct::test::builtinCaseDir().string()));
  ASSERT_TRUE(finished.wait(20000));
  ASSERT_TRUE(finished.at(0).at(0).toBool()) << finished.at(0).at(1).toString().toStdString();
}

/// Answers the next modal message box with `button` (from the event loop, while it is open).
void answerNextMessageBox(QMessageBox::StandardButton button, QString* text = nullptr) {
  QTimer::singleShot(0, [button, text] {
    auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
    if (!box) return;
    if (text) *text = box->text();
    box->button(button)->click();
  });
}

/// A step with the hooks the main window calls.
class CountingStep : public QWidget {
 public:
  void setActive(bool active) { active ? ++activations : ++deactivations; }
  void attachViews(const std::vector<fct::XrayViewWidget*>& xrays, const std::array<fct::SliceViewWidget*, 3>& slices) {
    lastXrayCount = static_cast<int>(xrays.size());
    slicesAttached = slices[0] != nullptr;
    ++attachments;
  }
  int activations = 0, deactivations = 0, attachments = 0, lastXrayCount = -1;
  bool slicesAttached = false;
};

class StudioMainWindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    QStandardPaths::setTestModeEnabled(true);  // recent sessions go to a test settings file
    ASSERT_FALSE(fct::test::builtinCaseDir().empty());
    m_folder = fct::test::scratchDir();
  }
  std::filesystem::path m_folder;
};

TEST_F(StudioMainWindowTest, ShowsTitleMenusDataStepAndReadyStatus) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  EXPECT_TRUE(window.windowTitle().contains(QStringLiteral("FluoroCT Studio")));
  EXPECT_FALSE(window.menuBar()->actions().isEmpty());
  EXPECT_EQ(window.statusBar()->currentMessage(), QStringLiteral("Ready"));
  ASSERT_EQ(window.stepCount(), 6);
  EXPECT_EQ(window.stepTitle(0), QStringLiteral("Data"));
  EXPECT_EQ(window.stepTitle(1), QStringLiteral("Initial pose"));
  EXPECT_EQ(window.stepTitle(4), QStringLiteral("Review"));
  EXPECT_EQ(window.stepTitle(5), QStringLiteral("Track"));
  EXPECT_TRUE(window.xrayViews().empty());
}

TEST_F(StudioMainWindowTest, StepsAddedByOneLineGetTheViewsAndActivation) {
  StudioMainWindow window(m_folder / "autosave.json");
  const int builtinSteps = window.stepCount();
  auto* step = window.addStep(QStringLiteral("Counting step"), new CountingStep);
  EXPECT_EQ(window.stepCount(), builtinSteps + 1);
  EXPECT_EQ(step->attachments, 1);
  EXPECT_TRUE(step->slicesAttached);
  EXPECT_TRUE(window.showStepNamed(QStringLiteral("counting-step")));
  EXPECT_EQ(window.currentStep(), builtinSteps);
  EXPECT_EQ(step->activations, 1);
  window.showStep(0);
  EXPECT_EQ(step->deactivations, 1);
  EXPECT_FALSE(window.showStepNamed(QStringLiteral("nope")));
  openBuiltinCase(window);
  EXPECT_EQ(step->lastXrayCount, 2);
}

TEST_F(StudioMainWindowTest, LoadsTheCaseIntoTheViewsAndLinksTheCrosshair) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.resize(1400, 900);
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  openBuiltinCase(window);
  ASSERT_EQ(window.xrayViews().size(), 2u);
  EXPECT_EQ(window.xrayViews()[1]->title(), QStringLiteral("lateral"));
  EXPECT_EQ(window.xrayViews()[0]->imageSize(), QSize(192, 144));
  for (fct::SliceViewWidget* slice : window.sliceViews()) EXPECT_TRUE(slice->hasImage());

  fct::SliceViewWidget* axial = window.sliceViews()[0];
  const Eigen::Vector3d target(12.0, -20.0, axial->slicePosition_mm());
  QTest::mouseClick(axial, Qt::LeftButton, Qt::NoModifier, axial->widgetPointForCtPoint(target));
  const Eigen::Vector3d coronal = window.sliceViews()[1]->crosshair_ct_mm();
  EXPECT_LT((coronal - target).norm(), 1.0) << coronal.transpose();
  EXPECT_NEAR(window.sliceViews()[2]->slicePosition_mm(), -coronal.x(), 1e-9);  // sagittal normal = -x (R)
  EXPECT_TRUE(window.isWindowModified());
}

TEST_F(StudioMainWindowTest, SliceTitleAndReadoutGiveTheSamePatientSideInLps) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.resize(1400, 900);
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  openBuiltinCase(window);
  fct::SliceViewWidget* axial = window.sliceViews()[0];
  fct::SliceViewWidget* sagittal = window.sliceViews()[2];
  // Click on the patient's right (LPS x < 0) in the axial view: the sagittal slice moves there.
  const Eigen::Vector3d right(-20.0, 5.0, axial->slicePosition_mm());
  QTest::mouseClick(axial, Qt::LeftButton, Qt::NoModifier, axial->widgetPointForCtPoint(right));
  const double x = sagittal->crosshair_ct_mm().x();
  ASSERT_LT(x, -15.0);
  const QString side = fct::SliceViewWidget::sideCoordinate(0, x);
  EXPECT_TRUE(side.startsWith(QStringLiteral("R "))) << side.toStdString();
  EXPECT_TRUE(sagittal->title().contains(side + QStringLiteral(" mm (LPS x -"))) << sagittal->title().toStdString();
  // Hovering the sagittal view at the crosshair reads the same side and the same LPS x.
  QTest::mouseMove(sagittal, sagittal->widgetPointForCtPoint(sagittal->crosshair_ct_mm()));
  const QString readout = window.hoverText();
  EXPECT_TRUE(readout.startsWith(QStringLiteral("Sagittal: LPS (") + QString::number(x, 'f', 1)))
      << readout.toStdString();
  EXPECT_TRUE(readout.contains(QStringLiteral("= ") + side)) << readout.toStdString();
  EXPECT_EQ(fct::SliceViewWidget::sideCoordinate(1, -12.34), QStringLiteral("A 12.3"));
  EXPECT_EQ(fct::SliceViewWidget::sideCoordinate(2, -0.01), QStringLiteral("S 0.0")) << "no signed zero";
}

TEST_F(StudioMainWindowTest, XraysOpenAtAReadableWindowAndTheUsersWindowIsSavedInTheSession) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.resize(1400, 900);
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  openBuiltinCase(window);
  ASSERT_EQ(window.xrayViews().size(), 2u);
  for (fct::XrayViewWidget* view : window.xrayViews()) {
    // The built-in X-rays are 16-bit with a bright direct exposure; the window covers the patient only.
    const auto& pixels = view->image().pixels;
    const double range = fct::ImageViewWidget::quantile(pixels, 0.99) - fct::ImageViewWidget::quantile(pixels, 0.01);
    EXPECT_LT(view->window(), 0.5 * range) << view->title().toStdString();
    EXPECT_LT(view->level() + 0.5 * view->window(), fct::ImageViewWidget::quantile(pixels, 0.9));
  }
  EXPECT_TRUE(window.document()->xrayWindows().empty()) << "the automatic window is not a user setting";

  // Ctrl-drag sets the window; it is saved and comes back with the session.
  fct::XrayViewWidget* ap = window.xrayViews()[0];
  QTest::mousePress(ap, Qt::LeftButton, Qt::ControlModifier, QPoint(100, 100));
  QTest::mouseMove(ap, QPoint(160, 80));
  QTest::mouseRelease(ap, Qt::LeftButton, Qt::ControlModifier, QPoint(160, 80));
  const double userWindow = ap->window();
  const double userLevel = ap->level();
  ASSERT_EQ(window.document()->xrayWindows().count("ap"), 1u);
  const QString path = QString::fromStdString((m_folder / "window.fctsession.json").string());
  ASSERT_TRUE(window.saveSessionTo(path));
  ASSERT_TRUE(window.newSession());
  ASSERT_TRUE(window.openSession(path)) << window.lastMessage().toStdString();
  ASSERT_EQ(window.xrayViews().size(), 2u);
  EXPECT_DOUBLE_EQ(window.xrayViews()[0]->window(), userWindow);
  EXPECT_DOUBLE_EQ(window.xrayViews()[0]->level(), userLevel);
  EXPECT_FALSE(window.document()->isModified());
}

TEST_F(StudioMainWindowTest, TheViewMenusXrayPresetsSetEveryXrayViewsWindow) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.resize(1400, 900);
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  openBuiltinCase(window);
  ASSERT_EQ(window.xrayViews().size(), 2u);
  const auto trigger = [&](fct::XrayWindowPreset preset) {
    const QString text = QStringLiteral("X-ray window: %1").arg(fct::XrayViewWidget::presetName(preset));
    for (QAction* menu : window.menuBar()->actions()) {
      if (!menu->menu()) continue;
      for (QAction* action : menu->menu()->actions()) {
        if (action->text() == text) {
          action->trigger();
          return true;
        }
      }
    }
    return false;
  };
  std::vector<double> automatic;
  for (fct::XrayViewWidget* view : window.xrayViews()) automatic.push_back(view->window());
  ASSERT_TRUE(trigger(fct::XrayWindowPreset::FullRange)) << "View > X-ray window: Full range";
  std::vector<double> full;
  for (fct::XrayViewWidget* view : window.xrayViews()) {
    const auto [low, high] = std::minmax_element(view->image().pixels.begin(), view->image().pixels.end());
    EXPECT_LE(view->window(), *high - *low + 1e-6) << "no wider than the image's range";
    full.push_back(view->window());
  }
  ASSERT_TRUE(trigger(fct::XrayWindowPreset::WholeField));
  for (std::size_t v = 0; v < window.xrayViews().size(); ++v) {
    const double field = window.xrayViews()[v]->window();
    EXPECT_LT(field, full[v]) << "the 1st-99th percentile is narrower than the full range, view " << v;
    EXPECT_GT(field, automatic[v]) << "and wider than the patient's window (the direct exposure is bright)";
  }
  EXPECT_EQ(window.document()->xrayWindows().size(), window.xrayViews().size()) << "a preset is saved per view";
  ASSERT_TRUE(trigger(fct::XrayWindowPreset::Automatic));
  for (std::size_t v = 0; v < window.xrayViews().size(); ++v) {
    EXPECT_DOUBLE_EQ(window.xrayViews()[v]->window(), automatic[v]) << "back to the window it opened at";
  }
}

TEST_F(StudioMainWindowTest, ReopeningASessionRestoresResidualsProjectedLandmarksAndTheRegisterState) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.resize(1400, 900);
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  openBuiltinCase(window);
  fct::StudioDocument& document = *window.document();
  ASSERT_TRUE(document.truthPose());
  // Five landmarks spread over the phantom, clicked at their true projections in both views.
  fct::Landmarks landmarks;
  const Eigen::Vector3d centre = document.ct()->centre_lps_mm();
  const std::vector<Eigen::Vector3d> offsets{{-20, -10, -15}, {20, -10, -10}, {0, 15, 0}, {-10, 5, 20}, {15, 10, 15}};
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    const std::string name = "L" + std::to_string(i + 1);
    landmarks.ct.push_back({name, centre + offsets[i]});
    for (const fct::RegistrationView& view : document.views()) {
      landmarks.imageByView[view.name].push_back({name, view.camera.project(*document.truthPose() * (centre + offsets[i]))});
    }
  }
  document.setLandmarks(landmarks);
  auto* landmarkStep = window.findChild<fct::LandmarkStepWidget*>();
  auto* registerStep = window.findChild<fct::RegisterStepWidget*>();
  ASSERT_TRUE(landmarkStep && registerStep);
  ASSERT_TRUE(landmarkStep->computePose()) << landmarkStep->message().toStdString();
  fct::RegistrationResult result;
  result.T_initial = *document.initialPose();
  result.T_world_from_ct = *document.truthPose();
  result.schedule = fct::RegistrationSchedule::builtin("fast").value();
  result.totalDrrs = 321;
  fct::StageReport stage;
  stage.name = "vlnc-rois-1:1";
  result.stages.push_back(stage);
  document.addResult(result);
  const QString path = QString::fromStdString((m_folder / "restored.fctsession.json").string());
  ASSERT_TRUE(window.saveSessionTo(path));
  ASSERT_TRUE(window.newSession());
  EXPECT_EQ(registerStep->progressText(), QStringLiteral("Not started"));

  ASSERT_TRUE(window.openSession(path)) << window.lastMessage().toStdString();
  ASSERT_TRUE(landmarkStep->estimate().has_value()) << "the landmark estimate is made again";
  EXPECT_TRUE(landmarkStep->table()->item(0, 3)->text().endsWith(QStringLiteral(" px")));
  window.showStepNamed(QStringLiteral("initial-pose"));
  for (fct::XrayViewWidget* view : window.xrayViews()) {
    EXPECT_EQ(view->layerPoints(fct::LandmarkStepWidget::kProjectedLayer).size(), offsets.size());
  }
  EXPECT_EQ(registerStep->progressText(), QStringLiteral("Finished"));
  EXPECT_TRUE(registerStep->logText().contains(QStringLiteral("Result 1 of 1"))) << registerStep->logText().toStdString();
  EXPECT_TRUE(registerStep->logText().contains(QStringLiteral("Final (full resolution)")));
  EXPECT_EQ(document.result()->totalDrrs, 321);
}

TEST_F(StudioMainWindowTest, AutosaveAppearsAfterAChangeAndIsRestoredAfterACrash) {
  const auto autosave = m_folder / "autosave.json";
  {
    StudioMainWindow crashed(autosave);
    openBuiltinCase(crashed);
    EXPECT_TRUE(std::filesystem::exists(autosave));
    crashed.document()->setRegistrationOptions({"paper", 99, "siddon"});
    // Destroyed without closing, as after a crash: the side file stays.
  }
  ASSERT_TRUE(std::filesystem::exists(autosave));
  StudioMainWindow next(autosave);
  EXPECT_TRUE(next.autosave()->exists());
  ASSERT_TRUE(next.restoreAutosave()) << next.lastMessage().toStdString();
  EXPECT_EQ(next.document()->views().size(), 2u);
  EXPECT_EQ(next.document()->registrationOptions().seed, 99u);
  EXPECT_TRUE(next.document()->isModified());
  EXPECT_EQ(next.xrayViews().size(), 2u);
}

TEST_F(StudioMainWindowTest, OfferedAutosaveCanBeDiscarded) {
  const auto autosave = m_folder / "autosave.json";
  {
    StudioMainWindow crashed(autosave);
    crashed.document()->setRegistrationOptions({"paper", 3, "siddon"});
  }
  ASSERT_TRUE(std::filesystem::exists(autosave));
  StudioMainWindow next(autosave);
  QString question;
  answerNextMessageBox(QMessageBox::Discard, &question);
  next.offerAutosave();
  EXPECT_TRUE(question.contains(QStringLiteral("did not close normally"))) << question.toStdString();
  EXPECT_FALSE(std::filesystem::exists(autosave));
  EXPECT_FALSE(next.document()->isModified());
}

TEST_F(StudioMainWindowTest, CloseAsksAboutUnsavedChangesAndCancelKeepsEverything) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  window.document()->setRegistrationOptions({"paper", 5, "siddon"});
  QString question;
  answerNextMessageBox(QMessageBox::Cancel, &question);
  EXPECT_FALSE(window.close());
  EXPECT_TRUE(question.contains(QStringLiteral("unsaved changes"))) << question.toStdString();
  EXPECT_TRUE(question.contains(QStringLiteral("It holds nothing yet"))) << "says what is unsaved: " << question.toStdString();
  EXPECT_TRUE(window.isVisible());
  EXPECT_EQ(window.document()->registrationOptions().seed, 5u);
  EXPECT_TRUE(std::filesystem::exists(m_folder / "autosave.json"));
}

TEST_F(StudioMainWindowTest, SaveNewAndReopenThroughTheWindowWithRecentSessions) {
  StudioMainWindow window(m_folder / "autosave.json");
  openBuiltinCase(window);
  const QString path = QString::fromStdString((m_folder / "mine.fctsession.json").string());
  ASSERT_TRUE(window.saveSessionTo(path)) << window.lastMessage().toStdString();
  EXPECT_FALSE(window.document()->isModified());
  EXPECT_FALSE(std::filesystem::exists(m_folder / "autosave.json"));  // saved: nothing to restore
  ASSERT_FALSE(window.recentSessions().isEmpty());
  EXPECT_EQ(window.recentSessions().front(), path);
  EXPECT_TRUE(window.windowTitle().contains(QStringLiteral("mine.fctsession.json")));

  ASSERT_TRUE(window.newSession());
  EXPECT_TRUE(window.document()->views().empty());
  EXPECT_TRUE(window.xrayViews().empty());
  ASSERT_TRUE(window.openSession(path)) << window.lastMessage().toStdString();
  EXPECT_EQ(window.document()->views().size(), 2u);
  EXPECT_TRUE(window.document()->initialPose().has_value());
  EXPECT_FALSE(window.document()->isModified());
}

TEST_F(StudioMainWindowTest, BadSessionShowsAMessageAndKeepsTheSession) {
  StudioMainWindow window(m_folder / "autosave.json");
  openBuiltinCase(window);
  ASSERT_TRUE(window.saveSessionTo(QString::fromStdString((m_folder / "good.fctsession.json").string())));
  std::ofstream(m_folder / "bad.fctsession.json") << "{ \"format\": \"fluoroct-studio-session\", \"version\": 1, ";
  EXPECT_FALSE(window.openSession(QString::fromStdString((m_folder / "bad.fctsession.json").string())));
  EXPECT_TRUE(window.lastMessage().startsWith(QStringLiteral("Could not open the session"))) << window.lastMessage().toStdString();
  EXPECT_TRUE(window.lastMessage().contains(QStringLiteral("bad.fctsession.json")));
  EXPECT_EQ(window.document()->views().size(), 2u);
  EXPECT_EQ(window.document()->sessionPath(), m_folder / "good.fctsession.json");
}

TEST_F(StudioMainWindowTest, ACaseSwapAsksFirstThenDropsTheOldResultVerdictAndLandmarks) {
  StudioMainWindow window(m_folder / "autosave.json");
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  openBuiltinCase(window);
  fct::StudioDocument& document = *window.document();
  fct::Landmarks landmarks;
  landmarks.ct = {{"L1", {1.0, 2.0, 3.0}}};
  landmarks.imageByView["ap"] = {{"L1", {50.0, 60.0}}};
  document.setLandmarks(landmarks);
  fct::RegistrationResult result;
  result.T_initial = *document.initialPose();
  result.T_world_from_ct = result.T_initial;
  document.addResult(result);
  auto* review = window.findChild<fct::ReviewStepWidget*>();
  ASSERT_NE(review, nullptr);
  window.showStepNamed(QStringLiteral("review"));
  review->acceptResult();
  ASSERT_EQ(document.resultVerdict(), fct::ResultVerdict::Accepted);

  // A second case (a copy of the built-in one): unsaved work is not dropped without asking; Cancel keeps it all.
  const auto second = m_folder / "second_case";
  std::filesystem::copy(fct::test::builtinCaseDir(), second, std::filesystem::copy_options::recursive);
  QString question;
  answerNextMessageBox(QMessageBox::Cancel, &question);
  window.dataStep()->openCaseFolder(QString::fromStdString(second.string()));
  EXPECT_TRUE(question.contains(QStringLiteral("registration results are dropped"))) << question.toStdString();
  EXPECT_TRUE(question.contains(QStringLiteral("1 landmark"))) << question.toStdString();
  EXPECT_TRUE(question.contains(QStringLiteral("1 accepted"))) << question.toStdString();
  EXPECT_FALSE(window.dataStep()->isBusy()) << "cancelled: nothing loads";
  EXPECT_EQ(document.resultVerdict(), fct::ResultVerdict::Accepted);

  // Discard: the new case comes in and nothing derived from the old one survives.
  QSignalSpy finished(window.dataStep(), &fct::DataStepWidget::loadFinished);
  answerNextMessageBox(QMessageBox::Discard);
  window.dataStep()->openCaseFolder(QString::fromStdString(second.string()));
  ASSERT_TRUE(finished.wait(20000));
  ASSERT_TRUE(finished.at(0).at(0).toBool()) << finished.at(0).at(1).toString().toStdString();
  EXPECT_EQ(document.result(), nullptr);
  EXPECT_TRUE(document.results().empty());
  EXPECT_EQ(document.resultVerdict(), fct::ResultVerdict::Undecided);
  EXPECT_TRUE(document.landmarks().ct.empty());
  EXPECT_TRUE(document.landmarks().imageByView.empty());
  ASSERT_TRUE(document.initialPose()) << "the new case's own initial pose";
  EXPECT_TRUE(document.initialPoseSource().contains(QStringLiteral("initial_pose.json")));
  EXPECT_TRUE(document.sessionPath().empty()) << "saving must not overwrite the first case's session";
  EXPECT_EQ(review->historyChooser()->count(), 0);

  // A saved session holds its work: then the swap needs no question.
  ASSERT_TRUE(window.saveSessionTo(QString::fromStdString((m_folder / "second.fctsession.json").string())));
  document.addResult(result);
  ASSERT_TRUE(window.saveSessionTo(QString::fromStdString((m_folder / "second.fctsession.json").string())));
  finished.clear();
  window.dataStep()->openCaseFolder(QString::fromStdString(fct::test::builtinCaseDir().string()));
  ASSERT_TRUE(finished.wait(20000));
  EXPECT_TRUE(document.results().empty());
}

}  // namespace
