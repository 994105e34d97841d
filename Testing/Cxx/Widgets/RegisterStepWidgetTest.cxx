// RegisterStepWidget: a fast registration run on its worker thread ends near the truth and lands in the document;
// cancelling a run mid-way keeps the best pose so far, marked cancelled, and the widget runs again afterwards; a
// missing initial pose is refused with a message.
#include <gtest/gtest.h>

#include <QDoubleSpinBox>
#include <QPushButton>
#include <QSignalSpy>

#include "Evaluation/PoseOffset.h"
#include "Registration/RegistrationCase.h"
#include "Registration/RegistrationSchedule.h"
#include "StepTestSession.h"
#include "Widgets/RegisterStepWidget.h"

namespace {

void setStartPose(fct::test::StepTestSession& session, double distance_mm) {
  auto start = fct::PoseOffset::randomAtSurfaceDistance(*session.bone, session.T_truth, distance_mm, 3);
  ASSERT_TRUE(start.ok()) << start.error();
  session.document.setInitialPose(start.value(), QStringLiteral("test start"));
}

}  // namespace

TEST(RegisterStepWidget, DefaultRunOnItsThreadEndsWithinOneMillimetre) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  setStartPose(session, 5.0);
  fct::RegisterStepWidget step(&session.document);
  ASSERT_TRUE(step.run()) << step.message().toStdString();
  EXPECT_TRUE(step.isRunning());
  EXPECT_FALSE(step.run()) << "one run at a time";
  bool sawTimeLeft = false;
  ASSERT_TRUE(fct::test::waitUntil(
      [&] {
        sawTimeLeft = sawTimeLeft || step.progressText().contains(QStringLiteral("s left"));
        return !step.isRunning();
      },
      120000))
      << "the run ends";
  EXPECT_TRUE(sawTimeLeft) << "the progress line estimates the time left";
  ASSERT_TRUE(session.document.result() != nullptr) << step.message().toStdString();
  const fct::RegistrationResult& result = *session.document.result();
  EXPECT_FALSE(result.cancelled);
  EXPECT_EQ(result.stages.size(),
            fct::RegistrationSchedule::builtin(fct::RegistrationSchedule::kDefaultPreset).value().stages.size())
      << "the default preset's stages";
  EXPECT_GT(step.lastProgress().drrs, 0) << "progress reached the widget";
  const double error_mm = session.surfaceError_mm(result.T_world_from_ct);
  std::printf("default registration from 5 mm via the Register step: %.3f mm, %ld DRRs\n", error_mm, result.totalDrrs);
  EXPECT_LT(error_mm, 1.0);
  EXPECT_NE(step.logText().indexOf(QStringLiteral("Registered")), -1);
  EXPECT_NE(step.logText().indexOf(QStringLiteral("Coarse alignment (whole images)")), -1) << "stages in words";
}

TEST(RegisterStepWidget, CancelMidRunKeepsTheBestPoseMarkedAndTheWidgetRunsAgain) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  setStartPose(session, 8.0);
  const Eigen::Isometry3d start = *session.document.initialPose();
  fct::StudioRegistrationOptions options = session.document.registrationOptions();
  options.preset = "paper";
  session.document.setRegistrationOptions(options);
  fct::RegisterStepWidget step(&session.document);
  ASSERT_TRUE(step.run()) << step.message().toStdString();
  ASSERT_TRUE(fct::test::waitUntil([&] { return step.lastProgress().drrs > 0; }, 60000)) << "progress arrives";
  step.cancel();
  ASSERT_TRUE(fct::test::waitUntil([&] { return !step.isRunning(); }, 60000)) << "cancelling ends the run";
  ASSERT_TRUE(session.document.result() != nullptr);
  const fct::RegistrationResult& cancelled = *session.document.result();
  EXPECT_TRUE(cancelled.cancelled);
  EXPECT_LE(session.surfaceError_mm(cancelled.T_world_from_ct), session.surfaceError_mm(start) + 1e-6)
      << "the best pose so far is never worse than the start";
  EXPECT_NE(step.message().indexOf(QStringLiteral("Cancelled")), -1) << step.message().toStdString();

  options.preset = "fast";
  session.document.setRegistrationOptions(options);
  ASSERT_TRUE(step.run()) << step.message().toStdString();
  ASSERT_TRUE(fct::test::waitUntil([&] { return !step.isRunning(); }, 120000));
  ASSERT_TRUE(session.document.result() != nullptr);
  EXPECT_FALSE(session.document.result()->cancelled);
}

TEST(RegisterStepWidget, RefusesToRunWithoutAnInitialPoseOrWithABadPreset) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RegisterStepWidget step(&session.document);
  step.setActive(true);
  EXPECT_NE(step.message().indexOf(QStringLiteral("No initial pose")), -1) << step.message().toStdString();
  EXPECT_FALSE(step.run());
  EXPECT_NE(step.message().indexOf(QStringLiteral("initial pose")), -1) << step.message().toStdString();
  EXPECT_FALSE(step.isRunning());
  setStartPose(session, 3.0);
  step.setActive(true);
  EXPECT_NE(step.message().indexOf(QStringLiteral("Ready: initial pose from test start")), -1)
      << step.message().toStdString();
  fct::StudioRegistrationOptions options = session.document.registrationOptions();
  options.preset = "/nonexistent/preset.json";
  session.document.setRegistrationOptions(options);
  EXPECT_FALSE(step.run());
  EXPECT_NE(step.message().indexOf(QStringLiteral("Preset")), -1) << step.message().toStdString();
  EXPECT_EQ(session.document.result(), nullptr);
}

TEST(RegisterStepWidget, DestroyingTheWidgetDuringARunCancelsItCleanly) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  setStartPose(session, 5.0);
  auto step = std::make_unique<fct::RegisterStepWidget>(&session.document);
  ASSERT_TRUE(step->run());
  step.reset();
  EXPECT_EQ(session.document.result(), nullptr) << "a run cut short by closing stores nothing";
}

TEST(RegisterStepWidget, AResultOfViewsReplacedDuringTheRunIsNotKept) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  setStartPose(session, 5.0);
  fct::RegisterStepWidget step(&session.document);
  ASSERT_TRUE(step.run()) << step.message().toStdString();
  session.document.setViews(session.document.views());
  ASSERT_TRUE(fct::test::waitUntil([&] { return !step.isRunning(); }, 120000));
  EXPECT_EQ(session.document.result(), nullptr);
  EXPECT_NE(step.message().indexOf(QStringLiteral("changed during the run")), -1) << step.message().toStdString();
}

TEST(RegisterStepWidget, EveryAblationSwitchIncludingTheTransgraphRoundTrips) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RegisterStepWidget step(&session.document);
  EXPECT_TRUE(step.ablation().activeNames().empty()) << "every technique on by default";
  fct::RegistrationAblation all;
  all.noDynamicRois = all.noPyramid = all.nccOnly = all.localOnly = all.cmaesForGenetic = all.noTransgraph =
      all.noCtPyramid = true;
  step.setAblation(all);
  EXPECT_EQ(step.ablation().activeNames(), all.activeNames());
  fct::RegistrationAblation onlyTransgraphOff;
  onlyTransgraphOff.noTransgraph = true;
  step.setAblation(onlyTransgraphOff);
  EXPECT_EQ(step.ablation().activeNames(), std::vector<std::string>{"no-transgraph"});
}

TEST(RegisterStepWidget, TheBoneContrastIsEditableAndPreparesTheCaseAgain) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RegisterStepWidget step(&session.document);
  QDoubleSpinBox* spin = step.boneContrastSpin();
  EXPECT_EQ(spin->value(), fct::RegistrationCaseOptions::kDefaultBoneContrast) << "the CLI's default";
  EXPECT_EQ(session.document.caseOptions().value().boneContrast, fct::RegistrationCaseOptions::kDefaultBoneContrast);
  ASSERT_TRUE(session.document.preparedCase().ok());
  ASSERT_NE(session.document.readyCase(), nullptr);

  spin->setValue(1.25);
  EXPECT_EQ(session.document.registrationOptions().boneContrast, 1.25);
  EXPECT_EQ(session.document.caseOptions().value().boneContrast, 1.25) << "what the registration's case gets";
  EXPECT_EQ(session.document.readyCase(), nullptr) << "the case is prepared again with the new contrast";
  auto prepared = session.document.preparedCase();
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  EXPECT_EQ(prepared.value()->drrVolume().options().boneContrast, 1.25);

  fct::StudioRegistrationOptions options = session.document.registrationOptions();
  options.boneContrast = 1.0;  // as a session file may say it
  session.document.setRegistrationOptions(options);
  EXPECT_EQ(spin->value(), 1.0) << "the spin box follows the document";
}

TEST(RegisterStepWidget, StagesHavePlainNamesAndMessagesReachTheStatusLine) {
  EXPECT_EQ(fct::RegisterStepWidget::plainStageName("ncc-whole-1:16"),
            QStringLiteral("Coarse alignment (whole images) [ncc-whole-1:16]"));
  EXPECT_EQ(fct::RegisterStepWidget::plainStageName("vlnc-rois-1:4"),
            QStringLiteral("Refinement (bone edges, 1:4) [vlnc-rois-1:4]"));
  EXPECT_EQ(fct::RegisterStepWidget::plainStageName("vlnc-rois-1:1"), QStringLiteral("Final (full resolution) [vlnc-rois-1:1]"));
  EXPECT_EQ(fct::RegisterStepWidget::plainStageName("custom"), QStringLiteral("Refinement (bone edges) [custom]"));
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RegisterStepWidget step(&session.document);
  QSignalSpy status(&step, &fct::RegisterStepWidget::statusMessage);
  step.setActive(true);
  ASSERT_EQ(status.count(), 1);
  EXPECT_TRUE(status.at(0).at(0).toString().startsWith(QStringLiteral("No initial pose"))) << "the status line follows";
}

TEST(RegisterStepWidget, RunIsDisabledWithoutDataAndItsTooltipSaysWhatIsMissing) {
  fct::StudioDocument empty;
  fct::RegisterStepWidget idle(&empty);
  EXPECT_FALSE(idle.runButton()->isEnabled());
  EXPECT_TRUE(idle.runButton()->toolTip().contains(QStringLiteral("a CT (Data step)"))) << idle.runButton()->toolTip().toStdString();
  EXPECT_TRUE(idle.runButton()->toolTip().contains(QStringLiteral("an initial pose")));
  EXPECT_FALSE(idle.run());
  EXPECT_TRUE(idle.message().contains(QStringLiteral("X-ray views"))) << idle.message().toStdString();
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RegisterStepWidget step(&session.document);
  EXPECT_FALSE(step.runButton()->isEnabled()) << "no initial pose yet";
  setStartPose(session, 3.0);
  EXPECT_TRUE(step.runButton()->isEnabled());
}

TEST(RegisterStepWidget, EachPresetShowsAnEstimatedTimeBeforeARun) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RegisterStepWidget step(&session.document);
  step.setActive(true);
  EXPECT_FALSE(step.estimatedSeconds(QStringLiteral("fast")).has_value()) << "no initial pose, nothing measured";
  setStartPose(session, 5.0);
  ASSERT_TRUE(fct::test::waitUntil([&] { return step.estimatedSeconds(QStringLiteral("paper")).has_value(); }, 60000))
      << step.estimateText().toStdString();
  const double fast_s = *step.estimatedSeconds(QStringLiteral("fast"));
  const double paper_s = *step.estimatedSeconds(QStringLiteral("paper"));
  std::printf("estimated: fast about %.1f s, paper about %.1f s (%s)\n", fast_s, paper_s,
              step.estimateText().toStdString().c_str());
  EXPECT_GT(fast_s, 0.0);
  EXPECT_GT(paper_s, fast_s) << "the paper's preset has the larger DRR budget";
  EXPECT_TRUE(step.estimateText().contains(QStringLiteral("fast about"))) << step.estimateText().toStdString();
  EXPECT_TRUE(step.estimateText().contains(QStringLiteral("paper about"))) << step.estimateText().toStdString();

  ASSERT_TRUE(step.run()) << step.message().toStdString();
  ASSERT_TRUE(fct::test::waitUntil([&] { return !step.isRunning(); }, 120000));
  ASSERT_NE(session.document.result(), nullptr);
  std::printf("the %s run took %.2f s (%ld DRRs)\n", fct::RegistrationSchedule::kDefaultPreset,
              session.document.result()->totalSeconds, session.document.result()->totalDrrs);
  const QString lastRun = QStringLiteral("the last %1 run here took").arg(fct::RegistrationSchedule::kDefaultPreset);
  EXPECT_TRUE(step.estimateText().contains(lastRun)) << step.estimateText().toStdString();
}
