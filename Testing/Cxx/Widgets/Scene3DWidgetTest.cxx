#include <gtest/gtest.h>

#include <QOpenGLContext>
#include <QTest>
#include <QVBoxLayout>

#include "StudioTestCase.h"
#include "Widgets/Scene3DWidget.h"
#include "Widgets/StudioDocument.h"

namespace {

/// Pixels of `image` whose colour is near the bone colour (pale yellow, lit: red > blue + 30).
int boneColouredPixels(const QImage& image) {
  int count = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const QColor c = image.pixelColor(x, y);
      if (c.red() > 90 && c.red() > c.blue() + 30 && c.green() > c.blue() + 15) ++count;
    }
  }
  return count;
}

TEST(Scene3DWidget, BuildsTheBoneSurfaceAndOneDetectorPerView) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  fct::StudioDocument document;
  fct::Scene3DWidget scene(&document);
  EXPECT_EQ(scene.boneTriangleCount(), 0);
  ASSERT_TRUE(document.loadCt(dir / "ct.nrrd").ok());
  ASSERT_TRUE(document.loadViews(dir / "views.json").ok());
  EXPECT_GT(scene.boneTriangleCount(), 1000);
  EXPECT_EQ(scene.viewCount(), 6);  // per view: detector, source, beam
  EXPECT_EQ(scene.poseDescription(), QStringLiteral("identity pose (no pose yet)"));
  document.setInitialPose(Eigen::Isometry3d::Identity(), QStringLiteral("test"));
  EXPECT_EQ(scene.poseDescription(), QStringLiteral("initial pose"));
  scene.setBoneThreshold_hu(5000.0);  // above every value of the phantom
  EXPECT_EQ(scene.boneTriangleCount(), 0);
}

// Render test: needs an OpenGL context (run under xvfb-run, as scripts/test.sh does); skipped without one.
TEST(Scene3DWidgetRender, DrawsTheBoneInTheViewport) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  fct::StudioDocument document;
  ASSERT_TRUE(document.loadCt(dir / "ct.nrrd").ok());
  if (!fct::Scene3DWidget::openGlAvailable()) {
    GTEST_SKIP() << "no OpenGL widgets on this Qt platform (the 'render' CTest runs this with xcb under xvfb-run)";
  }
  fct::Scene3DWidget scene(&document);
  scene.resize(320, 240);
  scene.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&scene));
  ASSERT_TRUE(scene.context() && scene.context()->isValid());
  const QImage image = scene.grabFramebuffer();
  ASSERT_FALSE(image.isNull());
  image.save(QStringLiteral("/tmp/fluoroct_tests_scene3d.png"));
  const int bone = boneColouredPixels(image);
  EXPECT_GT(bone, 320 * 240 / 50) << "bone-coloured pixels: " << bone;
  EXPECT_LT(bone, 320 * 240);  // and the background is there too
}

// Render test: the view draws the bone again after it was shrunk to nothing (a collapsed splitter, a minimised window)
// and given back its size, and after its top-level window changed (a new OpenGL context).
TEST(Scene3DWidgetRender, DrawsTheBoneAgainAfterShrinkingToNothingAndRestoring) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  fct::StudioDocument document;
  ASSERT_TRUE(document.loadCt(dir / "ct.nrrd").ok());
  if (!fct::Scene3DWidget::openGlAvailable()) {
    GTEST_SKIP() << "no OpenGL widgets on this Qt platform (the 'render' CTest runs this with xcb under xvfb-run)";
  }
  QWidget holder;
  auto* layout = new QVBoxLayout(&holder);
  layout->setContentsMargins(0, 0, 0, 0);
  auto* scene = new fct::Scene3DWidget(&document, &holder);
  layout->addWidget(scene);
  holder.resize(320, 240);
  holder.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&holder));
  EXPECT_GT(boneColouredPixels(scene->grabFramebuffer()), 320 * 240 / 50);
  for (const QSize size : {QSize(1, 1), QSize(0, 0)}) {
    scene->setMinimumSize(0, 0);
    holder.setMinimumSize(0, 0);
    holder.resize(size);
    scene->resize(size);
    QTest::qWait(50);
    (void)scene->grabFramebuffer();  // renders at the tiny size
    holder.resize(320, 240);
    QTest::qWait(50);
    const int bone = boneColouredPixels(scene->grabFramebuffer());
    EXPECT_GT(bone, 320 * 240 / 50) << "after shrinking to " << size.width() << "x" << size.height();
  }
  QWidget other;
  other.resize(320, 240);
  other.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&other));
  scene->setParent(&other);  // another window: Qt gives the view a new OpenGL context
  scene->resize(320, 240);
  scene->show();
  QTest::qWait(50);
  EXPECT_GT(boneColouredPixels(scene->grabFramebuffer()), 320 * 240 / 50) << "in another window";
}

}  // namespace
