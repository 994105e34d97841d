// StudyTrialCase: one trial of a study written as a case folder holds the X-rays, true pose and start pose the study's
// trial uses, the registration CT when it differs from the study's CT file, and bad requests write nothing.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyRunner.h"
#include "Evaluation/StudyTrialCase.h"
#include "Evaluation/StudyXraySource.h"
#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "IO/Xray/XrayLoader.h"
#include "Registration/RegistrationCase.h"
#include "Simulation/PhantomBuilder.h"
#include "TestSupport.h"

namespace {

/// The quick table2 study on a small phantom CT labelled "phantom", on a small coarse detector.
struct QuickStudy {
  fct::StudyDefinition study;
  std::vector<fct::StudyCt> cts;
};

QuickStudy quickStudy() {
  fct::PhantomOptions phantom;
  phantom.dims = Eigen::Vector3i(60, 60, 40);
  phantom.spacing_mm = 2.0;  // finer than the realistic scenario's slices
  QuickStudy q;
  q.cts.push_back(fct::StudyCt{"phantom", fct::PhantomBuilder::build(phantom).value()});
  q.study = fct::StudyCatalog::define("table2", true, {"phantom"}, fct::DrrMethod::Siddon).value();
  q.study.setup.detector.cols = q.study.setup.detector.rows = 64;
  q.study.setup.detector.pixelSpacing_mm = 4.0;
  fct::StudyRunner::resolveSliceSpacings(q.study, q.cts);
  return q;
}

/// The largest absolute difference between two images of the same size (infinity when the sizes differ).
double maxDifference(const fct::XrayImage& a, const fct::XrayImage& b) {
  if (a.cols != b.cols || a.rows != b.rows) return INFINITY;
  double largest = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    largest = std::max(largest, static_cast<double>(std::abs(a.pixels[i] - b.pixels[i])));
  }
  return largest;
}

}  // namespace

TEST(StudyTrialCase, WritesTheTrialsOwnXraysTruthAndStartAndTheCoarserRegistrationCt) {
  const QuickStudy q = quickStudy();
  const auto realistic = std::find_if(q.study.conditions.begin(), q.study.conditions.end(),
                                      [](const fct::StudyCondition& c) { return c.scenario == "realistic"; });
  ASSERT_NE(realistic, q.study.conditions.end());
  const int trial = 1;
  const std::filesystem::path folder = fct::test::scratchDir() / "trial";
  const auto files = fct::StudyTrialCase::write(q.study, q.cts, realistic->name, trial, {}, folder);
  ASSERT_TRUE(files.ok()) << files.error();

  // The same truth, X-rays and start as StudyRunner's trial (seed = setup seed + trial).
  const std::uint32_t seed = q.study.setup.seed + trial;
  const fct::BoneSurface bone = fct::BoneSurface::extract(q.cts[0].volume).value();
  const Eigen::Isometry3d T_truth = fct::StudyRunner::trialTruthPose(bone, seed);
  EXPECT_TRUE(fct::PoseFile::read(files.value().truthFile).value().isApprox(T_truth, 1e-9));
  const auto views = fct::ViewFile::read(files.value().viewFile);
  ASSERT_TRUE(views.ok()) << views.error();
  ASSERT_EQ(static_cast<int>(views.value().size()), realistic->viewCount);
  const auto expected = fct::StudyXraySource::simulate(q.cts[0].volume, views.value(), T_truth,
                                                       fct::StudyRunner::trialXraySeed(seed), true);
  ASSERT_TRUE(expected.ok()) << expected.error();
  std::vector<fct::Camera> cameras;
  for (std::size_t v = 0; v < views.value().size(); ++v) {
    const auto written = fct::XrayLoader::load(views.value()[v].imagePath);
    ASSERT_TRUE(written.ok()) << written.error();
    EXPECT_LE(maxDifference(written.value(), expected.value()[v].xray), 0.5) << "view " << v << ": 16-bit rounding only";
    cameras.push_back(views.value()[v].camera);
  }
  double target_mm = 0.0;
  const Eigen::Isometry3d T_start = fct::StudyRunner::startPose(*realistic, bone, T_truth, cameras, seed, target_mm).value();
  EXPECT_TRUE(fct::PoseFile::read(files.value().startFile).value().isApprox(T_start, 1e-9));
  EXPECT_NEAR(files.value().initialStre_mm, target_mm, 0.05 * target_mm);

  // The realistic scenario registers on thicker slices: that CT is written beside the X-rays.
  ASSERT_TRUE(files.value().ctWritten);
  const auto ct = fct::VolumeFileIO::read(files.value().registrationCt);
  ASSERT_TRUE(ct.ok()) << ct.error();
  const auto degraded = fct::StudyXraySource::registrationCt(q.cts[0].volume, realistic->sliceSpacing_mm).value();
  EXPECT_EQ(ct.value().dims(), degraded.dims());
  EXPECT_DOUBLE_EQ(files.value().cutFaceMargin_mm, fct::RegistrationCaseOptions::kDefaultCutFaceMargin_mm);
}

TEST(StudyTrialCase, NamesTheStudyCtFileWhenTheTrialRegistersOnIt) {
  const QuickStudy q = quickStudy();
  const auto ideal = std::find_if(q.study.conditions.begin(), q.study.conditions.end(),
                                  [](const fct::StudyCondition& c) { return c.scenario == "ideal"; });
  ASSERT_NE(ideal, q.study.conditions.end());
  const std::filesystem::path folder = fct::test::scratchDir();
  const auto files = fct::StudyTrialCase::write(q.study, q.cts, ideal->name, 0, "/data/phantom.nrrd", folder);
  ASSERT_TRUE(files.ok()) << files.error();
  EXPECT_FALSE(files.value().ctWritten);
  EXPECT_EQ(files.value().registrationCt, std::filesystem::path("/data/phantom.nrrd"));
  EXPECT_FALSE(std::filesystem::exists(folder / "ct_registration.nrrd"));
}

TEST(StudyTrialCase, RejectsAnUnknownConditionOrTrialAndWritesNothing) {
  const QuickStudy q = quickStudy();
  const std::filesystem::path folder = fct::test::scratchDir();
  const auto unknown = fct::StudyTrialCase::write(q.study, q.cts, "phantom/nonsense", 0, {}, folder);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("no condition 'phantom/nonsense'"), std::string::npos) << unknown.error();
  EXPECT_NE(unknown.error().find(q.study.conditions.front().name), std::string::npos) << "lists the conditions";
  const fct::StudyCondition& first = q.study.conditions.front();
  const auto outside = fct::StudyTrialCase::write(q.study, q.cts, first.name, first.trials, {}, folder);
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.error().find(fmt::format("trials 0 to {}", first.trials - 1)), std::string::npos) << outside.error();
  const auto negative = fct::StudyTrialCase::write(q.study, q.cts, first.name, -1, {}, folder);
  EXPECT_FALSE(negative.ok());
  EXPECT_TRUE(fct::test::folderEntries(folder).empty());
}
