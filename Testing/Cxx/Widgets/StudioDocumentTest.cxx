#include <gtest/gtest.h>

#include <QSignalSpy>

#include <fstream>

#include "StudioTestCase.h"
#include "TestSupport.h"
#include "Widgets/StudioDocument.h"

namespace {

using fct::StudioDocument;

TEST(StudioDocument, LoadsTheBuiltinCaseWithGroundTruthAndSignals) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  QSignalSpy ctSpy(&document, &StudioDocument::ctChanged);
  QSignalSpy viewsSpy(&document, &StudioDocument::viewsChanged);
  QSignalSpy modifiedSpy(&document, &StudioDocument::modifiedChanged);
  EXPECT_FALSE(document.isModified());

  const fct::Status ct = document.loadCt(dir / "ct.nrrd");
  ASSERT_TRUE(ct.ok()) << ct.error();
  const fct::Status views = document.loadViews(dir / "views.json");
  ASSERT_TRUE(views.ok()) << views.error();

  ASSERT_TRUE(document.ct());
  EXPECT_EQ(document.ct()->dims(), Eigen::Vector3i(96, 96, 72));
  ASSERT_EQ(document.views().size(), 2u);
  EXPECT_EQ(document.views()[0].name, "ap");
  EXPECT_EQ(document.views()[0].xray.cols, 192);
  EXPECT_EQ(document.viewIndex("lateral"), 1);
  EXPECT_EQ(document.viewIndex("nope"), -1);
  EXPECT_TRUE(document.truthPose().has_value());
  EXPECT_EQ(ctSpy.count(), 1);
  EXPECT_EQ(viewsSpy.count(), 1);
  EXPECT_TRUE(document.isModified());
  ASSERT_EQ(modifiedSpy.count(), 1);
  EXPECT_TRUE(modifiedSpy.at(0).at(0).toBool());
}

TEST(StudioDocument, BadViewFileFailsWithTheFileNameAndKeepsTheViews) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  ASSERT_TRUE(document.loadViews(dir / "views.json").ok());
  const auto bad = fct::test::scratchDir() / "broken_views.json";
  std::ofstream(bad) << "{\"views\": [ {\"name\": \"ap\", \"detector\": {\"cols\": 0} ]";
  QSignalSpy viewsSpy(&document, &StudioDocument::viewsChanged);

  const fct::Status status = document.loadViews(bad);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("broken_views.json"), std::string::npos) << status.error();
  EXPECT_EQ(document.views().size(), 2u);
  EXPECT_EQ(document.viewFilePath(), dir / "views.json");
  EXPECT_EQ(viewsSpy.count(), 0);
}

TEST(StudioDocument, MissingCtAndXrayWithoutGeometryAreRefusedWithAdvice) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  const fct::Status ct = document.loadCt(dir / "no_such_ct.nrrd");
  ASSERT_FALSE(ct.ok());
  EXPECT_FALSE(document.ct());
  const fct::Status xray = document.addXrayFile(dir / "ap.png");
  ASSERT_FALSE(xray.ok());
  EXPECT_NE(xray.error().find("view file"), std::string::npos) << xray.error();
  EXPECT_TRUE(document.views().empty());
  EXPECT_FALSE(document.isModified());
}

TEST(StudioDocument, RoiParametersSignalOnlyRealChanges) {
  StudioDocument document;
  QSignalSpy spy(&document, &StudioDocument::roiParametersChanged);
  fct::RoiParameters roi = document.roiParameters();
  document.setRoiParameters(roi);
  EXPECT_EQ(spy.count(), 0);
  EXPECT_FALSE(document.isModified());
  roi.targetFraction = 0.2;
  document.setRoiParameters(roi);
  EXPECT_EQ(spy.count(), 1);
  EXPECT_DOUBLE_EQ(document.roiParameters().targetFraction, 0.2);
  EXPECT_TRUE(document.isModified());
}

TEST(StudioDocument, PreparedCaseNeedsCtAndViewsAndIsKeptUntilTheyChange) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  auto none = document.preparedCase();
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().find("Data step"), std::string::npos);
  ASSERT_TRUE(document.loadCt(dir / "ct.nrrd").ok());
  ASSERT_TRUE(document.loadViews(dir / "views.json").ok());
  auto first = document.preparedCase();
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_EQ(first.value()->viewCount(), 2u);
  auto again = document.preparedCase();
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(first.value().get(), again.value().get());
  fct::RoiParameters roi = document.roiParameters();
  roi.margin_px = 12;
  document.setRoiParameters(roi);
  auto rebuilt = document.preparedCase();
  ASSERT_TRUE(rebuilt.ok());
  EXPECT_NE(first.value().get(), rebuilt.value().get());
}

TEST(StudioDocument, TheCaseIsPreparedInTheBackgroundAndAnInputChangeOrCancelDropsIt) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  QSignalSpy finished(&document, &StudioDocument::casePreparationFinished);
  document.prepareCaseInBackground();
  ASSERT_TRUE(finished.wait(10000)) << "it cannot start without data, and says so";
  EXPECT_FALSE(finished.last().at(0).toBool());
  EXPECT_TRUE(finished.last().at(1).toString().contains(QStringLiteral("Data step")));
  ASSERT_TRUE(document.loadCt(dir / "ct.nrrd").ok());
  ASSERT_TRUE(document.loadViews(dir / "views.json").ok());

  QSignalSpy progressed(&document, &StudioDocument::casePreparationProgressed);
  finished.clear();
  document.prepareCaseInBackground();
  EXPECT_TRUE(document.isPreparingCase());
  EXPECT_EQ(document.readyCase(), nullptr) << "nothing is ready while it runs";
  ASSERT_TRUE(finished.wait(60000));
  EXPECT_TRUE(finished.last().at(0).toBool()) << finished.last().at(1).toString().toStdString();
  ASSERT_NE(document.readyCase(), nullptr);
  EXPECT_FALSE(document.isPreparingCase());
  EXPECT_GE(progressed.count(), 1) << "the steps were reported";
  EXPECT_EQ(document.preparedCase().value().get(), document.readyCase().get()) << "the same case for everyone";

  // An exclusion changed during a preparation: that preparation is dropped, with the reason.
  fct::RoiParameters roi = document.roiParameters();
  roi.margin_px = 12;
  document.setRoiParameters(roi);
  EXPECT_EQ(document.readyCase(), nullptr);
  finished.clear();
  document.prepareCaseInBackground();
  roi.margin_px = 14;
  document.setRoiParameters(roi);
  EXPECT_FALSE(document.isPreparingCase());
  ASSERT_TRUE(finished.wait(10000));
  EXPECT_FALSE(finished.last().at(0).toBool());
  EXPECT_TRUE(finished.last().at(1).toString().contains(QStringLiteral("changed"))) << finished.last().at(1).toString().toStdString();

  // Cancelled: it ends with an error and no case; the next request prepares again.
  finished.clear();
  document.prepareCaseInBackground();
  document.cancelCasePreparation();
  ASSERT_TRUE(finished.wait(60000));
  EXPECT_FALSE(finished.last().at(0).toBool());
  EXPECT_TRUE(finished.last().at(1).toString().contains(QStringLiteral("cancelled"))) << finished.last().at(1).toString().toStdString();
  EXPECT_EQ(document.readyCase(), nullptr);
  EXPECT_TRUE(document.preparedCase().ok()) << "a later request prepares it";
}

TEST(StudioDocument, ClearEmptiesEverythingAndIsNotModified) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  ASSERT_TRUE(document.loadViews(dir / "views.json").ok());
  document.setInitialPose(Eigen::Isometry3d::Identity(), QStringLiteral("test"));
  document.clear();
  EXPECT_TRUE(document.views().empty());
  EXPECT_FALSE(document.initialPose());
  EXPECT_FALSE(document.truthPose());
  EXPECT_FALSE(document.isModified());
}

}  // namespace
