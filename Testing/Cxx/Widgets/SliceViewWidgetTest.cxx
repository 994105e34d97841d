#include <gtest/gtest.h>

#include <QApplication>
#include <QSignalSpy>
#include <QTest>
#include <QWheelEvent>

#include "Widgets/SliceViewWidget.h"

namespace {

using fct::SliceOrientation;
using fct::SliceViewWidget;

/// A 40 x 30 x 20 volume, 1.5 x 1.0 x 2.5 mm, off-centre origin, value = z index (so slices are distinguishable).
std::shared_ptr<const fct::Volume> testVolume() {
  auto volume = fct::Volume::create({40, 30, 20}, {1.5, 1.0, 2.5}, {-20.0, 10.0, 5.0});
  EXPECT_TRUE(volume.ok());
  fct::Volume v = std::move(volume).value();
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 40; ++i) v.at(i, j, k) = static_cast<float>(100 * k);
  return std::make_shared<const fct::Volume>(std::move(v));
}

class SliceViewClick : public ::testing::TestWithParam<SliceOrientation> {};

TEST_P(SliceViewClick, ClickGivesTheCtPointOnTheSlice) {
  SliceViewWidget view(GetParam());
  view.resize(360, 300);
  view.setVolume(testVolume());
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  const Eigen::Vector3d crosshair(5.0, 20.0, 25.0);
  view.setCrosshair_ct_mm(crosshair);
  view.setZoom(1.7);
  view.setPan(QPointF(-15, 12));
  QSignalSpy spy(&view, &SliceViewWidget::pointClicked);

  const Eigen::Vector3d target(-3.0, 27.0, 40.0);
  QTest::mouseClick(&view, Qt::LeftButton, Qt::NoModifier, view.widgetPointForCtPoint(target));
  ASSERT_EQ(spy.count(), 1);
  const auto p = spy.at(0).at(0).value<Eigen::Vector3d>();
  // In-plane: the target within a widget pixel (< 0.5 mm here); along the normal: on the crosshair's slice.
  Eigen::Vector3d expected = target;
  switch (GetParam()) {
    case SliceOrientation::Axial:
      expected.z() = crosshair.z();
      break;
    case SliceOrientation::Coronal:
      expected.y() = crosshair.y();
      break;
    case SliceOrientation::Sagittal:
      expected.x() = crosshair.x();
      break;
  }
  EXPECT_LT((p - expected).norm(), 0.5) << p.transpose() << " vs " << expected.transpose();
}

INSTANTIATE_TEST_SUITE_P(AllOrientations, SliceViewClick,
                         ::testing::Values(SliceOrientation::Axial, SliceOrientation::Coronal,
                                           SliceOrientation::Sagittal));

TEST(SliceViewWidget, LayoutIsRadiologicalLikeSlicer) {
  SliceViewWidget axial(SliceOrientation::Axial);
  SliceViewWidget coronal(SliceOrientation::Coronal);
  SliceViewWidget sagittal(SliceOrientation::Sagittal);
  for (SliceViewWidget* view : {&axial, &coronal, &sagittal}) {
    view->resize(300, 300);
    view->setVolume(testVolume());
  }
  const Eigen::Vector3d c(10.0, 25.0, 30.0);
  // Axial: patient's left (+x) to the screen's right, posterior (+y) down.
  EXPECT_GT(axial.widgetPointForCtPoint(c + Eigen::Vector3d(5, 0, 0)).x(), axial.widgetPointForCtPoint(c).x());
  EXPECT_GT(axial.widgetPointForCtPoint(c + Eigen::Vector3d(0, 5, 0)).y(), axial.widgetPointForCtPoint(c).y());
  // Coronal and sagittal: superior (+z) up; sagittal: posterior (+y) to the right.
  EXPECT_LT(coronal.widgetPointForCtPoint(c + Eigen::Vector3d(0, 0, 5)).y(), coronal.widgetPointForCtPoint(c).y());
  EXPECT_LT(sagittal.widgetPointForCtPoint(c + Eigen::Vector3d(0, 0, 5)).y(), sagittal.widgetPointForCtPoint(c).y());
  EXPECT_GT(sagittal.widgetPointForCtPoint(c + Eigen::Vector3d(0, 5, 0)).x(), sagittal.widgetPointForCtPoint(c).x());
}

TEST(SliceViewWidget, WheelScrollsOneSliceAndCtrlWheelZooms) {
  SliceViewWidget view(SliceOrientation::Axial);
  view.resize(300, 300);
  view.setVolume(testVolume());
  QSignalSpy moved(&view, &SliceViewWidget::crosshairMoved);
  const double before = view.slicePosition_mm();
  EXPECT_DOUBLE_EQ(view.sliceStep_mm(), 2.5);
  QWheelEvent up(QPointF(150, 150), QPointF(150, 150), QPoint(), QPoint(0, 120), Qt::NoButton, Qt::NoModifier,
                 Qt::NoScrollPhase, false);
  QApplication::sendEvent(&view, &up);
  EXPECT_NEAR(view.slicePosition_mm() - before, 2.5, 1e-9);
  ASSERT_EQ(moved.count(), 1);
  // The slice shows the voxel values of its z.
  const Eigen::Vector3d p = view.crosshair_ct_mm();
  const double k = view.volume()->ijkFromLps(p).z();
  const QPoint centre = view.widgetPointForCtPoint(p);
  const Eigen::Vector2d uv = view.pixelForWidgetPoint(centre);
  EXPECT_NEAR(view.image().at(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y()))), 100.0 * k,
              1e-3);

  QWheelEvent zoom(QPointF(150, 150), QPointF(150, 150), QPoint(), QPoint(0, 120), Qt::NoButton, Qt::ControlModifier,
                   Qt::NoScrollPhase, false);
  QApplication::sendEvent(&view, &zoom);
  EXPECT_NEAR(view.zoom(), 1.2, 1e-9);
  EXPECT_NEAR(view.slicePosition_mm() - before, 2.5, 1e-9);
}

TEST(SliceViewWidget, ShowsOnlyTheCtPointsOfTheCurrentSlice) {
  SliceViewWidget view(SliceOrientation::Axial);
  view.resize(300, 300);
  view.setVolume(testVolume());
  view.setCrosshair_ct_mm({0.0, 20.0, 30.0});
  view.setCtPointLayer(QStringLiteral("landmarks"),
                       {fct::SlicePoint{{0.0, 20.0, 30.5}, QStringLiteral("near"), Qt::yellow},
                        fct::SlicePoint{{0.0, 20.0, 40.0}, QStringLiteral("far"), Qt::yellow}});
  const auto shown = view.layerPoints(QStringLiteral("ct:landmarks"));
  ASSERT_EQ(shown.size(), 1u);
  EXPECT_EQ(shown[0].label, QStringLiteral("near"));
}

TEST(SliceViewWidget, WithoutAVolumeClicksEmitNothing) {
  SliceViewWidget view(SliceOrientation::Coronal);
  view.resize(200, 200);
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  QSignalSpy spy(&view, &SliceViewWidget::pointClicked);
  QTest::mouseClick(&view, Qt::LeftButton, Qt::NoModifier, QPoint(100, 100));
  EXPECT_EQ(spy.count(), 0);
  view.setVolume(nullptr);
  EXPECT_FALSE(view.hasImage());
}

}  // namespace
