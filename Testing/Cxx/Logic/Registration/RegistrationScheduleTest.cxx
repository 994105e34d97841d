#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "Base/JsonDocument.h"
#include "Registration/RegistrationSchedule.h"
#include "TestSupport.h"

using fct::RegistrationSchedule;

TEST(RegistrationSchedule, PaperPresetHasThePapersThreeStages) {
  auto paper = RegistrationSchedule::builtin("paper");
  ASSERT_TRUE(paper.ok()) << paper.error();
  const auto& s = paper.value().stages;
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0].metric, fct::SimilarityMetric::Ncc);
  EXPECT_EQ(s[0].level, 2);
  EXPECT_EQ(s[0].pixels.kind, fct::PixelSetKind::WholeImage);
  EXPECT_EQ(s[0].search, fct::SearchStrategy::Genetic);
  EXPECT_EQ(s[0].genetic.randomGuesses, 4);
  EXPECT_EQ(s[1].metric, fct::SimilarityMetric::Vlnc);
  EXPECT_EQ(s[1].level, 2);
  EXPECT_EQ(s[1].pixels.kind, fct::PixelSetKind::Rois);
  EXPECT_EQ(s[1].pixels.windowSize, 7);
  EXPECT_EQ(s[1].search, fct::SearchStrategy::Genetic);
  EXPECT_EQ(s[2].metric, fct::SimilarityMetric::Vlnc);
  EXPECT_EQ(s[2].level, 0);
  EXPECT_EQ(s[2].pixels.kind, fct::PixelSetKind::Rois);
  EXPECT_EQ(s[2].search, fct::SearchStrategy::Local);
  EXPECT_EQ(RegistrationSchedule::builtinNames(), (std::vector<std::string>{"accurate", "clinical", "fast", "paper"}));
}

TEST(RegistrationSchedule, DefaultPresetKeepsThePapersStagesWithASmallerSearch) {
  auto preset = RegistrationSchedule::builtin(RegistrationSchedule::kDefaultPreset);
  ASSERT_TRUE(preset.ok()) << preset.error();
  const auto& s = preset.value().stages;
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0].metric, fct::SimilarityMetric::Ncc);
  EXPECT_EQ(s[0].search, fct::SearchStrategy::Genetic);
  EXPECT_GT(s[0].pixels.maxPixels, 0) << "the global stage samples its level sparsely";
  EXPECT_GE(s[0].rotationSweep.maxRotation_deg, 45.0) << "a far start is looked around on a grid of rotations";
  EXPECT_FALSE(s[0].shiftPrealign) << "the sweep lines up every pose it ranks in 2D, the start's own too";
  EXPECT_FALSE(s[0].metalReview);
  EXPECT_TRUE(s[1].metalReview) << "the first stage after the global search reviews the metal masks";
  EXPECT_FALSE(s[2].metalReview);
  for (std::size_t i = 1; i < s.size(); ++i) {
    EXPECT_FALSE(s[i].shiftPrealign);
    EXPECT_EQ(s[i].rotationSweep.maxRotation_deg, 0.0);
    EXPECT_EQ(s[i].metric, fct::SimilarityMetric::Vlnc);
    EXPECT_EQ(s[i].pixels.kind, fct::PixelSetKind::Rois);
  }
  EXPECT_EQ(s.back().level, 1) << "ends at 1:4: a full-resolution stage pulls toward the CT grid's detail";
  EXPECT_EQ(s.back().drrMethod, fct::DrrMethod::RayCast) << "on trilinear DRRs (a smooth patient)";
  EXPECT_EQ(s.back().drrStep_voxels, 1.0);
  EXPECT_EQ(s.back().drrSlices, fct::CtSliceModel::SlabAverages) << "a thick slice's edges are not blurred over two";
  EXPECT_LE(s.back().simplex.tolerance, 0.01) << "a tenth of the 0.1 mm it must hold from the truth";
  for (std::size_t i = 0; i + 1 < s.size(); ++i) EXPECT_FALSE(s[i].drrMethod) << "the others on the case's renderers";
  EXPECT_EQ(preset.value().stageDrrNotes(),
            std::vector<std::string>{"stage 'vlnc-rois-1:4' renders its DRRs with the raycast method (a sample every 1 "
                                     "voxel), a thick-slice CT's slices read as averages over their thickness"});
  EXPECT_TRUE(RegistrationSchedule::builtin("paper").value().stageDrrNotes().empty());
  int budget = 0;
  for (const auto& stage : s) budget += stage.maxEvaluations;
  EXPECT_LE(3 * budget, 4500) << "about the paper's 3,000 DRRs for 3 views, not 8,500";
}

TEST(RegistrationSchedule, JsonRoundTripGivesTheSameSchedule) {
  for (const std::string& name : RegistrationSchedule::builtinNames()) {
    SCOPED_TRACE(name);
    const auto original = RegistrationSchedule::builtin(name).value().withSeed(42);
    const auto json = original.toJson();
    auto again = RegistrationSchedule::fromJson(nlohmann::json::parse(json.dump()), "round trip");
    ASSERT_TRUE(again.ok()) << again.error();
    EXPECT_EQ(again.value().toJson(), json);
    EXPECT_EQ(again.value().stages[0].genetic.seed, 42u);
    EXPECT_EQ(again.value().stages[1].cmaes.seed, 43u);
  }
}

TEST(RegistrationSchedule, VlncDomainIsReadWrittenAndResetByTheNccOnlyAblation) {
  const auto parsed = RegistrationSchedule::fromJson(
      nlohmann::json::parse(R"({"name": "x", "stages": [{"name": "s", "metric": "vlnc", "level": 1,
          "domain": "intensity", "pixels": {"set": "rois"}, "search": {"strategy": "local", "max_evaluations": 10}}]})"),
      "test.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().stages[0].vlncDomain, fct::VlncDomain::Intensity);
  const auto json = parsed.value().toJson();
  EXPECT_EQ(json["stages"][0]["domain"], "intensity");
  const auto again = RegistrationSchedule::fromJson(nlohmann::json::parse(json.dump()), "round trip");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().toJson(), json);
  EXPECT_FALSE(RegistrationSchedule::builtin("clinical").value().toJson()["stages"][2].contains("domain"))
      << "line integrals are the default and are not written";
  fct::RegistrationAblation nccOnly;
  nccOnly.nccOnly = true;
  const auto ablated = parsed.value().withAblation(nccOnly);
  EXPECT_EQ(ablated.stages[0].vlncDomain, fct::VlncDomain::LineIntegral);
  EXPECT_TRUE(RegistrationSchedule::fromJson(ablated.toJson(), "ablated").ok()) << "an NCC stage has no domain";
}

TEST(RegistrationSchedule, SliceModelIsReadAndWrittenOnlyWhereTheSlicesAreSlabAverages) {
  const auto parsed = RegistrationSchedule::fromJson(
      nlohmann::json::parse(R"({"name": "x", "stages": [{"name": "s", "metric": "vlnc", "level": 1, "drr": "raycast",
          "drr_slices": "slab_averages", "pixels": {"set": "rois"}, "search": {"strategy": "local", "max_evaluations": 10}},
          {"name": "t", "metric": "vlnc", "level": 1, "drr": "raycast", "drr_slices": "samples",
          "pixels": {"set": "rois"}, "search": {"strategy": "local", "max_evaluations": 10}}]})"),
      "test.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().stages[0].drrSlices, fct::CtSliceModel::SlabAverages);
  EXPECT_EQ(parsed.value().stages[1].drrSlices, fct::CtSliceModel::Samples);
  const auto json = parsed.value().toJson();
  EXPECT_EQ(json["stages"][0]["drr_slices"], "slab_averages");
  EXPECT_FALSE(json["stages"][1].contains("drr_slices")) << "samples are the default and are not written";
  const auto again = RegistrationSchedule::fromJson(nlohmann::json::parse(json.dump()), "round trip");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().toJson(), json);
  EXPECT_EQ(parsed.value().stageDrrNotes().front(),
            "stage 's' renders its DRRs with the raycast method, a thick-slice CT's slices read as averages over their "
            "thickness");
}

TEST(RegistrationSchedule, HazeRemovalIsReadAndWrittenOnlyWhereItIsOn) {
  const auto parsed = RegistrationSchedule::fromJson(
      nlohmann::json::parse(R"({"name": "x", "stages": [{"name": "s", "metric": "vlnc", "level": 1,
          "haze_sigma_mm": 15, "pixels": {"set": "rois"}, "search": {"strategy": "local", "max_evaluations": 10}}]})"),
      "test.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().stages[0].hazeSigma_mm, 15.0);
  const auto json = parsed.value().toJson();
  EXPECT_EQ(json["stages"][0]["haze_sigma_mm"], 15.0);
  const auto again = RegistrationSchedule::fromJson(nlohmann::json::parse(json.dump()), "round trip");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().toJson(), json);
  const auto paper = RegistrationSchedule::builtin("paper").value().toJson();
  for (const auto& stage : paper["stages"]) {
    EXPECT_FALSE(stage.contains("haze_sigma_mm")) << "off by default, and off is not written";
  }
  const auto clinical = RegistrationSchedule::builtin("clinical").value();
  EXPECT_EQ(clinical.stages.back().hazeSigma_mm, 15.0) << "the default removes the haze before its last stage";
  EXPECT_EQ(clinical.stages.back().vlncWeights, fct::VlncWeightSource::Drr) << "and weighs that stage's windows by a DRR";
  EXPECT_EQ(clinical.stages.front().hazeSigma_mm, 0.0) << "its NCC stage compares the X-rays as prepared";
}

// docs/evaluation.md re-runs its ablations with the preset files of docs/evaluation/presets/: each must stay a valid
// schedule, and the two that the page defines as the default less its last stage's haze removal and/or DRR window
// weights must stay exactly that.
TEST(RegistrationSchedule, TheEvaluationsPresetFilesAreValidAndTheHazeAblationsDifferFromTheDefaultOnlyWhereNamed) {
  const auto presetDir = fct::test::sourcePath("docs/evaluation/presets");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(presetDir)) {
    const auto parsed = RegistrationSchedule::resolve(entry.path().string());
    EXPECT_TRUE(parsed.ok()) << entry.path() << ": " << parsed.error();
    ++files;
  }
  EXPECT_GE(files, 2) << presetDir;
  auto expected = RegistrationSchedule::builtin("clinical").value().toJson()["stages"];
  ASSERT_EQ(expected.back()["weights"], "drr");
  expected.back().erase("weights");
  const auto dehaze = RegistrationSchedule::resolve((presetDir / "clinical-dehaze.json").string());
  ASSERT_TRUE(dehaze.ok()) << dehaze.error();
  EXPECT_EQ(dehaze.value().toJson()["stages"], expected) << "clinical-dehaze is clinical without its DRR weights";
  expected.back().erase("haze_sigma_mm");
  const auto without = RegistrationSchedule::resolve((presetDir / "clinical-without-haze-removal.json").string());
  ASSERT_TRUE(without.ok()) << without.error();
  EXPECT_EQ(without.value().toJson()["stages"], expected) << "clinical without its haze removal and DRR weights";
}

TEST(RegistrationSchedule, DrrWindowWeightsAreReadAndWrittenOnlyWhereTheyAreAskedFor) {
  const auto parsed = RegistrationSchedule::fromJson(
      nlohmann::json::parse(R"({"name": "x", "stages": [{"name": "s", "metric": "vlnc", "level": 1,
          "weights": "drr", "pixels": {"set": "rois"}, "search": {"strategy": "local", "max_evaluations": 10}}]})"),
      "test.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().stages[0].vlncWeights, fct::VlncWeightSource::Drr);
  const auto json = parsed.value().toJson();
  EXPECT_EQ(json["stages"][0]["weights"], "drr");
  const auto again = RegistrationSchedule::fromJson(nlohmann::json::parse(json.dump()), "round trip");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().toJson(), json);
  const auto paper = RegistrationSchedule::builtin("paper").value().toJson();
  for (const auto& stage : paper["stages"]) {
    EXPECT_FALSE(stage.contains("weights")) << "the X-ray's variances (the paper's) are the default and not written";
  }
}

TEST(RegistrationSchedule, DepthScaleIsReadAndWrittenOnlyWhereItIsOn) {
  const auto parsed = RegistrationSchedule::fromJson(
      nlohmann::json::parse(R"({"name": "x", "stages": [{"name": "s", "metric": "vlnc", "level": 2,
          "pixels": {"set": "rois"}, "search": {"strategy": "local", "max_evaluations": 10, "depth_scale": 10}}]})"),
      "test.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().stages[0].depthScale, 10.0);
  const auto json = parsed.value().toJson();
  EXPECT_EQ(json["stages"][0]["search"]["depth_scale"], 10.0);
  const auto again = RegistrationSchedule::fromJson(nlohmann::json::parse(json.dump()), "round trip");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().toJson(), json);
  const auto clinical = RegistrationSchedule::builtin("clinical").value().toJson();
  for (const auto& stage : clinical["stages"]) {
    EXPECT_FALSE(stage["search"].contains("depth_scale")) << "off (1) by default, and off is not written";
  }
}

TEST(RegistrationSchedule, ReadsAUserFileAndResolvesNames) {
  const auto dir = fct::test::scratchDir();
  const auto path = dir / "mine.json";
  std::ofstream(path) << R"({"name": "mine", "stages": [
      {"name": "only", "metric": "gc", "level": 1, "pixels": {"set": "whole"},
       "search": {"strategy": "cmaes", "max_evaluations": 50, "cmaes": {"sigma": 2}}}]})";
  auto mine = RegistrationSchedule::resolve(path.string());
  ASSERT_TRUE(mine.ok()) << mine.error();
  EXPECT_EQ(mine.value().name, "mine");
  ASSERT_EQ(mine.value().stages.size(), 1u);
  EXPECT_EQ(mine.value().stages[0].metric, fct::SimilarityMetric::GradientCorrelation);
  EXPECT_EQ(mine.value().stages[0].search, fct::SearchStrategy::CmaEs);
  EXPECT_EQ(mine.value().stages[0].cmaes.initialSigma, 2.0);
  EXPECT_EQ(mine.value().stages[0].maxEvaluations, 50);
  auto fast = RegistrationSchedule::resolve("fast");
  ASSERT_TRUE(fast.ok()) << fast.error();
  EXPECT_EQ(fast.value().name, "fast");
}

TEST(RegistrationSchedule, RejectsBadSchedulesNamingTheKey) {
  auto parse = [](const std::string& text) {
    return RegistrationSchedule::fromJson(nlohmann::json::parse(text), "test.json");
  };
  const std::string stageHead = R"({"name": "x", "stages": [{"name": "s", )";
  const std::string search = R"("search": {"strategy": "local", "max_evaluations": 10}})";
  struct Case {
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases{
      {R"({"name": "x", "stages": []})", "stages"},
      {R"({"name": "x"})", "stages"},
      {stageHead + R"("metric": "mi", "level": 0, "pixels": {"set": "whole"}, )" + search + "]}", "metric"},
      {stageHead + R"("metric": "ncc", "level": 9, "pixels": {"set": "whole"}, )" + search + "]}", "level"},
      {stageHead + R"("metric": "ncc", "level": 0, "pixels": {"set": "rois", "fraction": 0}, )" + search + "]}",
       "fraction"},
      {stageHead + R"("metric": "ncc", "level": 0, "pixels": {"set": "rois", "window": 1}, )" + search + "]}",
       "window"},
      {stageHead + R"("metric": "ncc", "level": 0, "pixels": {"set": "all"}, )" + search + "]}", "set"},
      {stageHead + R"("metric": "ncc", "level": 0, "exact_drr": "yes", "pixels": {"set": "whole"}, )" + search + "]}",
       "exact_drr"},
      {stageHead + R"("metric": "ncc", "level": 0, "drr": "transgraph", "pixels": {"set": "whole"}, )" + search + "]}",
       "drr"},
      {stageHead + R"("metric": "ncc", "level": 2, "shift_prealign": 1, "pixels": {"set": "whole"}, )" + search + "]}",
       "shift_prealign"},
      {stageHead + R"("metric": "vlnc", "level": 2, "metal_review": "on", "pixels": {"set": "whole"}, )" + search + "]}",
       "metal_review"},
      {stageHead + R"("metric": "vlnc", "level": 2, "domain": "log", "pixels": {"set": "whole"}, )" + search + "]}",
       "domain"},
      {stageHead + R"("metric": "ncc", "level": 2, "domain": "intensity", "pixels": {"set": "whole"}, )" + search + "]}",
       "domain"},
      {stageHead + R"("metric": "vlnc", "level": 1, "haze_sigma_mm": 0.5, "pixels": {"set": "whole"}, )" + search + "]}",
       "haze_sigma_mm"},
      {stageHead + R"("metric": "vlnc", "level": 1, "weights": "noise", "pixels": {"set": "whole"}, )" + search + "]}",
       "weights"},
      {stageHead + R"("metric": "ncc", "level": 1, "weights": "drr", "pixels": {"set": "whole"}, )" + search + "]}",
       "weights"},
      {stageHead + R"("metric": "vlnc", "level": 1, "haze_sigma_mm": "15", "pixels": {"set": "whole"}, )" + search + "]}",
       "haze_sigma_mm"},
      {stageHead + R"("metric": "ncc", "level": 2, "rotation_sweep": {"step_deg": 10}, "pixels": {"set": "whole"}, )" +
           search + "]}",
       "max_deg"},
      {stageHead + R"("metric": "ncc", "level": 2, "rotation_sweep": {"max_deg": 0}, "pixels": {"set": "whole"}, )" +
           search + "]}",
       "max_deg"},
      {stageHead + R"("metric": "ncc", "level": 2, "rotation_sweep": {"max_deg": 30, "step_deg": 40}, )" +
           R"("pixels": {"set": "whole"}, )" + search + "]}",
       "step_deg"},
      {stageHead + R"("metric": "ncc", "level": 2, "rotation_sweep": {"max_deg": 30, "aligned": 2, "seeds": 3}, )" +
           R"("pixels": {"set": "whole"}, )" + search + "]}",
       "seeds"},
      {stageHead + R"("metric": "ncc", "level": 0, "drr_step_voxels": 1, "pixels": {"set": "whole"}, )" + search + "]}",
       "drr_step_voxels"},
      {stageHead + R"("metric": "ncc", "level": 0, "drr": "raycast", "drr_step_voxels": 0, "pixels": {"set": "whole"}, )" +
           search + "]}",
       "drr_step_voxels"},
      {stageHead + R"("metric": "ncc", "level": 0, "drr_slices": "slab_averages", "pixels": {"set": "whole"}, )" +
           search + "]}",
       "drr_slices"},
      {stageHead + R"("metric": "ncc", "level": 0, "drr": "raycast", "drr_slices": "boxes", "pixels": {"set": "whole"}, )" +
           search + "]}",
       "slab_averages"},
      {stageHead + R"("metric": "ncc", "level": 0, "pixels": {"set": "whole"}, "search": {"strategy": "local", )" +
           R"("max_evaluations": 10, "depth_scale": 0.5}}]})",
       "depth_scale"},
      {stageHead + R"("metric": "ncc", "level": 0, "pixels": {"set": "whole"}, "search": {"strategy": "genetic", )" +
           R"("max_evaluations": 10, "depth_scale": 10}}]})",
       "depth_scale"},
      {stageHead + R"("metric": "ncc", "level": 0, "pixels": {"set": "whole"}})" + "]}", "search"},
      {stageHead + R"("metric": "ncc", "level": 0, "pixels": {"set": "whole"}, "search": {"strategy": "local", )" +
           R"("max_evaluations": 10, "simplex": {"tolerance": -1}}}]})",
       "tolerance"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    auto schedule = parse(c.text);
    ASSERT_FALSE(schedule.ok());
    EXPECT_NE(schedule.error().find(c.expected), std::string::npos) << schedule.error();
    EXPECT_NE(schedule.error().find("test.json"), std::string::npos) << schedule.error();
  }
  auto unknown = RegistrationSchedule::resolve("fastest");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("fast, paper"), std::string::npos) << unknown.error();
}

TEST(RegistrationSchedule, AblationTurnsOneTechniqueOffAtATime) {
  const auto paper = RegistrationSchedule::builtin("paper").value();
  EXPECT_EQ(paper.withAblation({}).toJson(), paper.toJson()) << "no switch: unchanged";
  fct::RegistrationAblation cmaes;
  cmaes.cmaesForGenetic = true;
  const auto withCmaes = paper.withAblation(cmaes);
  EXPECT_EQ(withCmaes.stages[0].search, fct::SearchStrategy::CmaEs);
  EXPECT_EQ(withCmaes.stages[2].search, fct::SearchStrategy::Local) << "local stages stay local";
  EXPECT_EQ(withCmaes.stages[1].metric, fct::SimilarityMetric::Vlnc) << "nothing else changes";
  EXPECT_NE(withCmaes.name.find("cmaes"), std::string::npos);
  fct::RegistrationAblation rois;
  rois.noDynamicRois = true;
  EXPECT_EQ(paper.withAblation(rois).stages[2].pixels.kind, fct::PixelSetKind::WholeImage);
  EXPECT_EQ(paper.withAblation(rois).stages[2].level, 0);

  // The Transgraph switch acts on the renderers (Registration), not on the stages: only the name changes.
  fct::RegistrationAblation transgraph;
  transgraph.noTransgraph = true;
  EXPECT_EQ(transgraph.activeNames(), std::vector<std::string>{"no-transgraph"});
  EXPECT_EQ(paper.withAblation(transgraph).toJson()["stages"], paper.toJson()["stages"]);
  EXPECT_NE(paper.withAblation(transgraph).name.find("no-transgraph"), std::string::npos);
  EXPECT_TRUE(paper.stages.back().exactDrr) << "the full-resolution stage renders exactly";
  EXPECT_FALSE(paper.stages.front().exactDrr);
}

TEST(RegistrationSchedule, RoiPixelsReplaceEveryRoiStagesWindowAndFractionOnly) {
  const auto fast = RegistrationSchedule::builtin("fast").value();
  auto same = fast.withRoiPixels(7, 0.15);
  ASSERT_TRUE(same.ok()) << same.error();
  EXPECT_EQ(same.value().stages[0].pixels.kind, fct::PixelSetKind::WholeImage);
  auto tuned = fast.withRoiPixels(9, 0.2);
  ASSERT_TRUE(tuned.ok()) << tuned.error();
  ASSERT_EQ(tuned.value().stages.size(), fast.stages.size());
  EXPECT_EQ(tuned.value().stages[0].pixels.windowSize, fast.stages[0].pixels.windowSize) << "whole-image stage kept";
  for (std::size_t i = 1; i < fast.stages.size(); ++i) {
    EXPECT_EQ(tuned.value().stages[i].pixels.windowSize, 9);
    EXPECT_DOUBLE_EQ(tuned.value().stages[i].pixels.targetFraction, 0.2);
    EXPECT_EQ(tuned.value().stages[i].level, fast.stages[i].level);
  }
}

TEST(RegistrationSchedule, RoiPixelsRejectABadWindowOrFraction) {
  const auto fast = RegistrationSchedule::builtin("fast").value();
  auto window = fast.withRoiPixels(1, 0.1);
  ASSERT_FALSE(window.ok());
  EXPECT_NE(window.error().find("2 to 64"), std::string::npos);
  auto fraction = fast.withRoiPixels(7, 0.0);
  ASSERT_FALSE(fraction.ok());
  EXPECT_NE(fraction.error().find("(0, 1]"), std::string::npos);
}

TEST(RegistrationSchedule, MetricAndSearchNamesParseBackAndUnknownNamesAreRefused) {
  for (fct::SimilarityMetric metric :
       {fct::SimilarityMetric::Ncc, fct::SimilarityMetric::Vlnc, fct::SimilarityMetric::GradientCorrelation}) {
    const auto parsed = fct::RegistrationSchedule::parseMetric(fct::RegistrationSchedule::metricName(metric));
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    EXPECT_EQ(parsed.value(), metric);
  }
  for (fct::SearchStrategy search :
       {fct::SearchStrategy::Genetic, fct::SearchStrategy::CmaEs, fct::SearchStrategy::Local}) {
    const auto parsed = fct::RegistrationSchedule::parseSearch(fct::RegistrationSchedule::searchName(search));
    ASSERT_TRUE(parsed.ok()) << parsed.error();
    EXPECT_EQ(parsed.value(), search);
  }
  const auto metric = fct::RegistrationSchedule::parseMetric("NCC");
  ASSERT_FALSE(metric.ok());
  EXPECT_EQ(metric.error(), "'NCC' is not a similarity metric; use one of ncc, vlnc, gc");
  const auto search = fct::RegistrationSchedule::parseSearch("");
  ASSERT_FALSE(search.ok());
  EXPECT_EQ(search.error(), "'' is not a search strategy; use one of genetic, cmaes, local");
}
