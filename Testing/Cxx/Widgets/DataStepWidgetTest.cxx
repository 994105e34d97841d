#include <gtest/gtest.h>

#include <QHeaderView>
#include <QSignalSpy>
#include <QTableWidget>
#include <QTest>

#include <fstream>

#include "../Core/SyntheticXrayDicom.h"
#include "IO/Project/DicomViewBuilder.h"
#include "StudioTestCase.h"
#include "TestSupport.h"
#include "Widgets/DataStepWidget.h"
#include "Widgets/StudioDocument.h"

namespace {

using fct::DataStepWidget;
using fct::StudioDocument;

/// Waits for the step's background load and returns (ok, message).
std::pair<bool, QString> waitForLoad(QSignalSpy& spy) {
  if (spy.isEmpty() && !spy.wait(20000)) return {false, QStringLiteral("timed out")};
  const QList<QVariant> args = spy.takeFirst();
  return {args.at(0).toBool(), args.at(1).toString()};
}

TEST(DataStepWidget, LoadsTheBuiltinCaseFolderAndDescribesIt) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  DataStepWidget step(&document);
  QSignalSpy finished(&step, &DataStepWidget::loadFinished);
  step.openCaseFolder(QString::fromStdString(dir.string()));
  const auto [ok, message] = waitForLoad(finished);
  ASSERT_TRUE(ok) << message.toStdString();
  EXPECT_FALSE(step.isBusy());
  ASSERT_TRUE(document.ct());
  EXPECT_EQ(document.views().size(), 2u);
  EXPECT_TRUE(document.initialPose().has_value());
  EXPECT_TRUE(document.truthPose().has_value());
  const QString summary = step.summaryText();
  EXPECT_TRUE(summary.contains(QStringLiteral("96 × 96 × 72 voxels"))) << summary.toStdString();
  EXPECT_TRUE(summary.contains(QStringLiteral("Initial pose from pose file initial_pose.json"))) << summary.toStdString();
  EXPECT_EQ(document.suggestedPath(QStringLiteral("pose.tfm")), QString::fromStdString((dir / "pose.tfm").string()))
      << "export dialogs start in the case folder";
  EXPECT_TRUE(summary.contains(QStringLiteral("Ground truth"))) << summary.toStdString();
  EXPECT_TRUE(step.errorText().isEmpty());
}

TEST(DataStepWidget, ViewsFromDicomTagsAddsOneViewPerFileWithAMirroredImageFlipped) {
  const auto dir = fct::test::scratchDir();
  auto xa = [&dir](const char* name, const char* orientation) {
    fct::test::SyntheticXray x;
    x.cols = 6;
    x.rows = 4;
    for (int i = 0; i < 24; ++i) x.samples.push_back(static_cast<Uint16>(100 + i));
    DcmFileFormat file = x.build();
    fct::test::putCarmTags(*file.getDataset(), 1000, 700, 0.5, 0.5, 20, 0);
    file.getDataset()->putAndInsertString(DCM_PatientOrientation, orientation);
    return fct::test::save(file, dir / name);
  };
  const auto fromSource = xa("source.dcm", "R\\F");
  const auto displayed = xa("displayed.dcm", "L\\F");
  StudioDocument document;
  DataStepWidget step(&document);
  QSignalSpy finished(&step, &DataStepWidget::loadFinished);
  step.addXrayFiles({QString::fromStdString(fromSource.string()), QString::fromStdString(displayed.string())});
  const auto [ok, message] = waitForLoad(finished);
  ASSERT_TRUE(ok) << message.toStdString() << " / " << step.errorText().toStdString();
  ASSERT_EQ(document.views().size(), 2u);
  EXPECT_EQ(document.views()[0].name, "source");
  EXPECT_FLOAT_EQ(document.views()[0].xray.at(0, 0), 100.0f);
  EXPECT_FLOAT_EQ(document.views()[1].xray.at(0, 0), 105.0f) << "the mirrored image is flipped left-right";
  auto expected = fct::DicomViewBuilder::build({displayed});
  ASSERT_TRUE(expected) << expected.error();
  EXPECT_TRUE(document.views()[1].camera.P_px_from_world().isApprox(expected.value()[0].camera.P_px_from_world()));

  const auto png = dir / "plain.png";
  std::ofstream(png) << "not really a PNG";
  step.addXrayFiles({QString::fromStdString(png.string())});
  const auto [refused, why] = waitForLoad(finished);
  EXPECT_FALSE(refused);
  EXPECT_TRUE(why.contains(QStringLiteral("view file"))) << why.toStdString();
  EXPECT_EQ(document.views().size(), 2u);
}

TEST(DataStepWidget, NonDicomFolderShowsAMessageAndKeepsTheCt) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  ASSERT_TRUE(document.loadCt(dir / "ct.nrrd").ok());
  const auto ct = document.ct();
  const auto folder = fct::test::scratchDir();
  std::ofstream(folder / "notes.txt") << "not a DICOM file";
  DataStepWidget step(&document);
  QSignalSpy finished(&step, &DataStepWidget::loadFinished);
  step.openCt(QString::fromStdString(folder.string()));
  const auto [ok, message] = waitForLoad(finished);
  EXPECT_FALSE(ok);
  EXPECT_TRUE(message.contains(QStringLiteral("Could not open the DICOM folder"))) << message.toStdString();
  EXPECT_EQ(step.errorText(), message);
  EXPECT_EQ(document.ct(), ct);
  EXPECT_EQ(step.seriesChoiceCount(), 0);
}

TEST(DataStepWidget, ViewFileWithErrorsShowsTheKeyAndKeepsTheViews) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  ASSERT_TRUE(document.loadViews(dir / "views.json").ok());
  const auto bad = fct::test::scratchDir() / "views.json";
  std::ofstream(bad) << R"({"views": [{"name": "ap", "image": {"path": ")" << (dir / "ap.png").string() << R"("},
    "detector": {"cols": 192, "rows": 144, "pixel_spacing_mm": [1.6, 1.6]},
    "source_to_detector_mm": -5, "principal_point_px": [95.5, 71.5],
    "T_world_from_camera": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]})";
  DataStepWidget step(&document);
  QSignalSpy finished(&step, &DataStepWidget::loadFinished);
  step.openViewFile(QString::fromStdString(bad.string()));
  const auto [ok, message] = waitForLoad(finished);
  EXPECT_FALSE(ok);
  EXPECT_TRUE(message.contains(QStringLiteral("source_to_detector_mm"))) << message.toStdString();
  EXPECT_EQ(document.views().size(), 2u);
  EXPECT_EQ(document.viewFilePath(), dir / "views.json");
}

TEST(DataStepWidget, CaseFolderWithoutCtNamesWhatIsMissing) {
  const auto folder = fct::test::scratchDir();
  auto files = DataStepWidget::findCaseFiles(folder);
  ASSERT_FALSE(files.ok());
  EXPECT_NE(files.error().find("ct.nrrd"), std::string::npos) << files.error();
  StudioDocument document;
  DataStepWidget step(&document);
  QSignalSpy finished(&step, &DataStepWidget::loadFinished);
  step.openCaseFolder(QString::fromStdString(folder.string()));
  ASSERT_EQ(finished.count(), 1);  // refused at once, nothing started
  EXPECT_FALSE(finished.at(0).at(0).toBool());
  EXPECT_FALSE(document.isModified());
}

}  // namespace

namespace {

TEST(DataStepWidget, OpensARealDicomFolderThroughTheSeriesChooser) {
  FCT_REQUIRE_DATA("ct/head_ge_irregular");
  StudioDocument document;
  DataStepWidget step(&document);
  QSignalSpy finished(&step, &DataStepWidget::loadFinished);
  step.openCt(QString::fromStdString((fct::test::dataDir() / "ct/head_ge_irregular").string()));
  auto [ok, message] = waitForLoad(finished);
  ASSERT_TRUE(ok) << message.toStdString();
  if (step.seriesChoiceCount() > 1) {  // several series: the chooser is shown, nothing loaded yet
    EXPECT_FALSE(document.ct());
    step.chooseSeries(0);
    step.loadChosenSeries();
    std::tie(ok, message) = waitForLoad(finished);
    ASSERT_TRUE(ok) << message.toStdString();
  }
  ASSERT_TRUE(document.ct());
  EXPECT_GT(document.ct()->voxelCount(), 0u);
  // An irregular series is resampled with a warning, which the step shows in words.
  EXPECT_FALSE(document.ctWarnings().empty());
  EXPECT_TRUE(step.summaryText().contains(QStringLiteral("CT warnings"))) << step.summaryText().toStdString();
}

TEST(DataStepWidget, OpensThePelvisVolumeFile) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  StudioDocument document;
  DataStepWidget step(&document);
  QSignalSpy finished(&step, &DataStepWidget::loadFinished);
  step.openCt(QString::fromStdString((fct::test::dataDir() / "ct/pelvis_totalseg.nii.gz").string()));
  const auto [ok, message] = waitForLoad(finished);
  ASSERT_TRUE(ok) << message.toStdString();
  ASSERT_TRUE(document.ct());
  EXPECT_TRUE(step.summaryText().contains(QStringLiteral("pelvis_totalseg.nii.gz")));
}

TEST(DataStepWidget, TheSidColumnIsNotClippedInTheStepsWidth) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_FALSE(dir.empty());
  StudioDocument document;
  DataStepWidget step(&document);
  step.resize(360, 600);  // the module panel's minimum width
  step.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&step));
  ASSERT_TRUE(document.loadViews(dir / "views.json").ok());
  QTest::qWait(20);
  auto* table = step.findChild<QTableWidget*>();
  ASSERT_NE(table, nullptr);
  const QHeaderView* header = table->horizontalHeader();
  const int sid = header->logicalIndex(4);
  EXPECT_EQ(table->horizontalHeaderItem(sid)->text(), QStringLiteral("SID (mm)"));
  EXPECT_LE(header->sectionViewportPosition(sid) + header->sectionSize(sid), table->viewport()->width())
      << "the SID column ends inside the table";
  EXPECT_GE(header->sectionSize(sid), header->fontMetrics().horizontalAdvance(QStringLiteral("SID (mm)")));
}

}  // namespace
