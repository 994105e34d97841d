// RegistrationResultJson: the result object of RESULT.json and of the session file: write -> read, the version-1
// files of Testing/Data/compat, bad input.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "Base/JsonDocument.h"
#include "Registration/RegistrationResultJson.h"
#include "TestSupport.h"

namespace {

using fct::RegistrationResultJson;

/// A stage report with its schedule fields set.
fct::StageReport stageReport(const std::string& name, fct::SimilarityMetric metric, int level,
                             fct::SearchStrategy search) {
  fct::StageReport stage;
  stage.name = name;
  stage.metric = metric;
  stage.level = level;
  stage.search = search;
  return stage;
}

fct::RegistrationResult twoStageResult() {
  fct::RegistrationResult result;
  result.viewNames = {"ap", "lateral"};
  fct::StageReport first = stageReport("ncc-whole-1:16", fct::SimilarityMetric::Ncc, 2, fct::SearchStrategy::Genetic);
  first.drrs = 120;
  first.fallbackRays = 7;
  first.keptFraction = {0.5, 0.25};
  fct::StageReport second = first;
  second.name = "vlnc-rois-1:1";
  second.cancelled = true;
  second.keptFraction = {0.12, 0.13, 0.99};  // one fraction more than view names
  result.stages = {first, second};
  return result;
}

/// A result with every field set to a value of its own.
fct::RegistrationResult fullResult() {
  fct::RegistrationResult r;
  r.T_initial.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  r.T_initial.translation() = Eigen::Vector3d(-12.25, 40.5, 1003.125);
  r.T_world_from_ct = r.T_initial * Eigen::Translation3d(1.5, -0.25, 2.0);
  r.rotationCentre_ct_mm = {0.5, 1.5, -2.5};
  r.viewNames = {"ap", "lateral.2"};  // a dot in a view name is kept as is
  fct::StageReport stage = stageReport("vlnc-rois-1:4", fct::SimilarityMetric::Vlnc, 1, fct::SearchStrategy::Local);
  stage.seconds = 1.25;
  stage.drrs = 4000;
  stage.fallbackRays = 3'000'000'000L;  // more than an int holds
  stage.evaluations = 2000;
  stage.startSimilarity = 0.5;
  stage.similarity = 0.875;
  stage.keptFraction = {0.125, 0.0625};
  stage.prealignShift_world_mm = {12.5, -3.25, 0.5};
  stage.rotationSweepSeeds = 2;
  stage.metalPiecesGivenBack = 3;
  stage.hazeViewsCorrected = 1;
  stage.hazeFraction = 0.125;
  stage.hazeHardening = 0.375;
  stage.hazeViewsKept = {"view 'lateral': haze removal: the DRR is constant over the valid pixels"};
  r.stages = {stage};
  r.totalSeconds = 7.5;
  r.totalDrrs = 4000;
  r.viewRendererSetupSeconds = 0.75;
  r.cancelled = true;
  r.schedule = fct::RegistrationSchedule::builtin("fast").value();
  r.drrMethod = "transgraph";
  return r;
}

/// The object read back from its text, as a file would give it.
fct::Result<fct::RegistrationResult> readBack(const nlohmann::ordered_json& json) {
  auto parsed = fct::JsonDocument::parseText(fct::JsonDocument::format(json), "result.json");
  EXPECT_TRUE(parsed.ok()) << parsed.error();
  return RegistrationResultJson::read(parsed.value(), "result.json");
}

/// The error of reading `json` after `edit`.
template <typename Edit>
std::string errorAfter(Edit edit) {
  nlohmann::json json = nlohmann::json::parse(RegistrationResultJson::write(fullResult()).dump());
  edit(json);
  auto read = RegistrationResultJson::read(json, "result.json");
  EXPECT_FALSE(read.ok());
  return read.error();
}

fct::Result<nlohmann::json> fixture(const std::string& name) {
  return fct::JsonDocument::parse(fct::test::fixtureDir() / "compat" / name);
}

}  // namespace

TEST(RegistrationResultJson, WritesEveryStageWithKeptFractionsByViewName) {
  const nlohmann::ordered_json stages = RegistrationResultJson::write(twoStageResult())["stages"];
  ASSERT_EQ(stages.size(), 2u);
  EXPECT_EQ(stages[0]["name"], "ncc-whole-1:16");
  EXPECT_EQ(stages[0]["level"], 2);
  EXPECT_EQ(stages[0]["drrs"], 120);
  EXPECT_EQ(stages[0]["fallback_rays"], 7);
  EXPECT_DOUBLE_EQ(stages[0]["kept_fraction"]["lateral"].get<double>(), 0.25);
  EXPECT_FALSE(stages[0]["cancelled"].get<bool>());
  EXPECT_TRUE(stages[1]["cancelled"].get<bool>());
  EXPECT_EQ(stages[1]["kept_fraction"].size(), 2u) << "a fraction without a view name is left out";
  EXPECT_FALSE(stages[0].contains("prealign_shift_mm")) << "written only for a stage whose start it moved";
  EXPECT_FALSE(stages[0].contains("rotation_sweep_seeds")) << "written only for a stage its rotation sweep seeded";
  EXPECT_FALSE(stages[0].contains("metal_pieces_given_back")) << "written only for a stage whose metal review gave back";
  EXPECT_FALSE(stages[0].contains("haze_views_corrected")) << "written only for a stage whose haze removal corrected";
  EXPECT_FALSE(stages[0].contains("haze_views_kept")) << "written only for a stage whose haze removal kept a view";
}

TEST(RegistrationResultJson, NoStageGivesAnEmptyArray) {
  const nlohmann::ordered_json stages = RegistrationResultJson::write(fct::RegistrationResult{})["stages"];
  EXPECT_TRUE(stages.is_array());
  EXPECT_TRUE(stages.empty());
}

TEST(RegistrationResultJson, WritesFormatVersionAndThePoseAtTheTopLevel) {
  const nlohmann::ordered_json json = RegistrationResultJson::write(fullResult());
  EXPECT_EQ(json["format"], "fluoroct-registration-result");
  EXPECT_EQ(json["version"], RegistrationResultJson::kVersion);
  EXPECT_EQ(json["T_world_from_ct"].size(), 4u) << "RESULT.json reads as a pose file";
  EXPECT_EQ(json["initial_pose"]["T_world_from_ct"].size(), 4u);
  EXPECT_EQ(json["options"]["method"], "transgraph");
  EXPECT_EQ(json["options"]["schedule"]["stages"].size(), 4u);
}

TEST(RegistrationResultJson, WriteThenReadGivesTheSameResult) {
  const fct::RegistrationResult a = fullResult();
  auto read = readBack(RegistrationResultJson::write(a));
  ASSERT_TRUE(read.ok()) << read.error();
  const fct::RegistrationResult& b = read.value();
  EXPECT_EQ(b.T_world_from_ct.matrix(), a.T_world_from_ct.matrix());
  EXPECT_EQ(b.T_initial.matrix(), a.T_initial.matrix());
  EXPECT_EQ(b.rotationCentre_ct_mm, a.rotationCentre_ct_mm);
  EXPECT_EQ(b.viewNames, a.viewNames);
  ASSERT_EQ(b.stages.size(), 1u);
  const fct::StageReport& s = b.stages[0];
  EXPECT_EQ(s.name, a.stages[0].name);
  EXPECT_EQ(s.metric, a.stages[0].metric);
  EXPECT_EQ(s.level, 1);
  EXPECT_EQ(s.search, a.stages[0].search);
  EXPECT_EQ(s.seconds, 1.25);
  EXPECT_EQ(s.drrs, 4000);
  EXPECT_EQ(s.fallbackRays, 3'000'000'000L);
  EXPECT_EQ(s.evaluations, 2000);
  EXPECT_EQ(s.startSimilarity, 0.5);
  EXPECT_EQ(s.similarity, 0.875);
  EXPECT_EQ(s.keptFraction, a.stages[0].keptFraction);
  EXPECT_EQ(s.prealignShift_world_mm, a.stages[0].prealignShift_world_mm);
  EXPECT_EQ(s.rotationSweepSeeds, a.stages[0].rotationSweepSeeds);
  EXPECT_EQ(s.metalPiecesGivenBack, 3);
  EXPECT_EQ(s.hazeViewsCorrected, 1);
  EXPECT_EQ(s.hazeFraction, 0.125);
  EXPECT_EQ(s.hazeHardening, 0.375);
  EXPECT_EQ(s.hazeViewsKept, a.stages[0].hazeViewsKept);
  EXPECT_FALSE(s.cancelled);
  EXPECT_EQ(b.totalSeconds, 7.5);
  EXPECT_EQ(b.totalDrrs, 4000);
  EXPECT_EQ(b.viewRendererSetupSeconds, 0.75);
  EXPECT_TRUE(b.cancelled);
  EXPECT_EQ(b.drrMethod, "transgraph");
  EXPECT_EQ(b.schedule.toJson(), a.schedule.toJson());
}

TEST(RegistrationResultJson, ReadsARunCancelledBeforeItsFirstStage) {
  fct::RegistrationResult cancelled;
  cancelled.cancelled = true;
  cancelled.schedule = fct::RegistrationSchedule::builtin("fast").value();
  auto read = readBack(RegistrationResultJson::write(cancelled));
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(read.value().cancelled);
  EXPECT_TRUE(read.value().stages.empty());
  EXPECT_EQ(read.value().drrMethod, "") << "no stage rendered, so no DRR method";
}

TEST(RegistrationResultJson, ReadsAResultFileOfFormat1) {
  auto file = fixture("RESULT-v1.json");
  ASSERT_TRUE(file.ok()) << file.error();
  auto read = RegistrationResultJson::read(file.value(), "RESULT-v1.json");
  ASSERT_TRUE(read.ok()) << read.error();
  const fct::RegistrationResult& r = read.value();
  EXPECT_NEAR(r.T_world_from_ct.translation().x(), 1.928635690899748, 1e-12);
  EXPECT_NEAR(r.T_initial.translation().x(), 1.4210490562144686, 1e-12);
  EXPECT_NEAR(r.T_initial.linear()(0, 1), 0.06182504370326325, 1e-12);
  EXPECT_NEAR(r.rotationCentre_ct_mm.z(), -3.138026607538803, 1e-12);
  EXPECT_FALSE(r.cancelled);
  EXPECT_EQ(r.totalDrrs, 1770);
  EXPECT_DOUBLE_EQ(r.totalSeconds, 0.066711318);
  EXPECT_EQ(r.viewRendererSetupSeconds, 0.0);
  EXPECT_EQ(r.drrMethod, "transgraph");
  EXPECT_EQ(r.viewNames, (std::vector<std::string>{"ap", "lateral"})) << "from the stages' kept fractions";
  ASSERT_EQ(r.stages.size(), 4u);
  EXPECT_EQ(r.stages[0].name, "ncc-whole-1:16");
  EXPECT_EQ(r.stages[0].drrs, 1080);
  EXPECT_EQ(r.stages[0].evaluations, 539);
  EXPECT_EQ(r.stages[1].keptFraction, (std::vector<double>{0.15123456790123457, 0.16}));
  EXPECT_DOUBLE_EQ(r.stages[3].similarity, 0.9968590235682205);
  EXPECT_EQ(r.schedule.name, "fast");
  EXPECT_EQ(r.schedule.stages.size(), 4u);
}

TEST(RegistrationResultJson, ReadsTheResultOfASessionFileOfVersion1) {
  auto file = fixture("session-v1.fctsession.json");
  ASSERT_TRUE(file.ok()) << file.error();
  auto read = RegistrationResultJson::read(file.value()["result"], "session-v1: result");
  ASSERT_TRUE(read.ok()) << read.error();
  const fct::RegistrationResult& r = read.value();
  EXPECT_NEAR(r.T_world_from_ct.translation().x(), 6.196236763656561, 1e-12);
  EXPECT_NEAR(r.T_initial.translation().x(), 5.256111045732162, 1e-12);
  EXPECT_EQ(r.totalDrrs, 2082);
  EXPECT_EQ(r.drrMethod, "siddon");
  EXPECT_EQ(r.viewNames, (std::vector<std::string>{"ap", "lateral"}));
  ASSERT_EQ(r.stages.size(), 4u);
  EXPECT_EQ(r.stages[2].drrs, 350);
  EXPECT_EQ(r.stages[2].keptFraction, (std::vector<double>{0.12180397727272728, 0.12418537291817523}));
  EXPECT_EQ(r.schedule.stages.size(), 4u);
}

TEST(RegistrationResultJson, MissingKeysNameTheKey) {
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j.erase("total_drrs"); }).find("result.json: key 'total_drrs' is "
                                                                               "missing"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["initial_pose"].erase("T_world_from_ct"); })
                .find("key 'initial_pose.T_world_from_ct' is missing"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["stages"][0].erase("similarity"); })
                .find("result.json: stages[0]: key 'similarity' is missing"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["options"].erase("schedule"); })
                .find("key 'options.schedule' is missing"),
            std::string::npos);
}

TEST(RegistrationResultJson, NaNAndWrongTypesAreRefusedNamingTheKey) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(errorAfter([nan](nlohmann::json& j) { j["total_seconds"] = nan; })
                .find("key 'total_seconds' must be a finite number"),
            std::string::npos);
  EXPECT_NE(errorAfter([nan](nlohmann::json& j) { j["T_world_from_ct"][1][3] = nan; })
                .find("key 'T_world_from_ct[1][3]' must be a finite number"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["cancelled"] = "no"; }).find("key 'cancelled' must be true or false"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["stages"][0]["drrs"] = -3; })
                .find("stages[0]: key 'drrs' must be a whole number >= 0"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["stages"][0]["kept_fraction"]["ap"] = "half"; })
                .find("key 'kept_fraction' of view 'ap' must be a finite number"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["stages"] = 4; }).find("key 'stages' must be an array"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["view_names"] = {"ap", 2}; })
                .find("key 'view_names' must hold only strings"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["T_world_from_ct"][0][0] = 2.0; })
                .find("result.json: T_world_from_ct is not a rigid transform"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["options"]["schedule"]["stages"] = nlohmann::json::array(); })
                .find("options.schedule"),
            std::string::npos);
}

TEST(RegistrationResultJson, RefusesAnotherFormatAndANewerVersion) {
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["format"] = "fluoroct-studio-session"; })
                .find("this is not a FluoroCT registration result"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["version"] = RegistrationResultJson::kVersion + 1; })
                .find("update FluoroCT"),
            std::string::npos);
  const auto notObject = RegistrationResultJson::read(nlohmann::json::array(), "result.json");
  ASSERT_FALSE(notObject.ok());
  EXPECT_NE(notObject.error().find("must be a JSON object"), std::string::npos) << notObject.error();
}

TEST(RegistrationResultJson, StageMetricAndSearchAreWrittenByNameAndUnknownNamesRefused) {
  const nlohmann::ordered_json json = RegistrationResultJson::write(fullResult());
  EXPECT_EQ(json["stages"][0]["metric"], "vlnc");
  EXPECT_EQ(json["stages"][0]["search"], "local");
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["stages"][0]["metric"] = "mi"; })
                .find("stages[0]: key 'metric': 'mi' is not a similarity metric; use one of ncc, vlnc, gc"),
            std::string::npos);
  EXPECT_NE(errorAfter([](nlohmann::json& j) { j["stages"][0]["search"] = "random"; })
                .find("stages[0]: key 'search': 'random' is not a search strategy; use one of genetic, cmaes, local"),
            std::string::npos);
}
