// LandmarkStepWidget: landmark pairs placed by simulated clicks give an initial pose near the truth; bad input (too
// few landmarks, an X-ray click with nothing selected) leaves a message and the data as they were; landmark files
// round-trip; the setup preset and the table edits work.
#include <gtest/gtest.h>

#include <QTableWidget>

#include "IO/Project/LandmarkFile.h"
#include "StepTestSession.h"
#include "TestSupport.h"
#include "Widgets/LandmarkStepWidget.h"

TEST(LandmarkStepWidget, ClickedLandmarkPairsGiveAnInitialPoseWithin3mm) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);

  const auto targets = session.spreadBonePoints();
  for (std::size_t i = 0; i < targets.size(); ++i) {
    session.clickCt(targets[i]);
    ASSERT_EQ(session.document.landmarks().ct.size(), i + 1) << step.message().toStdString();
    EXPECT_EQ(step.selectedLandmark(), QStringLiteral("L%1").arg(i + 1));
    // The CT point actually clicked (snapped to the slice and the screen pixel) and its true projections.
    const Eigen::Vector3d clicked = session.document.landmarks().ct.back().p_ct_mm;
    EXPECT_LT((clicked - targets[i]).norm(), 2.0);
    for (std::size_t v = 0; v < session.xrayViews.size(); ++v) session.clickTrueProjection(v, clicked);
  }
  ASSERT_GE(targets.size(), 4u);
  for (const auto& [view, points] : session.document.landmarks().imageByView) {
    EXPECT_EQ(points.size(), targets.size()) << "every X-ray click placed a partner in view " << view;
  }

  ASSERT_TRUE(step.computePose()) << step.message().toStdString();
  ASSERT_TRUE(session.document.initialPose().has_value());
  const double error_mm = session.surfaceError_mm(*session.document.initialPose());
  std::printf("initial pose from %zu clicked landmarks: %.2f mm from the truth\n", targets.size(), error_mm);
  EXPECT_LT(error_mm, 3.0);
  ASSERT_TRUE(step.estimate().has_value());
  EXPECT_EQ(step.estimate()->residuals.size(), targets.size());
  // Residuals in the table and the landmarks projected at the pose in every X-ray view.
  auto* table = step.findChild<QTableWidget*>();
  ASSERT_NE(table, nullptr);
  EXPECT_NE(table->item(0, 3)->text(), QStringLiteral("—"));
  for (fct::XrayViewWidget* view : session.xrayViews) {
    EXPECT_EQ(view->layerPoints(fct::LandmarkStepWidget::kProjectedLayer).size(), targets.size());
  }
}

TEST(LandmarkStepWidget, FewerThanFourLandmarksShowAMessageAndLoseNothing) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  const auto targets = session.spreadBonePoints();
  for (int i = 0; i < 3; ++i) {
    step.addCtLandmark(targets[static_cast<std::size_t>(i)]);
    const Eigen::Vector2d uv = session.document.views()[0].camera.project(session.T_truth * targets[static_cast<std::size_t>(i)]);
    step.setImagePoint(0, uv);
  }
  const fct::Landmarks before = session.document.landmarks();
  EXPECT_FALSE(step.computePose());
  EXPECT_NE(step.message().indexOf(QStringLiteral("4")), -1) << step.message().toStdString();
  EXPECT_FALSE(session.document.initialPose().has_value());
  ASSERT_EQ(session.document.landmarks().ct.size(), 3u);
  EXPECT_EQ(session.document.landmarks().imageByView.at("ap").size(), 3u);
  EXPECT_EQ(session.document.landmarks().ct[2].p_ct_mm, before.ct[2].p_ct_mm);
}

TEST(LandmarkStepWidget, XrayClickWithoutASelectedLandmarkAsksForOne) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  session.clickTrueProjection(0, Eigen::Vector3d::Zero());
  EXPECT_TRUE(session.document.landmarks().imageByView.empty());
  EXPECT_NE(step.message().indexOf(QStringLiteral("Select a landmark")), -1) << step.message().toStdString();
  // Inactive: clicks are ignored.
  step.setActive(false);
  session.clickCt(session.bone->centroid_ct_mm());
  EXPECT_TRUE(session.document.landmarks().ct.empty());
}

TEST(LandmarkStepWidget, RenameDeleteAndFileRoundTrip) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  step.addCtLandmark(Eigen::Vector3d(1, 2, 3));
  step.setImagePoint(1, Eigen::Vector2d(50, 60));
  step.addCtLandmark(Eigen::Vector3d(4, 5, 6));
  EXPECT_FALSE(step.renameLandmark(QStringLiteral("L2"), QStringLiteral("L1"))) << "a used name is refused";
  ASSERT_TRUE(step.renameLandmark(QStringLiteral("L1"), QStringLiteral("ASIS left")));
  EXPECT_EQ(session.document.landmarks().ct[0].name, "ASIS left");
  EXPECT_EQ(session.document.landmarks().imageByView.at("lateral")[0].name, "ASIS left") << "renamed in the views too";

  const auto dir = fct::test::scratchDir();
  const QString ctPath = QString::fromStdString((dir / "ct.mrk.json").string());
  const QString imagePath = QString::fromStdString((dir / "xray.json").string());
  ASSERT_TRUE(step.saveLandmarks(ctPath, imagePath)) << step.message().toStdString();
  step.deleteLandmark(QStringLiteral("ASIS left"));
  ASSERT_EQ(session.document.landmarks().ct.size(), 1u);
  EXPECT_TRUE(session.document.landmarks().imageByView.empty());
  ASSERT_TRUE(step.loadLandmarks(ctPath, imagePath)) << step.message().toStdString();
  ASSERT_EQ(session.document.landmarks().ct.size(), 2u);
  EXPECT_LT((session.document.landmarks().ct[1].p_ct_mm - Eigen::Vector3d(4, 5, 6)).norm(), 1e-9);
  EXPECT_LT((session.document.landmarks().imageByView.at("lateral")[0].uv_px - Eigen::Vector2d(50, 60)).norm(), 1e-9);

  EXPECT_FALSE(step.loadLandmarks(QString::fromStdString((dir / "missing.mrk.json").string()), QString()));
  EXPECT_EQ(session.document.landmarks().ct.size(), 2u) << "a failed load keeps the landmarks";
}

TEST(LandmarkStepWidget, DraggingAPartnerMovesIt) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  step.addCtLandmark(Eigen::Vector3d(1, 2, 3));
  step.setImagePoint(0, Eigen::Vector2d(90, 90));
  fct::XrayViewWidget* view = session.xrayViews[0];
  QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, view->widgetPointForPixel(Eigen::Vector2d(90, 90)));
  QTest::mouseMove(view, view->widgetPointForPixel(Eigen::Vector2d(110, 100)));
  QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, view->widgetPointForPixel(Eigen::Vector2d(110, 100)));
  const auto& points = session.document.landmarks().imageByView.at("ap");
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LT((points[0].uv_px - Eigen::Vector2d(110, 100)).norm(), 1.0);
}

TEST(LandmarkStepWidget, SupineApPresetPutsTheBoneAtTheIsocentre) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  ASSERT_TRUE(step.applySetupPose()) << step.message().toStdString();
  ASSERT_TRUE(session.document.initialPose().has_value());
  // The simulated views look at the world origin; the bone centroid goes there.
  EXPECT_LT((*session.document.initialPose() * session.bone->centroid_ct_mm()).norm(), 1e-6);
  EXPECT_EQ(session.document.initialPoseSource(), QStringLiteral("preset supine AP"));
}
