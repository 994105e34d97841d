#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "Base/JsonDocument.h"
#include "Registration/RegistrationResultJson.h"
#include "StudioTestCase.h"
#include "TestSupport.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/StudioSession.h"

namespace {

using fct::StudioDocument;
using fct::StudioSession;

/// A document with every part set: the built-in case, landmarks, poses, ROI and options, a result.
void fillDocument(StudioDocument& d) {
  const auto dir = fct::test::builtinCaseDir();
  ASSERT_TRUE(d.loadCt(dir / "ct.nrrd").ok());
  ASSERT_TRUE(d.loadViews(dir / "views.json").ok());
  fct::Landmarks landmarks;
  landmarks.ct = {{"L1", {1.5, -2.0, 3.25}}, {"L2", {10.0, 20.0, -30.0}}};
  landmarks.imageByView["ap"] = {{"L1", {12.5, 40.0}}};
  landmarks.imageByView["lateral"] = {{"L2", {100.0, 70.25}}};
  d.setLandmarks(landmarks);
  Eigen::Isometry3d initial = Eigen::Isometry3d::Identity();
  initial.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, 2, 3).normalized()));
  initial.translation() = Eigen::Vector3d(4, -5, 6);
  d.setInitialPose(initial, QStringLiteral("landmarks (2 pairs)"));
  fct::RoiParameters roi;
  roi.windowSize = 9;
  roi.useThreshold = true;
  roi.varianceThreshold = 1.7;
  roi.margin_px = 5;
  roi.detectFieldOfView = false;
  roi.cutFaceMargin_mm = 12.5;
  d.setRoiParameters(roi);
  d.setRegistrationOptions({"paper", 42, "raycast", 1.25});
  fct::RegistrationResult result;
  result.T_initial = initial;
  result.T_world_from_ct = initial * Eigen::Translation3d(1, 1, 1);
  result.rotationCentre_ct_mm = {0.5, 1.5, 2.5};
  result.totalDrrs = 1234;
  result.totalSeconds = 5.5;
  result.drrMethod = "raycast";
  result.viewNames = {"ap", "lateral"};
  result.cancelled = true;
  fct::StageReport stage;
  stage.name = "coarse";
  stage.metric = fct::SimilarityMetric::Ncc;
  stage.level = 2;
  stage.search = fct::SearchStrategy::Genetic;
  stage.similarity = 0.75;
  stage.keptFraction = {0.1, 0.2};
  result.stages.push_back(stage);
  result.schedule = fct::RegistrationSchedule::builtin("fast").value();
  d.addResult(result);
  d.setResultVerdict(fct::ResultVerdict::Rejected);
  result.cancelled = false;
  result.totalDrrs = 99;
  d.addResult(result);
  d.setResultVerdict(fct::ResultVerdict::Accepted);
  d.setCurrentResult(0);
  d.setXrayWindow("ap", {1200.0, 30000.0});
}

void expectSameDocument(const StudioDocument& a, const StudioDocument& b) {
  ASSERT_TRUE(a.ct() && b.ct());
  EXPECT_EQ(a.ct()->dims(), b.ct()->dims());
  EXPECT_EQ(a.ct()->voxels(), b.ct()->voxels());
  ASSERT_EQ(a.views().size(), b.views().size());
  for (std::size_t v = 0; v < a.views().size(); ++v) {
    EXPECT_EQ(a.views()[v].name, b.views()[v].name);
    EXPECT_EQ(a.views()[v].xray.pixels, b.views()[v].xray.pixels);
    EXPECT_TRUE(a.views()[v].camera.P_px_from_world().isApprox(b.views()[v].camera.P_px_from_world()));
  }
  ASSERT_EQ(a.landmarks().ct.size(), b.landmarks().ct.size());
  for (std::size_t i = 0; i < a.landmarks().ct.size(); ++i) {
    EXPECT_EQ(a.landmarks().ct[i].name, b.landmarks().ct[i].name);
    EXPECT_TRUE(a.landmarks().ct[i].p_ct_mm.isApprox(b.landmarks().ct[i].p_ct_mm));
  }
  ASSERT_EQ(a.landmarks().imageByView.size(), b.landmarks().imageByView.size());
  EXPECT_TRUE(b.landmarks().imageByView.at("lateral").at(0).uv_px.isApprox(Eigen::Vector2d(100.0, 70.25)));
  ASSERT_TRUE(b.initialPose());
  EXPECT_TRUE(a.initialPose()->isApprox(*b.initialPose(), 1e-12));
  EXPECT_EQ(a.initialPoseSource(), b.initialPoseSource());
  EXPECT_EQ(a.roiParameters(), b.roiParameters());
  EXPECT_EQ(a.registrationOptions(), b.registrationOptions());
  ASSERT_TRUE(b.result());
  EXPECT_TRUE(a.result()->T_world_from_ct.isApprox(b.result()->T_world_from_ct, 1e-12));
  EXPECT_EQ(b.result()->totalDrrs, 1234);
  EXPECT_TRUE(b.result()->cancelled);
  ASSERT_EQ(b.result()->stages.size(), 1u);
  EXPECT_EQ(b.result()->stages[0].keptFraction, (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(b.result()->schedule.stages.size(), a.result()->schedule.stages.size());
  EXPECT_EQ(b.resultVerdict(), fct::ResultVerdict::Rejected);
  ASSERT_EQ(b.results().size(), 2u) << "the whole history";
  EXPECT_EQ(b.currentResultIndex(), 0);
  EXPECT_EQ(b.results()[1].verdict, fct::ResultVerdict::Accepted);
  EXPECT_EQ(b.results()[1].result.totalDrrs, 99);
  EXPECT_EQ(b.xrayWindows(), a.xrayWindows());
  ASSERT_TRUE(b.truthPose());
  EXPECT_TRUE(a.truthPose()->isApprox(*b.truthPose(), 1e-12));
}

TEST(StudioSession, SaveThenOpenGivesTheSameDocument) {
  ASSERT_FALSE(fct::test::builtinCaseDir().empty());
  StudioDocument original;
  fillDocument(original);
  const auto path = fct::test::scratchDir() / "case.fctsession.json";
  const fct::Status saved = StudioSession::save(original, path);
  ASSERT_TRUE(saved.ok()) << saved.error();
  EXPECT_FALSE(original.isModified());
  EXPECT_EQ(original.sessionPath(), path);

  StudioDocument reopened;
  const fct::Status opened = StudioSession::open(reopened, path);
  ASSERT_TRUE(opened.ok()) << opened.error();
  expectSameDocument(original, reopened);
  EXPECT_FALSE(reopened.isModified());
  EXPECT_EQ(reopened.sessionPath(), path);
}

TEST(StudioSession, SavesEachResultAsTheObjectOfResultFiles) {
  ASSERT_FALSE(fct::test::builtinCaseDir().empty());
  StudioDocument document;
  fillDocument(document);
  const auto path = fct::test::scratchDir() / "case.fctsession.json";
  ASSERT_TRUE(StudioSession::save(document, path).ok());
  auto json = fct::JsonDocument::parse(path);
  ASSERT_TRUE(json.ok()) << json.error();
  EXPECT_EQ(json.value()["version"], 3);
  EXPECT_EQ(json.value()["current_result"], 0);
  ASSERT_EQ(json.value()["results"].size(), 2u);
  EXPECT_EQ(json.value()["results"][1]["verdict"], "accepted");
  const nlohmann::json& result = json.value()["results"][0];
  EXPECT_EQ(result["format"], fct::RegistrationResultJson::kFormat);
  EXPECT_EQ(result["verdict"], "rejected");
  auto read = fct::RegistrationResultJson::read(result, "session: result");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(read.value().T_initial.isApprox(document.result()->T_initial, 1e-12));
  EXPECT_EQ(read.value().drrMethod, "raycast");
}

TEST(StudioSession, BadSessionFileLeavesTheDocumentAsItWas) {
  ASSERT_FALSE(fct::test::builtinCaseDir().empty());
  StudioDocument document;
  fillDocument(document);
  const auto folder = fct::test::scratchDir();
  // Valid JSON, but the CT it names is gone: refused before anything changes.
  std::ofstream(folder / "gone.fctsession.json")
      << R"({"format": "fluoroct-studio-session", "version": 1, "ct": {"path": "missing.nrrd"}})";
  const fct::Status missing = StudioSession::open(document, folder / "gone.fctsession.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("missing.nrrd"), std::string::npos) << missing.error();
  std::ofstream(folder / "other.json") << R"({"views": []})";
  const fct::Status other = StudioSession::open(document, folder / "other.json");
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.error().find("format"), std::string::npos) << other.error();
  EXPECT_EQ(document.views().size(), 2u);
  EXPECT_EQ(document.landmarks().ct.size(), 2u);
  EXPECT_TRUE(document.result());
  EXPECT_TRUE(document.isModified());
}

TEST(StudioSession, BadValueMessagesNameTheSectionAndEntry) {
  // Each file is valid JSON of the session format with one bad section; the message names where to fix it.
  const std::vector<std::pair<std::string, std::string>> cases{
      {R"("version": 4)", "version"},
      {R"("views": {"files": []})", "views needs \"view_file\" or \"xray_files\""},
      {R"("views": {"xray_files": [{"name": "ap"}]})", "views.xray_files[0]"},
      {R"("landmarks": {"ct": [{"name": "L1", "p_ct_mm": [1, 2, 3]}, {"name": "L2"}]})", "landmarks.ct[1]"},
      {R"("landmarks": {"image": {"ap": {"name": "L1"}}})", "landmarks.image.ap must be an array"},
      {R"("landmarks": {"image": {"ap": [{"name": "L1", "uv_px": [1]}]}})", "landmarks.image.ap[0]"},
      {R"("initial_pose": {"source": "landmarks"})", "initial_pose"},
      {R"("roi": {"window_size": 7, "use_threshold": false, "target_fraction": 1.5, "variance_threshold": 0,
                  "margin_px": 0, "detect_field_of_view": true, "detect_spheres": true, "sphere_margin_px": 2})",
       "target_fraction"},
      {R"("roi": {"window_size": 7, "use_threshold": false, "target_fraction": 0.5, "variance_threshold": 0,
                  "margin_px": 0, "detect_field_of_view": true, "detect_spheres": true, "sphere_margin_px": 2,
                  "cut_face_margin_mm": 501})",
       "roi: key 'cut_face_margin_mm' must be at most 500 mm"},
      {R"("registration": {"preset": "fast", "seed": -1, "drr_method": "siddon"})", "registration"},
      {R"("registration": {"preset": "fast", "seed": 1, "drr_method": "siddon", "bone_contrast": 0})",
       "registration: key 'bone_contrast' must be above 0 and at most 10"},
      {R"("result": {"verdict": "maybe"})", "use accepted, rejected or undecided"},
      {R"("results": {"verdict": "accepted"})", "results must be an array"},
      {R"("results": [{"verdict": "maybe"}])", "results[0]"},
      {R"("current_result": 0)", "current_result must be an index into results"},
      {R"("display": {"xray_windows": {"ap": {"window": -1, "level": 0}}})", "display.xray_windows.ap"},
      {R"("truth_pose": {"T_world_from_ct": [[1, 0], [0, 1]]})", "truth_pose"},
  };
  const auto path = fct::test::scratchDir() / "bad.fctsession.json";
  for (const auto& [section, expected] : cases) {
    std::ofstream(path) << R"({"format": "fluoroct-studio-session", "version": 2, )" << section << "}";
    StudioDocument document;
    const fct::Status opened = StudioSession::open(document, path);
    ASSERT_FALSE(opened.ok()) << section;
    EXPECT_NE(opened.error().find(path.string()), std::string::npos) << opened.error();
    EXPECT_NE(opened.error().find(expected), std::string::npos) << opened.error();
    EXPECT_FALSE(document.isModified()) << section;
  }
}

TEST(StudioSession, AutosaveReopensModifiedAndRemembersItsSessionFile) {
  ASSERT_FALSE(fct::test::builtinCaseDir().empty());
  StudioDocument document;
  fillDocument(document);
  const auto folder = fct::test::scratchDir();
  ASSERT_TRUE(StudioSession::save(document, folder / "mine.fctsession.json").ok());
  document.setRegistrationOptions({"fast", 7, "siddon"});
  ASSERT_TRUE(StudioSession::writeAutosave(document, folder / "autosave" / "side.json").ok());
  EXPECT_EQ(StudioSession::autosaveOwner(folder / "autosave" / "side.json"), folder / "mine.fctsession.json");

  StudioDocument restored;
  ASSERT_TRUE(StudioSession::open(restored, folder / "autosave" / "side.json").ok());
  EXPECT_TRUE(restored.isModified());
  EXPECT_EQ(restored.sessionPath(), folder / "mine.fctsession.json");
  EXPECT_EQ(restored.registrationOptions().seed, 7u);
}

TEST(StudioSession, OpensASessionFileOfVersion2AsAHistoryOfOneResult) {
  ASSERT_FALSE(fct::test::builtinCaseDir().empty());
  StudioDocument document;
  fillDocument(document);
  const auto path = fct::test::scratchDir() / "v2.fctsession.json";
  ASSERT_TRUE(StudioSession::save(document, path).ok());
  // Version 2 wrote the one result the Studio kept as "result", without a history or windows.
  auto json = fct::JsonDocument::parse(path).value();
  json["version"] = 2;
  json["result"] = json["results"][1];
  for (const char* key : {"results", "current_result", "display"}) json.erase(key);
  ASSERT_TRUE(fct::JsonDocument::write(json, path).ok());

  StudioDocument reopened;
  const fct::Status opened = StudioSession::open(reopened, path);
  ASSERT_TRUE(opened.ok()) << opened.error();
  ASSERT_EQ(reopened.results().size(), 1u);
  EXPECT_EQ(reopened.currentResultIndex(), 0);
  EXPECT_EQ(reopened.result()->totalDrrs, 99);
  EXPECT_EQ(reopened.resultVerdict(), fct::ResultVerdict::Accepted);
  EXPECT_TRUE(reopened.xrayWindows().empty());
}

TEST(StudioSession, OpensASessionFileOfVersion1) {
  // A session saved by the Studio in version 1 after a registration of the built-in case (Testing/Data/compat); its
  // CT and view file are named relative to it, so it is opened from a copy of the built-in case folder.
  ASSERT_FALSE(fct::test::builtinCaseDir().empty());
  const auto folder = fct::test::scratchDir() / "case";
  std::filesystem::copy(fct::test::builtinCaseDir(), folder, std::filesystem::copy_options::recursive);
  const auto path = folder / "session-v1.fctsession.json";
  std::filesystem::copy_file(fct::test::fixtureDir() / "compat" / "session-v1.fctsession.json", path);

  StudioDocument document;
  const fct::Status opened = StudioSession::open(document, path);
  ASSERT_TRUE(opened.ok()) << opened.error();
  ASSERT_TRUE(document.ct());
  ASSERT_EQ(document.views().size(), 2u);
  ASSERT_EQ(document.landmarks().ct.size(), 2u);
  EXPECT_EQ(document.landmarks().ct[1].name, "L2");
  ASSERT_TRUE(document.initialPose());
  EXPECT_NEAR(document.initialPose()->translation().x(), 5.256111045732162, 1e-12);
  EXPECT_EQ(document.registrationOptions(), (fct::StudioRegistrationOptions{"fast", 1, "siddon"}));
  ASSERT_TRUE(document.result());
  const fct::RegistrationResult& r = *document.result();
  EXPECT_NEAR(r.T_world_from_ct.translation().x(), 6.196236763656561, 1e-12);
  EXPECT_TRUE(r.T_initial.isApprox(*document.initialPose(), 1e-12));
  EXPECT_NEAR(r.rotationCentre_ct_mm.x(), 14.775599999999951, 1e-12);
  EXPECT_FALSE(r.cancelled);
  EXPECT_EQ(r.totalDrrs, 2082);
  EXPECT_DOUBLE_EQ(r.totalSeconds, 0.176155691);
  EXPECT_EQ(r.drrMethod, "siddon");
  EXPECT_EQ(r.viewNames, (std::vector<std::string>{"ap", "lateral"}));
  ASSERT_EQ(r.stages.size(), 4u);
  EXPECT_EQ(r.stages[0].name, "ncc-whole-1:16");
  EXPECT_EQ(r.stages[0].level, 2);
  EXPECT_EQ(r.stages[3].keptFraction.size(), 2u);
  EXPECT_EQ(r.schedule.stages.size(), 4u);
  EXPECT_EQ(document.resultVerdict(), fct::ResultVerdict::Accepted);
  ASSERT_TRUE(document.truthPose());
  EXPECT_NEAR(document.truthPose()->translation().x(), 6.029505328528211, 1e-12);
  EXPECT_FALSE(document.isModified());
}

}  // namespace
