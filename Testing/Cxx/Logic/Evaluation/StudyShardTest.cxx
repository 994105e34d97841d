// StudyShard: every trial in exactly one shard, spread evenly over shards within each condition and in all; the
// "K/N" text round trip; bad shard texts refused with the accepted form.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <vector>

#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyShard.h"

namespace {

/// The number of trials of each shard of `count`, within condition `condition` or (empty) in all.
std::vector<int> trialsPerShard(const fct::StudyDefinition& study, int count, const std::string& condition = "") {
  std::vector<int> perShard(count, 0);
  for (int k = 1; k <= count; ++k) {
    const fct::StudyShard shard = fct::StudyShard::create(study, k, count).value();
    for (const fct::StudyCondition& c : study.conditions) {
      if (!condition.empty() && c.name != condition) continue;
      for (int t = 0; t < c.trials; ++t) perShard[k - 1] += shard.holds(c.name, t) ? 1 : 0;
    }
  }
  return perShard;
}

int spread(const std::vector<int>& counts) {
  const auto [low, high] = std::minmax_element(counts.begin(), counts.end());
  return *high - *low;
}

}  // namespace

TEST(StudyShard, DealsEveryTrialToOneShardEvenlyWithinEachConditionAndInAll) {
  // The full capture study: 34 conditions of 10 trials = 340 trials, over 7 shards.
  const fct::StudyDefinition study = fct::StudyCatalog::define("capture", false, {"pelvis"}).value();
  int total = 0;
  for (const fct::StudyCondition& c : study.conditions) {
    total += c.trials;
    for (int t = 0; t < c.trials; ++t) {
      int holders = 0;
      for (int k = 1; k <= 7; ++k) holders += fct::StudyShard::create(study, k, 7).value().holds(c.name, t) ? 1 : 0;
      EXPECT_EQ(holders, 1) << c.name << " trial " << t;
    }
    EXPECT_LE(spread(trialsPerShard(study, 7, c.name)), 1) << c.name;
  }
  const std::vector<int> all = trialsPerShard(study, 7);
  EXPECT_LE(spread(all), 1);
  int sum = 0;
  for (int n : all) sum += n;
  EXPECT_EQ(sum, total);

  fct::StudyDefinition sample = study;  // a run of the first trial of each condition (--trials 1) over 4 shards
  for (fct::StudyCondition& c : sample.conditions) c.trials = 1;
  EXPECT_LE(spread(trialsPerShard(sample, 4)), 1);
  EXPECT_EQ(fct::StudyShard::create(sample, 1, 4).value().totalTrials(), static_cast<int>(sample.conditions.size()));
}

TEST(StudyShard, QuickTable2InThreeShardsGivesEachShardOneTrialOfTwoConditions) {
  const fct::StudyDefinition study = fct::StudyCatalog::define("table2", true, {"phantom"}).value();
  const fct::StudyShard first = fct::StudyShard::create(study, 1, 3).value();
  EXPECT_EQ(first.shardOf("phantom/ideal", 0), 1);
  EXPECT_EQ(first.shardOf("phantom/ideal", 1), 2);
  EXPECT_EQ(first.shardOf("phantom/realistic", 0), 3);  // the round robin goes on where the previous condition ended
  EXPECT_EQ(first.shardOf("phantom/realistic", 1), 1);
  EXPECT_EQ(first.shardOf("phantom/bad", 0), 2);
  EXPECT_EQ(first.shardOf("phantom/bad", 1), 3);
  EXPECT_EQ(first.shardOf("phantom/none", 0), 0);
  EXPECT_EQ(trialsPerShard(study, 3), (std::vector<int>{2, 2, 2}));
}

TEST(StudyShard, TextRoundTripsAndOneOfOneHoldsEveryTrial) {
  const fct::StudyDefinition study = fct::StudyCatalog::define("views", true, {"phantom"}).value();
  const auto shard = fct::StudyShard::parse(study, "12/40");
  ASSERT_TRUE(shard.ok()) << shard.error();
  EXPECT_EQ(shard.value().index(), 12);
  EXPECT_EQ(shard.value().count(), 40);
  EXPECT_EQ(shard.value().text(), "12/40");
  const fct::StudyShard whole = fct::StudyShard::parse(study, "1/1").value();
  for (const fct::StudyCondition& c : study.conditions) {
    for (int t = 0; t < c.trials; ++t) EXPECT_TRUE(whole.holds(c.name, t)) << c.name << " trial " << t;
  }
}

TEST(StudyShard, BadShardTextsAreRefusedWithTheAcceptedForm) {
  const fct::StudyDefinition study = fct::StudyCatalog::define("views", true, {"phantom"}).value();
  for (const char* text : {"3", "a/b", "1/3x", "/3", "1/", " 1/3", ""}) {
    const auto shard = fct::StudyShard::parse(study, text);
    ASSERT_FALSE(shard.ok()) << text;
    EXPECT_NE(shard.error().find("is not of the form K/N"), std::string::npos) << shard.error();
  }
  for (const char* text : {"0/3", "-1/3", "4/3", "1/0", "1/10001"}) {
    const auto shard = fct::StudyShard::parse(study, text);
    ASSERT_FALSE(shard.ok()) << text;
    EXPECT_NE(shard.error().find("1 <= K <= N <= 10000"), std::string::npos) << shard.error();
  }
}
