#include <gtest/gtest.h>

#include "Registration/RegistrationStagesJson.h"

namespace {

fct::RegistrationResult twoStageResult() {
  fct::RegistrationResult result;
  result.viewNames = {"ap", "lateral"};
  fct::StageReport first;
  first.name = "ncc-whole-1:16";
  first.metric = "ncc";
  first.level = 2;
  first.search = "genetic";
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

}  // namespace

TEST(RegistrationStagesJson, WritesEveryStageWithKeptFractionsByViewName) {
  const nlohmann::ordered_json stages = fct::RegistrationStagesJson::write(twoStageResult());
  ASSERT_EQ(stages.size(), 2u);
  EXPECT_EQ(stages[0]["name"], "ncc-whole-1:16");
  EXPECT_EQ(stages[0]["level"], 2);
  EXPECT_EQ(stages[0]["drrs"], 120);
  EXPECT_EQ(stages[0]["fallback_rays"], 7);
  EXPECT_DOUBLE_EQ(stages[0]["kept_fraction"]["lateral"].get<double>(), 0.25);
  EXPECT_FALSE(stages[0]["cancelled"].get<bool>());
  EXPECT_TRUE(stages[1]["cancelled"].get<bool>());
  EXPECT_EQ(stages[1]["kept_fraction"].size(), 2u) << "a fraction without a view name is left out";
}

TEST(RegistrationStagesJson, NoStageGivesAnEmptyArray) {
  const nlohmann::ordered_json stages = fct::RegistrationStagesJson::write(fct::RegistrationResult{});
  EXPECT_TRUE(stages.is_array());
  EXPECT_TRUE(stages.empty());
}
