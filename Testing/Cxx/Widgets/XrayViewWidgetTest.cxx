#include <gtest/gtest.h>

#include <QApplication>
#include <QSignalSpy>
#include <QTest>
#include <QWheelEvent>

#include "Widgets/XrayViewWidget.h"

namespace {

using fct::OverlayPoint;
using fct::XrayViewWidget;

/// A 200 x 100 ramp image (value = col + row).
fct::FloatImage rampImage() {
  fct::FloatImage image = fct::FloatImage::filled(200, 100);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) image.at(col, row) = static_cast<float>(col + row);
  }
  return image;
}

void sendWheel(QWidget& widget, QPoint at, int delta, Qt::KeyboardModifiers modifiers = Qt::NoModifier) {
  QWheelEvent event(QPointF(at), QPointF(widget.mapToGlobal(at)), QPoint(), QPoint(0, delta), Qt::NoButton, modifiers,
                    Qt::NoScrollPhase, false);
  QApplication::sendEvent(&widget, &event);
}

TEST(XrayViewWidget, ClickGivesTheImagePixelAtZoomAndPan) {
  XrayViewWidget view;
  view.resize(400, 300);
  view.setImage(rampImage());
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  view.setZoom(2.5);
  view.setPan(QPointF(30, -20));
  QSignalSpy spy(&view, &XrayViewWidget::pixelClicked);

  const Eigen::Vector2d target(37.0, 61.0);
  QTest::mouseClick(&view, Qt::LeftButton, Qt::NoModifier, view.widgetPointForPixel(target));
  ASSERT_EQ(spy.count(), 1);
  const auto uv = spy.at(0).at(0).value<Eigen::Vector2d>();
  // The widget point is rounded to whole widget pixels: 2 px (fit) x 2.5 zoom = 5 widget px per image pixel.
  EXPECT_NEAR(uv.x(), target.x(), 0.2);
  EXPECT_NEAR(uv.y(), target.y(), 0.2);
}

TEST(XrayViewWidget, WheelZoomKeepsThePixelUnderTheCursor) {
  XrayViewWidget view;
  view.resize(400, 300);
  view.setImage(rampImage());
  const QPoint cursor(250, 120);
  const Eigen::Vector2d before = view.pixelForWidgetPoint(cursor);
  sendWheel(view, cursor, 240);
  EXPECT_NEAR(view.zoom(), 1.44, 1e-9);
  const Eigen::Vector2d after = view.pixelForWidgetPoint(cursor);
  EXPECT_NEAR(after.x(), before.x(), 1e-6);
  EXPECT_NEAR(after.y(), before.y(), 1e-6);
}

TEST(XrayViewWidget, DraggingAPointMovesItAndIsNotAClick) {
  XrayViewWidget view;
  view.resize(400, 300);
  view.setImage(rampImage());
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  view.setPointLayer(QStringLiteral("marks"), {OverlayPoint{{50.0, 40.0}, QStringLiteral("L1"), Qt::green}}, true);
  QSignalSpy clicks(&view, &XrayViewWidget::pixelClicked);
  QSignalSpy drags(&view, &XrayViewWidget::pointDragged);

  const QPoint from = view.widgetPointForPixel({50.0, 40.0});
  const QPoint to = view.widgetPointForPixel({70.0, 45.0});
  QTest::mousePress(&view, Qt::LeftButton, Qt::NoModifier, from);
  QTest::mouseMove(&view, (from + to) / 2);
  QTest::mouseMove(&view, to);
  QTest::mouseRelease(&view, Qt::LeftButton, Qt::NoModifier, to);

  EXPECT_EQ(clicks.count(), 0);
  ASSERT_GE(drags.count(), 1);
  const QList<QVariant> last = drags.takeLast();
  EXPECT_EQ(last.at(0).toString(), QStringLiteral("marks"));
  EXPECT_EQ(last.at(1).toInt(), 0);
  const auto uv = last.at(2).value<Eigen::Vector2d>();
  EXPECT_NEAR(uv.x(), 70.0, 0.5);
  EXPECT_NEAR(uv.y(), 45.0, 0.5);
  EXPECT_NEAR(view.layerPoints(QStringLiteral("marks")).at(0).uv_px.x(), 70.0, 0.5);
}

TEST(XrayViewWidget, LeftDragOnTheImagePansWithoutClicking) {
  XrayViewWidget view;
  view.resize(400, 300);
  view.setImage(rampImage());
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  QSignalSpy clicks(&view, &XrayViewWidget::pixelClicked);
  QTest::mousePress(&view, Qt::LeftButton, Qt::NoModifier, QPoint(100, 100));
  QTest::mouseMove(&view, QPoint(130, 110));
  QTest::mouseRelease(&view, Qt::LeftButton, Qt::NoModifier, QPoint(130, 110));
  EXPECT_EQ(clicks.count(), 0);
  EXPECT_NEAR(view.pan().x(), 30.0, 1e-9);
  EXPECT_NEAR(view.pan().y(), 10.0, 1e-9);
}

TEST(XrayViewWidget, CtrlDragChangesWindowAndLevel) {
  XrayViewWidget view;
  view.resize(400, 300);
  view.setImage(rampImage());
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  const double window = view.window();
  const double level = view.level();
  QTest::mousePress(&view, Qt::LeftButton, Qt::ControlModifier, QPoint(100, 100));
  QTest::mouseMove(&view, QPoint(160, 80));
  QTest::mouseRelease(&view, Qt::LeftButton, Qt::ControlModifier, QPoint(160, 80));
  EXPECT_GT(view.window(), window);
  EXPECT_GT(view.level(), level);
}

TEST(XrayViewWidget, ImageLayerOfAnotherSizeIsRefusedAndClicksOutsideAreIgnored) {
  XrayViewWidget view;
  view.resize(400, 300);
  view.setImage(rampImage());
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  QImage wrong(10, 10, QImage::Format_ARGB32);
  view.setImageLayer(QStringLiteral("rois"), wrong, 0.5);
  EXPECT_FALSE(view.hasLayer(QStringLiteral("rois")));
  QImage right(200, 100, QImage::Format_ARGB32);
  right.fill(Qt::transparent);
  view.setImageLayer(QStringLiteral("rois"), right, 0.5);
  EXPECT_TRUE(view.isLayerVisible(QStringLiteral("rois")));
  view.setLayerVisible(QStringLiteral("rois"), false);
  EXPECT_FALSE(view.isLayerVisible(QStringLiteral("rois")));
  EXPECT_TRUE(view.hasLayer(QStringLiteral("rois")));

  QSignalSpy clicks(&view, &XrayViewWidget::pixelClicked);
  // The 200 x 100 image fits 400 x 200 widget pixels: rows 0..49 and 250..299 of the widget are outside it.
  QTest::mouseClick(&view, Qt::LeftButton, Qt::NoModifier, QPoint(200, 20));
  EXPECT_EQ(clicks.count(), 0);
}

TEST(XrayViewWidget, ShowsAnXrayImageWithARobustWindow) {
  fct::XrayImage xray;
  xray.cols = 4;
  xray.rows = 2;
  xray.pixels = {0, 10, 20, 30, 40, 50, 60, 70};
  XrayViewWidget view;
  view.setImage(xray);
  EXPECT_EQ(view.imageSize(), QSize(4, 2));
  EXPECT_GT(view.window(), 0.0);
  EXPECT_GT(view.level(), 0.0);
  EXPECT_LT(view.level(), 70.0);
  view.clear();
  EXPECT_FALSE(view.hasImage());
}

/// A 200 x 100 X-ray like the built-in case's: the direct exposure (60000) on the left 40 %, the patient on the right,
/// its soft tissue ramping from 12000 down to 3000 away from the skin edge, with a bone block at 2000.
fct::XrayImage patientXray() {
  fct::XrayImage xray;
  xray.cols = 200;
  xray.rows = 100;
  xray.pixels.resize(200 * 100);
  for (int row = 0; row < xray.rows; ++row) {
    for (int col = 0; col < xray.cols; ++col) {
      float value = 60000.0f;
      if (col >= 80) value = std::max(3000.0f, 12000.0f - 600.0f * static_cast<float>(col - 80));
      if (col >= 120 && col < 160 && row >= 30 && row < 70) value = 2000.0f;
      xray.pixels[static_cast<std::size_t>(row * xray.cols + col)] = value;
    }
  }
  return xray;
}

TEST(XrayViewWidget, OpensAtAWindowOnThePatientNotTheDirectExposure) {
  XrayViewWidget view;
  view.resize(400, 300);
  view.setImage(patientXray());
  const double low = view.level() - 0.5 * view.window();
  const double high = view.level() + 0.5 * view.window();
  EXPECT_LE(low, 2000.0 + 1.0) << "the bone is at the dark end";
  EXPECT_GE(high, 3000.0) << "the soft tissue next to the bone is brighter than the bone";
  EXPECT_LT(high, 15000.0) << "the direct exposure (60000) takes no grey levels";
  view.applyWindowPreset(fct::XrayWindowPreset::FullRange);
  EXPECT_DOUBLE_EQ(view.window(), 58000.0);
  view.applyWindowPreset(fct::XrayWindowPreset::WholeField);
  EXPECT_GT(view.level() + 0.5 * view.window(), 59000.0) << "the whole field reaches the direct exposure";
  view.applyWindowPreset(fct::XrayWindowPreset::Automatic);
  EXPECT_NEAR(view.level() + 0.5 * view.window(), high, 1e-9);
  EXPECT_EQ(view.fieldMask().size(), 200u * 100u);
}

TEST(XrayViewWidget, AnImageWithoutDirectExposureOpensAtItsRobustRange) {
  XrayViewWidget view;
  fct::XrayImage xray;
  xray.cols = 100;
  xray.rows = 10;
  for (int i = 0; i < 1000; ++i) xray.pixels.push_back(100.0f + static_cast<float>(i % 100));
  view.setImage(xray);
  EXPECT_NEAR(view.level(), 149.5, 1.0);
  EXPECT_NEAR(view.window(), 98.0, 1.0);
  fct::XrayImage empty;
  view.setImage(empty);
  view.applyWindowPreset(fct::XrayWindowPreset::Automatic);  // nothing shown: no effect, no crash
  EXPECT_FALSE(view.hasImage());
}

TEST(XrayViewWidget, AThickPatientWithBrightThinEdgesOpensWithItsBodyInTheMidGreys) {
  // A lateral pelvis: 90 % of the field is the body at 30-190 counts, the rest a thin edge ramping up to 12000 counts,
  // too little of it at the top for a direct exposure; the 1st-99th percentile window left the body in its darkest 6 %.
  XrayViewWidget view;
  fct::XrayImage xray;
  xray.cols = 100;
  xray.rows = 100;
  for (int i = 0; i < 10000; ++i) {
    const bool edge = i % 100 >= 90;
    xray.pixels.push_back(edge ? 200.0f + 12000.0f * static_cast<float>((i / 100) % 100) / 99.0f
                               : 30.0f + static_cast<float>((i * 7) % 160));
  }
  view.setImage(xray);
  const double low = view.level() - 0.5 * view.window();
  const double high = view.level() + 0.5 * view.window();
  const double bodyMedian = 110.0;
  const double shownAt = (bodyMedian - low) / (high - low);
  EXPECT_GT(shownAt, 0.15) << "W " << view.window() << " L " << view.level();
  EXPECT_LT(shownAt, 0.85) << "W " << view.window() << " L " << view.level();
  EXPECT_GE(high, 190.0) << "the whole body stays inside the window";
  view.applyWindowPreset(fct::XrayWindowPreset::WholeField);
  EXPECT_GT(view.level() + 0.5 * view.window(), 10000.0) << "the whole-field preset still reaches the bright edge";
}

}  // namespace
