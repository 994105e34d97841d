// ReviewStepWidget: contours at both poses over every X-ray, the DRR blend and checkerboard, flicker, sTRE with a
// truth, the verdict, and the exports (.tfm and JSON read back equal; screenshot PNG readable).
#include <gtest/gtest.h>

#include <QComboBox>
#include <QImage>

#include "Evaluation/PoseOffset.h"
#include "IO/Dicom/DicomRegistrationReader.h"
#include "IO/Project/ItkTransformFile.h"
#include "IO/Project/PoseFile.h"
#include "StepTestSession.h"
#include "TestSupport.h"
#include "Widgets/ReviewStepWidget.h"

namespace {

/// A result ending at `finalPose` from a start 4 mm away.
fct::RegistrationResult resultAt(const fct::test::StepTestSession& session, const Eigen::Isometry3d& finalPose) {
  fct::RegistrationResult result;
  result.T_initial = fct::PoseOffset::randomAtSurfaceDistance(*session.bone, session.T_truth, 4.0, 5).value();
  result.T_world_from_ct = finalPose;
  return result;
}

}  // namespace

TEST(ReviewStepWidget, DrawsBothOutlinesAndTheDrrAndShowsTheSurfaceError) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  session.document.addResult(resultAt(session, session.T_truth));
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document));
  ASSERT_TRUE(step.finalSurfaceTre_mm().has_value()) << step.message().toStdString();
  EXPECT_NEAR(*step.finalSurfaceTre_mm(), 0.0, 1e-9);
  for (fct::XrayViewWidget* view : session.xrayViews) {
    EXPECT_TRUE(view->isLayerVisible(fct::ReviewStepWidget::kInitialLayer));
    EXPECT_TRUE(view->isLayerVisible(fct::ReviewStepWidget::kFinalLayer));
    EXPECT_FALSE(view->hasLayer(fct::ReviewStepWidget::kDrrLayer)) << "DRR off by default";
  }
  step.setShowInitial(false);
  EXPECT_FALSE(session.xrayViews[0]->isLayerVisible(fct::ReviewStepWidget::kInitialLayer));
  EXPECT_TRUE(session.xrayViews[0]->isLayerVisible(fct::ReviewStepWidget::kFinalLayer));

  step.setDrrMode(fct::ReviewStepWidget::DrrMode::Checkerboard);
  EXPECT_TRUE(session.xrayViews[1]->isLayerVisible(fct::ReviewStepWidget::kDrrLayer));
  step.setFlicker(true);
  EXPECT_TRUE(step.isFlickering());
  const bool shown = session.xrayViews[1]->isLayerVisible(fct::ReviewStepWidget::kDrrLayer);
  QTest::qWait(fct::ReviewStepWidget::kFlickerInterval_ms + 200);
  EXPECT_NE(session.xrayViews[1]->isLayerVisible(fct::ReviewStepWidget::kDrrLayer), shown) << "the DRR flickered";
  step.setActive(false);
  EXPECT_FALSE(step.isFlickering()) << "an inactive step does not flicker";
  EXPECT_FALSE(session.xrayViews[1]->isLayerVisible(fct::ReviewStepWidget::kFinalLayer));
}

TEST(ReviewStepWidget, AcceptRejectAndExportsReadBack) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  const Eigen::Isometry3d finalPose =
      fct::PoseOffset::randomAtSurfaceDistance(*session.bone, session.T_truth, 0.5, 9).value();
  session.document.addResult(resultAt(session, finalPose));
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document));
  EXPECT_NEAR(*step.finalSurfaceTre_mm(), 0.5, 1e-3);
  step.acceptResult();
  EXPECT_EQ(session.document.resultVerdict(), fct::ResultVerdict::Accepted);
  step.rejectResult();
  EXPECT_EQ(session.document.resultVerdict(), fct::ResultVerdict::Rejected);

  const auto dir = fct::test::scratchDir();
  ASSERT_TRUE(step.exportPose(QString::fromStdString((dir / "pose.tfm").string()))) << step.message().toStdString();
  auto tfm = fct::ItkTransformFile::read(dir / "pose.tfm");
  ASSERT_TRUE(tfm.ok()) << tfm.error();
  EXPECT_TRUE(tfm.value().isApprox(finalPose, 1e-9));
  ASSERT_TRUE(step.exportPose(QString::fromStdString((dir / "pose.json").string()))) << step.message().toStdString();
  auto json = fct::PoseFile::read(dir / "pose.json");
  ASSERT_TRUE(json.ok()) << json.error();
  EXPECT_TRUE(json.value().isApprox(finalPose, 1e-9));

  const QString shot = QString::fromStdString((dir / "review.png").string());
  ASSERT_TRUE(step.saveScreenshot(shot)) << step.message().toStdString();
  const QImage image(shot);
  EXPECT_FALSE(image.isNull());
  int viewsWidth = 0;
  for (const fct::XrayViewWidget* view : session.xrayViews) viewsWidth += view->width();
  EXPECT_EQ(image.width(), viewsWidth) << "the X-ray views side by side";
  EXPECT_FALSE(step.saveScreenshot(QString::fromStdString((dir / "missing" / "x.png").string())));
  EXPECT_NE(step.message().indexOf(QStringLiteral("Cannot write")), -1);
}

TEST(ReviewStepWidget, ExportsTheFinalPoseAsADicomRegistration) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  const Eigen::Isometry3d finalPose =
      fct::PoseOffset::randomAtSurfaceDistance(*session.bone, session.T_truth, 0.5, 9).value();
  session.document.addResult(resultAt(session, finalPose));
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  const auto dir = fct::test::scratchDir();
  ASSERT_TRUE(step.exportDicomRegistration(QString::fromStdString((dir / "reg.dcm").string())))
      << step.message().toStdString();
  EXPECT_NE(step.message().indexOf(QStringLiteral("generated Frame of Reference UID")), -1)
      << "the phantom CT is no DICOM series: " << step.message().toStdString();
  auto registration = fct::DicomRegistrationReader::read(dir / "reg.dcm");
  ASSERT_TRUE(registration.ok()) << registration.error();
  EXPECT_TRUE(registration.value().T_world_from_ct.matrix().isApprox(finalPose.matrix(), 1e-8));
  EXPECT_FALSE(step.exportDicomRegistration(QString::fromStdString((dir / "missing" / "reg.dcm").string())));
  EXPECT_NE(step.message().indexOf(QStringLiteral("Cannot export the DICOM registration")), -1)
      << step.message().toStdString();
}

TEST(ReviewStepWidget, WithoutAResultExportIsRefusedWithAMessage) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document));
  const auto dir = fct::test::scratchDir();
  EXPECT_FALSE(step.exportPose(QString::fromStdString((dir / "pose.tfm").string())));
  EXPECT_NE(step.message().indexOf(QStringLiteral("No registration result")), -1) << step.message().toStdString();
  EXPECT_FALSE(std::filesystem::exists(dir / "pose.tfm"));
  EXPECT_FALSE(step.exportDicomRegistration(QString::fromStdString((dir / "reg.dcm").string())));
  EXPECT_FALSE(std::filesystem::exists(dir / "reg.dcm"));
  step.acceptResult();
  EXPECT_EQ(session.document.resultVerdict(), fct::ResultVerdict::Undecided);
}

TEST(ReviewStepWidget, OutlinesAreDrawnOverTheCheckerboardAndTheBlend) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  session.document.addResult(resultAt(session, session.T_truth));
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document));
  step.setShowInitial(false);
  step.setContourColours(QColor(255, 0, 255), QColor(255, 0, 255));  // a colour neither the X-ray nor the DRR has
  fct::XrayViewWidget* view = session.xrayViews[0];
  const auto magentaPixels = [view] {
    const QImage shot = view->grab().toImage();
    int count = 0;
    for (int y = 0; y < shot.height(); ++y) {
      for (int x = 0; x < shot.width(); ++x) {
        const QColor c = shot.pixelColor(x, y);
        if (c.red() > 200 && c.blue() > 200 && c.green() < 80) ++count;
      }
    }
    return count;
  };
  const int alone = magentaPixels();
  ASSERT_GT(alone, 50) << "the final outline is drawn";
  for (const auto mode : {fct::ReviewStepWidget::DrrMode::Checkerboard, fct::ReviewStepWidget::DrrMode::Blend}) {
    step.setDrrMode(mode);
    step.setDrrOpacity(1.0);
    ASSERT_TRUE(view->isLayerVisible(fct::ReviewStepWidget::kDrrLayer));
    EXPECT_GT(magentaPixels(), alone * 9 / 10) << "the outline stays on top of the DRR";
  }
}

TEST(ReviewStepWidget, TheHistoryKeepsTheAcceptedResultAndGoesBackToAnyRun) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document));
  session.document.addResult(resultAt(session, session.T_truth));
  step.acceptResult();
  fct::RegistrationResult later = resultAt(session, session.T_truth);
  later.cancelled = true;
  EXPECT_FALSE(session.document.addResult(later)) << "a later run does not replace the accepted result";
  QComboBox* history = step.historyChooser();
  ASSERT_EQ(history->count(), 2);
  EXPECT_EQ(history->currentIndex(), 0);
  EXPECT_TRUE(history->itemText(0).contains(QStringLiteral("accepted"))) << history->itemText(0).toStdString();
  EXPECT_TRUE(history->itemText(1).contains(QStringLiteral("cancelled"))) << history->itemText(1).toStdString();
  emit history->activated(1);  // the user picks run 2 in the chooser
  EXPECT_EQ(session.document.currentResultIndex(), 1);
  EXPECT_TRUE(session.document.result()->cancelled);
  EXPECT_EQ(session.document.resultVerdict(), fct::ResultVerdict::Undecided);
  emit history->activated(0);  // and back to the accepted one
  EXPECT_EQ(session.document.resultVerdict(), fct::ResultVerdict::Accepted);
}
