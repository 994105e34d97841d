#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "Tracking/SimilarityLevel.h"

using fct::SimilarityLevel;

namespace {

/// The index of the first frame after frame 0 that fails the level (following every frame that holds), or -1.
int firstFlagged(const std::vector<double>& similarities, double growth = 2.0, double weight = 0.2) {
  SimilarityLevel level(similarities.front(), growth, weight);
  for (std::size_t f = 1; f < similarities.size(); ++f) {
    if (!level.holds(similarities[f])) return static_cast<int>(f);
    level.follow(similarities[f]);
  }
  return -1;
}

}  // namespace

TEST(SimilarityLevel, FlagsASlowFallThatARunningMeanAloneWouldFollow) {
  // The pelvis single-plane sequence of the tracking study: steady near 0.94 while tracked, then the track drifts off
  // and the similarity falls over several frames (0.85, 0.78, 0.70, ...).
  const std::vector<double> drift = {0.935, 0.944, 0.941, 0.942, 0.948, 0.946, 0.939, 0.931, 0.850, 0.780,
                                     0.704, 0.709, 0.647, 0.623, 0.601};
  EXPECT_EQ(firstFlagged(drift), 8);

  // A slower fall, 0.01 per frame: a reference that followed it would stay within reach of every frame; frame 0's
  // dissimilarity keeps it where it was.
  std::vector<double> slow = {0.94};
  for (int f = 1; f <= 20; ++f) slow.push_back(0.94 - 0.01 * f);
  const int flagged = firstFlagged(slow);
  EXPECT_GT(flagged, 1);
  EXPECT_LE(slow[static_cast<std::size_t>(flagged)], 1.0 - 2.0 * 0.06 + 1e-12);  // 1 - s > 2 x (1 - 0.94)

  SimilarityLevel followed(0.94, 2.0, 0.2);
  SimilarityLevel anchored(0.94, 2.0, 0.2);
  for (int f = 1; f <= 20; ++f) followed.follow(0.94 - 0.01 * f);
  EXPECT_NEAR(anchored.referenceDissimilarity(), 0.06, 1e-12);
  EXPECT_NEAR(followed.referenceDissimilarity(), 0.06, 1e-12);  // the smaller of the two levels' dissimilarities
  EXPECT_LT(followed.running(), 0.85);
}

TEST(SimilarityLevel, KeepsSteadyNoisyTracksAndNearPerfectMatches) {
  // The tracking study's correctly tracked sequences: pelvis biplane (0.958-0.979) and head single-plane (0.989-0.997).
  const std::vector<double> pelvis = {0.965, 0.969, 0.972, 0.970, 0.967, 0.963, 0.964, 0.967, 0.959, 0.965,
                                      0.966, 0.970, 0.968, 0.973, 0.974, 0.979, 0.977, 0.978};
  EXPECT_EQ(firstFlagged(pelvis), -1);
  const std::vector<double> head = {0.9907, 0.9892, 0.9914, 0.9941, 0.9966, 0.9969, 0.9963, 0.9936, 0.9968};
  EXPECT_EQ(firstFlagged(head), -1);
  // Below the floor, only noise: 1 - 0.9999 is tiny, and a frame at 0.991 still holds (1 - s <= 2 x 0.005).
  SimilarityLevel perfect(0.9999, 2.0, 0.2);
  EXPECT_DOUBLE_EQ(perfect.referenceDissimilarity(), SimilarityLevel::kMinReferenceDissimilarity);
  EXPECT_TRUE(perfect.holds(0.991));
  EXPECT_FALSE(perfect.holds(0.989));
}

TEST(SimilarityLevel, RefusesNaNAndFollowsRisingLevels) {
  SimilarityLevel level(0.80, 2.0, 0.5);
  EXPECT_FALSE(level.holds(std::nan("")));
  EXPECT_TRUE(level.holds(0.61));   // 0.39 <= 2 x 0.2
  EXPECT_FALSE(level.holds(0.59));
  level.follow(0.96);               // running 0.88: the reference tightens to 0.12
  EXPECT_NEAR(level.running(), 0.88, 1e-12);
  EXPECT_NEAR(level.referenceDissimilarity(), 0.12, 1e-12);
  EXPECT_FALSE(level.holds(0.75));
}

TEST(SimilarityLevel, TellsAGradualFallFromASuddenOneAndReanchorsAtAConfirmedFrame) {
  // The pelvis biplane sequence whose scene lowered the similarity: frame 0 at 0.961, then slowly down to 0.934.
  SimilarityLevel level(0.961, 1.75, 0.2);
  for (const double s : {0.955, 0.950, 0.945, 0.944, 0.940, 0.934}) level.follow(s);
  EXPECT_DOUBLE_EQ(level.last(), 0.934);
  EXPECT_NEAR(level.referenceDissimilarity(), 0.039, 1e-12);  // frame 0's is the smaller
  EXPECT_FALSE(level.holds(0.919));                            // 0.081 > 1.75 x 0.039
  EXPECT_TRUE(level.fellGradually(0.919));                     // 0.081 <= 1.75 x 0.066
  EXPECT_FALSE(level.fellGradually(0.850));                    // the drifting track above: 0.150 > 1.75 x 0.066
  EXPECT_FALSE(level.fellGradually(std::nan("")));
  level.reanchor(0.919);  // a re-registration confirmed that frame's pose
  EXPECT_DOUBLE_EQ(level.running(), 0.919);
  EXPECT_DOUBLE_EQ(level.last(), 0.919);
  EXPECT_NEAR(level.referenceDissimilarity(), 0.081, 1e-12);
  EXPECT_TRUE(level.holds(0.905));
  EXPECT_FALSE(level.holds(0.85));  // 0.15 > 1.75 x 0.081
}
