// RoiStepWidget: moving the threshold or fraction slider re-thresholds the precomputed window statistics and changes
// the kept fraction per view as expected; the overlay layers appear; exclusions are editable.
#include <gtest/gtest.h>

#include <QDoubleSpinBox>
#include <QRadioButton>
#include <QSlider>

#include <cmath>

#include "Similarity/DynamicRoiSelector.h"
#include "StepTestSession.h"
#include "Widgets/RoiStepWidget.h"

TEST(RoiStepWidget, RaisingTheThresholdSliderKeepsFewerPixelsInEveryView) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  auto prepared = session.document.preparedCase();
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const std::size_t viewCount = session.document.views().size();
  const int window = session.document.roiParameters().windowSize;
  std::vector<fct::DynamicRoiSelector> selectors;
  double start = 1e9;  // a threshold keeping about 30 % or more in every view
  for (std::size_t v = 0; v < viewCount; ++v) {
    const fct::PyramidLevel& level = prepared.value()->prepared(v).pyramid.level(0);
    selectors.push_back(fct::DynamicRoiSelector::create(level.image, level.mask, window).value());
    start = std::min(start, selectors.back().selectFraction(0.3).value().threshold);
  }
  fct::RoiParameters parameters = session.document.roiParameters();
  parameters.useThreshold = true;
  parameters.varianceThreshold = start;
  session.document.setRoiParameters(parameters);
  fct::RoiStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << step.message().toStdString();

  std::vector<double> low(viewCount);
  for (std::size_t v = 0; v < viewCount; ++v) {
    low[v] = step.keptFraction(v);
    EXPECT_GE(low[v], 0.29) << step.message().toStdString();
    EXPECT_TRUE(session.xrayViews[v]->isLayerVisible(fct::RoiStepWidget::kRoiLayer));
    EXPECT_TRUE(session.xrayViews[v]->isLayerVisible(fct::RoiStepWidget::kExcludedLayer));
  }
  // Drag the slider like a user: half a decade up (threshold x 3.2).
  step.thresholdSlider()->setValue(step.thresholdSlider()->value() + fct::RoiStepWidget::kThresholdSliderSteps / 2);
  const double raised = session.document.roiParameters().varianceThreshold;
  EXPECT_NEAR(raised / start, std::sqrt(10.0), 0.1);
  double meanFraction = 0.0;
  for (std::size_t v = 0; v < viewCount; ++v) {
    const double high = step.keptFraction(v);
    EXPECT_LT(high, low[v]) << "view " << v;
    // Exactly what the Logic selector keeps at that threshold on the level-0 statistics.
    auto expected = selectors[v].selectAboveThreshold(raised);
    ASSERT_TRUE(expected.ok()) << expected.error();
    EXPECT_DOUBLE_EQ(high, expected.value().keptFraction);
    meanFraction += high / static_cast<double>(viewCount);
  }
  std::printf("threshold %.4f -> %.4f: kept fraction of view 0 %.3f -> %.3f\n", start, raised, low[0],
              step.keptFraction(0));
  EXPECT_NEAR(session.document.roiParameters().targetFraction, meanFraction, 1e-12)
      << "the registration keeps the threshold's mean fraction";
}

TEST(RoiStepWidget, ThresholdSliderIsLogarithmicAndRoundTrips) {
  EXPECT_DOUBLE_EQ(fct::RoiStepWidget::thresholdForSlider(0), 1e-4);
  const int one = fct::RoiStepWidget::sliderForThreshold(1.0);
  EXPECT_NEAR(fct::RoiStepWidget::thresholdForSlider(one), 1.0, 1e-12);
  EXPECT_EQ(fct::RoiStepWidget::sliderForThreshold(0.0), 0) << "zero and below clamp to the slider's start";
}

TEST(RoiStepWidget, TheThresholdSpinBoxReadsTheSlidersWholeRangeWithoutZeros) {
  fct::StudioDocument document;
  fct::RoiStepWidget step(&document);
  fct::RoiParameters parameters = document.roiParameters();
  parameters.useThreshold = true;
  document.setRoiParameters(parameters);
  step.thresholdSlider()->setValue(step.thresholdSlider()->minimum());
  EXPECT_EQ(step.thresholdSpin()->text(), QStringLiteral("0.0001")) << "the low end is not shown as 0.000";
  EXPECT_DOUBLE_EQ(document.roiParameters().varianceThreshold, 1e-4);
  step.thresholdSlider()->setValue(step.thresholdSlider()->maximum());
  EXPECT_DOUBLE_EQ(document.roiParameters().varianceThreshold, 10.0);
  step.thresholdSpin()->setValue(0.0);
  EXPECT_DOUBLE_EQ(step.thresholdSpin()->value(), 1e-4) << "no threshold below the slider's range";
}

TEST(RoiStepWidget, FractionSliderKeepsThatFractionAndLevelsWork) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RoiStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << step.message().toStdString();
  step.fractionSlider()->setValue(25);
  EXPECT_DOUBLE_EQ(session.document.roiParameters().targetFraction, 0.25);
  for (std::size_t v = 0; v < session.document.views().size(); ++v) {
    EXPECT_NEAR(step.keptFraction(v), 0.25, 0.01) << "within a window's worth of pixels";
  }
  step.setLevel(2);
  EXPECT_EQ(step.level(), 2);
  EXPECT_NEAR(step.keptFraction(0), 0.25, 0.05) << "coarser windows, same target";
}

TEST(RoiStepWidget, ExclusionsAreEditableAndAThresholdAboveEveryWindowSaysSo) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RoiStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << step.message().toStdString();
  fct::RoiParameters parameters = session.document.roiParameters();
  parameters.margin_px = 40;
  session.document.setRoiParameters(parameters);
  auto prepared = session.document.preparedCase();
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const fct::ValidMask& mask = prepared.value()->prepared(0).pyramid.level(0).mask;
  EXPECT_FALSE(mask.isValid(39, 96)) << "the wider margin is excluded";
  EXPECT_TRUE(std::isfinite(step.keptFraction(0)));

  parameters.useThreshold = true;
  parameters.varianceThreshold = 1e6;
  const double fractionBefore = session.document.roiParameters().targetFraction;
  session.document.setRoiParameters(parameters);
  EXPECT_EQ(step.keptFraction(0), 0.0);
  EXPECT_NE(step.message().indexOf(QStringLiteral("Lower the threshold")), -1) << step.message().toStdString();
  EXPECT_EQ(session.document.roiParameters().targetFraction, fractionBefore)
      << "the registration's fraction stays as it was";
}

TEST(RoiStepWidget, TheCutFaceMarginIsEditableDownToOffAndPreparesTheCaseAgain) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RoiStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << step.message().toStdString();
  QDoubleSpinBox* spin = step.cutFaceSpin();
  EXPECT_EQ(spin->value(), fct::RegistrationCaseOptions::kDefaultCutFaceMargin_mm) << "the CLI's default";
  const std::shared_ptr<fct::RegistrationCase> before = session.document.readyCase();
  ASSERT_NE(before, nullptr);

  spin->setValue(12.5);
  EXPECT_EQ(session.document.roiParameters().cutFaceMargin_mm, 12.5);
  EXPECT_EQ(session.document.caseOptions().value().cutFaceMargin_mm, 12.5) << "what the registration's case gets";
  EXPECT_EQ(session.document.readyCase(), nullptr) << "the case is prepared again with the new margin";

  spin->setValue(spin->minimum());
  EXPECT_EQ(spin->text(), QStringLiteral("off"));
  EXPECT_LT(session.document.roiParameters().cutFaceMargin_mm, 0.0) << "negative: every ray is compared";

  fct::RoiParameters parameters = session.document.roiParameters();
  parameters.cutFaceMargin_mm = -5.0;  // off, as a session file may say it
  session.document.setRoiParameters(parameters);
  EXPECT_EQ(spin->text(), QStringLiteral("off"));
  step.fractionSlider()->setValue(step.fractionSlider()->value() + 5);
  EXPECT_EQ(session.document.roiParameters().cutFaceMargin_mm, -5.0) << "another control leaves the value as it is";
  parameters = session.document.roiParameters();
  parameters.cutFaceMargin_mm = 3.0;
  session.document.setRoiParameters(parameters);
  EXPECT_EQ(spin->value(), 3.0) << "the spin box follows the document";
}

TEST(RoiStepWidget, SwitchingToTheThresholdStartsWhereTheFractionWas) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RoiStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << step.message().toStdString();
  step.fractionSlider()->setValue(15);
  const double before = step.keptFraction(0);
  auto* thresholdRadio = step.findChild<QRadioButton*>(QString(), Qt::FindChildrenRecursively);
  ASSERT_NE(thresholdRadio, nullptr);
  ASSERT_EQ(thresholdRadio->text(), QStringLiteral("Variance threshold"));
  thresholdRadio->click();
  EXPECT_TRUE(session.document.roiParameters().useThreshold);
  EXPECT_NEAR(step.keptFraction(0), before, 0.08) << "about the same pixels as before the switch";
  EXPECT_GT(step.keptFraction(0), 0.0);
}

TEST(RoiStepWidget, CalibrationSpheresAreExcludedAndOutlined) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  std::vector<fct::RegistrationView> views = session.document.views();
  views[0].spheres.push_back(fct::PixelCircle{Eigen::Vector2d(60.0, 70.0), 6.0});
  session.document.setViews(views);
  fct::RoiStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << step.message().toStdString();
  auto prepared = session.document.preparedCase();
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  EXPECT_FALSE(prepared.value()->prepared(0).pyramid.level(0).mask.isValid(60, 70)) << "the sphere is excluded";
  EXPECT_TRUE(session.xrayViews[0]->isLayerVisible(fct::RoiStepWidget::kSphereLayer));
  EXPECT_TRUE(std::isfinite(step.keptFraction(0)));
  step.setActive(false);
  EXPECT_FALSE(session.xrayViews[0]->isLayerVisible(fct::RoiStepWidget::kSphereLayer)) << "hidden when inactive";
}

TEST(RoiStepWidget, SaysWhichMaskExcludedEachPatch) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::RoiParameters parameters = session.document.roiParameters();
  parameters.margin_px = 10;
  session.document.setRoiParameters(parameters);
  fct::RoiStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << step.message().toStdString();
  const QString text = step.exclusionText();
  const QString view = QString::fromStdString(session.document.views()[0].name);
  EXPECT_TRUE(text.contains(view + QStringLiteral(" excluded:"))) << text.toStdString();
  EXPECT_TRUE(text.contains(QStringLiteral("margin "))) << text.toStdString();
  EXPECT_TRUE(text.contains(QStringLiteral("outside the field")));
  EXPECT_TRUE(text.contains(QStringLiteral("spheres")));
  // The 10-pixel margin of a 192 x 192 view is 19.3 % of it; the margin share says so (the field may take more).
  EXPECT_FALSE(text.contains(QStringLiteral("margin 0.0 %"))) << text.toStdString();
}
