// fluoroct views --from-dicom: one view per X-ray DICOM file from its C-arm tags; missing tags named with the view-file
// key and the flag that supply them.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "../Core/SyntheticXrayDicom.h"
#include "IO/Project/ViewFile.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

/// An XA file with SID, pixel spacing and angles; SOD only when `withSod`.
fs::path xaFile(const fs::path& path, bool withSod) {
  fct::test::SyntheticXray x;
  x.cols = 64;
  x.rows = 48;
  DcmFileFormat file = x.build();
  fct::test::putCarmTags(*file.getDataset(), 1100, 750, 0.4, 0.4, 25, -5);
  if (!withSod) file.getDataset()->findAndDeleteElement(DCM_DistanceSourceToPatient);
  file.getDataset()->putAndInsertString(DCM_PatientOrientation, "R\\F");
  return fct::test::save(file, path);
}

bool oneErrorLine(const fct::test::ProcessResult& run) {
  return run.exitCode == 2 && run.err.rfind("error: ", 0) == 0 && std::count(run.err.begin(), run.err.end(), '\n') == 1;
}

}  // namespace

TEST(ViewsCommand, FromDicomWritesOneViewPerFileNamedAfterIt) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path ap = xaFile(dir / "first.dcm", true);
  const fs::path other = xaFile(dir / "second.dcm", true);
  const auto run = fct::test::runCli(
      fmt::format("views --from-dicom '{}' '{}' --out '{}'", ap.string(), other.string(), (dir / "v.json").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("2 views from DICOM geometry tags"), std::string::npos) << run.out;
  auto views = fct::ViewFile::read(dir / "v.json");
  ASSERT_TRUE(views) << views.error();
  ASSERT_EQ(views.value().size(), 2u);
  EXPECT_EQ(views.value()[0].name, "first");
  EXPECT_EQ(views.value()[0].imagePath, ap);
  EXPECT_DOUBLE_EQ(views.value()[1].camera.intrinsics().sourceToDetector_mm, 1100.0);
  EXPECT_NEAR(views.value()[1].camera.sourcePosition_world_mm().norm(), 750.0, 1e-6);
}

TEST(ViewsCommand, FromDicomNamesTheMissingTagItsViewFileKeyAndTheFlag) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path xa = xaFile(dir / "nosod.dcm", false);
  const std::string out = (dir / "v.json").string();
  const auto refused = fct::test::runCli(fmt::format("views --from-dicom '{}' --out '{}'", xa.string(), out));
  EXPECT_TRUE(oneErrorLine(refused)) << refused.err;
  for (const char* part : {"nosod.dcm", "DistanceSourceToPatient (0018,1111)", "source_to_patient_mm", "--sod-mm"}) {
    EXPECT_NE(refused.err.find(part), std::string::npos) << part << " in " << refused.err;
  }
  EXPECT_FALSE(fs::exists(out));

  const auto supplied =
      fct::test::runCli(fmt::format("views --from-dicom '{}' --sod-mm 700 --out '{}'", xa.string(), out));
  ASSERT_EQ(supplied.exitCode, 0) << supplied.err;
  auto views = fct::ViewFile::read(out);
  ASSERT_TRUE(views) << views.error();
  EXPECT_NEAR(views.value()[0].camera.sourcePosition_world_mm().norm(), 700.0, 1e-6);

  const auto frameWithoutDicom = fct::test::runCli(fmt::format("views --ct '{}' --frame 2 --out '{}'", xa.string(), out));
  EXPECT_EQ(frameWithoutDicom.exitCode, 2) << frameWithoutDicom.err;
  const auto neither = fct::test::runCli(fmt::format("views --out '{}'", out));
  EXPECT_TRUE(oneErrorLine(neither)) << neither.err;
  EXPECT_NE(neither.err.find("--from-dicom"), std::string::npos) << neither.err;
}
