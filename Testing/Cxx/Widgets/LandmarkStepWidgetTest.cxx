// LandmarkStepWidget: landmark pairs placed by simulated clicks give an initial pose near the truth; bad input (too
// few landmarks, an X-ray click with nothing selected) leaves a message and the data as they were; landmark files
// round-trip; the setup preset and the table edits work.
#include <gtest/gtest.h>

#include <QHeaderView>
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

namespace {

/// Places landmark i (of `targets`) in the CT and, for each listed view, at its true projection.
void placeLandmark(fct::test::StepTestSession& session, fct::LandmarkStepWidget& step, const Eigen::Vector3d& target,
                   std::initializer_list<int> views) {
  step.addCtLandmark(target);
  for (int v : views) {
    step.setImagePoint(v, session.document.views()[static_cast<std::size_t>(v)].camera.project(session.T_truth * target));
  }
}

}  // namespace

TEST(LandmarkStepWidget, StatesTheRuleAndSaysPerLandmarkAndViewWhatIsMissing) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  EXPECT_TRUE(fct::LandmarkStepWidget::ruleText().contains(QStringLiteral("4 of them clicked in the same view")));
  const auto targets = session.spreadBonePoints();
  ASSERT_GE(targets.size(), 5u);
  // 4 landmarks, 2 in each of two views: the stated "4 landmarks" rule alone is not enough.
  placeLandmark(session, step, targets[0], {0});
  placeLandmark(session, step, targets[1], {0});
  placeLandmark(session, step, targets[2], {1});
  placeLandmark(session, step, targets[3], {1});
  placeLandmark(session, step, targets[4], {});
  const QString missing = step.missingText();
  EXPECT_TRUE(missing.contains(QStringLiteral("click L5 in an X-ray view"))) << missing.toStdString();
  EXPECT_TRUE(missing.contains(QStringLiteral("2 more landmark(s) in view"))) << missing.toStdString();
  EXPECT_TRUE(missing.contains(QStringLiteral("Clicked per view: ") + QString::fromStdString(session.document.views()[0].name) +
                               QStringLiteral(" 2")))
      << missing.toStdString();
  EXPECT_FALSE(step.computePose());
  EXPECT_TRUE(step.message().contains(QStringLiteral("To do: click L5"))) << step.message().toStdString();
  EXPECT_FALSE(session.document.initialPose());
  // Two more clicks in view 0 (L3, L4) meet the rule: nothing missing, and the pose is computed.
  step.selectLandmark(QStringLiteral("L5"));
  step.deleteLandmark(QStringLiteral("L5"));
  EXPECT_EQ(step.message(), QStringLiteral("Deleted L5 (Ctrl+Z brings it back)."));
  for (int i : {2, 3}) {
    step.selectLandmark(QStringLiteral("L%1").arg(i + 1));
    step.setImagePoint(0, session.document.views()[0].camera.project(session.T_truth * targets[static_cast<std::size_t>(i)]));
  }
  EXPECT_TRUE(step.missingText().isEmpty()) << step.missingText().toStdString();
  EXPECT_TRUE(step.computePose()) << step.message().toStdString();
  auto* header = step.table()->horizontalHeaderItem(3);
  EXPECT_TRUE(step.table()->item(0, 3)->text().endsWith(QStringLiteral(" px"))) << "units in every residual";
  EXPECT_GE(step.table()->horizontalHeader()->sectionSize(3),
            step.table()->horizontalHeader()->fontMetrics().horizontalAdvance(header->text()))
      << "the residual header is not clipped";
}

TEST(LandmarkStepWidget, SelectingARowJumpsTheSlicesAndEmptyTableSpaceDeselects) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  step.resize(420, 500);
  step.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&step));
  const auto targets = session.spreadBonePoints();
  ASSERT_GE(targets.size(), 2u);
  session.clickCt(targets[0]);
  session.clickCt(targets[1]);
  const Eigen::Vector3d first = session.document.landmarks().ct[0].p_ct_mm;
  QTableWidget* table = step.table();
  const QRect cell = table->visualItemRect(table->item(0, 1));
  QTest::mouseClick(table->viewport(), Qt::LeftButton, Qt::NoModifier, cell.center());
  EXPECT_EQ(step.selectedLandmark(), QStringLiteral("L1"));
  for (fct::SliceViewWidget* view : session.sliceViews) {
    EXPECT_LT((view->crosshair_ct_mm() - first).norm(), 1e-9) << "every slice view shows L1";
  }
  QTest::mouseClick(table->viewport(), Qt::LeftButton, Qt::NoModifier, QPoint(10, table->viewport()->height() - 5));
  EXPECT_TRUE(step.selectedLandmark().isEmpty()) << "a click below the rows deselects";
}

TEST(LandmarkStepWidget, UndoRestoresAMovedLandmarkAndAStrayClickMovesNothing) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  const auto targets = session.spreadBonePoints();
  ASSERT_GE(targets.size(), 1u);
  session.clickCt(targets[0]);
  session.clickTrueProjection(0, targets[0]);
  const Eigen::Vector2d placed = session.document.landmarks().imageByView.at(session.document.views()[0].name)[0].uv_px;
  fct::XrayViewWidget* view = session.xrayViews[0];

  // Nothing selected: a click on the partner's marker (with a 2-pixel jitter) selects it and does not move it.
  step.selectLandmark({});
  const QPoint marker = view->widgetPointForPixel(placed);
  QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, marker);
  QTest::mouseMove(view, marker + QPoint(2, 1));
  QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, marker + QPoint(2, 1));
  EXPECT_TRUE(session.document.landmarks().imageByView.at(session.document.views()[0].name)[0].uv_px.isApprox(placed));
  EXPECT_EQ(step.selectedLandmark(), QStringLiteral("L1"));

  // A real drag moves it; one undo puts it back, redo moves it again.
  QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, marker);
  QTest::mouseMove(view, marker + QPoint(15, 0));
  QTest::mouseMove(view, marker + QPoint(30, 10));
  QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, marker + QPoint(30, 10));
  const auto uvNow = [&] { return session.document.landmarks().imageByView.at(session.document.views()[0].name)[0].uv_px; };
  const Eigen::Vector2d dragged = uvNow();
  ASSERT_GT((dragged - placed).norm(), 3.0);
  step.undo();
  EXPECT_TRUE(uvNow().isApprox(placed, 1e-9)) << "one undo for the whole drag";
  step.redo();
  EXPECT_TRUE(uvNow().isApprox(dragged, 1e-9));

  // Every edit undoes: the CT drag, the delete and the add.
  step.moveCtLandmark(QStringLiteral("L1"), targets[0] + Eigen::Vector3d(3.0, 0.0, 0.0));
  step.deleteLandmark(QStringLiteral("L1"));
  EXPECT_TRUE(session.document.landmarks().ct.empty());
  step.undo();
  ASSERT_EQ(session.document.landmarks().ct.size(), 1u);
  EXPECT_NEAR(session.document.landmarks().ct[0].p_ct_mm.x(), targets[0].x() + 3.0, 2.0);
  step.undo();
  step.undo();
  step.undo();
  EXPECT_TRUE(session.document.landmarks().imageByView.empty() ||
              session.document.landmarks().imageByView.begin()->second.empty());
  step.undo();
  EXPECT_TRUE(session.document.landmarks().ct.empty()) << "back to before the first click";
}

TEST(LandmarkStepWidget, CtrlZInTheWindowUndoesTheLastEdit) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  auto* step = new fct::LandmarkStepWidget(&session.document, session.window.get());
  step->attachViews(session.xrayViews, session.sliceViews);
  step->setActive(true);
  step->show();  // shortcuts of hidden widgets do not fire
  session.window->activateWindow();
  ASSERT_TRUE(QTest::qWaitForWindowActive(session.window.get()));
  step->addCtLandmark(session.document.ct()->centre_lps_mm());
  ASSERT_EQ(session.document.landmarks().ct.size(), 1u);
  QTest::keyClick(session.window.get(), Qt::Key_Z, Qt::ControlModifier);
  EXPECT_TRUE(session.document.landmarks().ct.empty()) << step->message().toStdString();
  QTest::keyClick(session.window.get(), Qt::Key_Z, Qt::ControlModifier | Qt::ShiftModifier);
  EXPECT_EQ(session.document.landmarks().ct.size(), 1u) << step->message().toStdString();
}

TEST(LandmarkStepWidget, ALandmarkCanBeDraggedInTheCtSlice) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  const auto targets = session.spreadBonePoints();
  ASSERT_GE(targets.size(), 1u);
  session.clickCt(targets[0]);
  ASSERT_EQ(session.document.landmarks().ct.size(), 1u);
  const Eigen::Vector3d placed = session.document.landmarks().ct[0].p_ct_mm;
  fct::SliceViewWidget* axial = session.sliceViews[0];
  const QPoint marker = axial->widgetPointForCtPoint(placed);
  const QPoint target = marker + QPoint(25, 10);
  QTest::mousePress(axial, Qt::LeftButton, Qt::NoModifier, marker);
  QTest::mouseMove(axial, target);
  QTest::mouseRelease(axial, Qt::LeftButton, Qt::NoModifier, target);
  ASSERT_EQ(session.document.landmarks().ct.size(), 1u) << "the drag moved the landmark, it added none";
  const Eigen::Vector3d moved = session.document.landmarks().ct[0].p_ct_mm;
  EXPECT_GT((moved - placed).norm(), 5.0) << "it moved";
  EXPECT_NEAR(moved.z(), placed.z(), 1e-6) << "within the axial plane";
  EXPECT_LE((axial->widgetPointForCtPoint(moved) - target).manhattanLength(), 2) << "to where it was dropped";
  step.undo();
  EXPECT_TRUE(session.document.landmarks().ct[0].p_ct_mm.isApprox(placed)) << "one drag is one undo step";
}

TEST(LandmarkStepWidget, ALongNameIsElidedInTheTableWithTheFullNameInItsTooltip) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::LandmarkStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  step.resize(420, 500);
  step.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&step));
  step.addCtLandmark(Eigen::Vector3d(1, 2, 3));
  const QString longName = QStringLiteral("left anterior superior iliac spine, most prominent point");
  ASSERT_TRUE(step.renameLandmark(QStringLiteral("L1"), longName));
  QTableWidget* table = step.table();
  QTableWidgetItem* item = table->item(0, 0);
  ASSERT_NE(item, nullptr);
  EXPECT_EQ(item->text(), longName);
  EXPECT_EQ(item->toolTip(), longName);
  EXPECT_LE(table->columnWidth(0), fct::LandmarkStepWidget::kMaxColumnWidth_px);
  EXPECT_LT(table->columnWidth(0), table->fontMetrics().horizontalAdvance(longName)) << "the name is cut, not the columns";
  EXPECT_GT(table->columnWidth(1), 0) << "the CT column stays in view";
}
