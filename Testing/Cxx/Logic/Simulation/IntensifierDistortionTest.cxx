#include <gtest/gtest.h>

#include <cmath>

#include "Simulation/IntensifierDistortion.h"

namespace {
/// Intensity-weighted centroid of an image.
Eigen::Vector2d centroid(const fct::FloatImage& image) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double total = 0.0;
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      sum += image.at(col, row) * Eigen::Vector2d(col, row);
      total += image.at(col, row);
    }
  }
  return sum / total;
}
}  // namespace

TEST(IntensifierDistortion, UndistortInvertsDistort) {
  auto distortion = fct::IntensifierDistortion::create(160, 120, 0.05, 3.0);
  ASSERT_TRUE(distortion.ok()) << distortion.error();
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0, 0), Eigen::Vector2d(159, 119), Eigen::Vector2d(40.3, 90.7)}) {
    const Eigen::Vector2d observed = distortion.value().distort(uv);
    EXPECT_GT((observed - uv).norm(), 0.5);  // pincushion moves the periphery outward
    EXPECT_LT((distortion.value().undistort(observed) - uv).norm(), 1e-6);
  }
  EXPECT_LT((distortion.value().distort(Eigen::Vector2d(79.5, 59.5)) - Eigen::Vector2d(79.5, 59.5)).norm(), 1e-12);
}

TEST(IntensifierDistortion, WarpThenDewarpWithTheSavedFieldRestoresABlobWithinATenthOfAPixel) {
  auto distortion = fct::IntensifierDistortion::create(160, 120, 0.06, 4.0);
  ASSERT_TRUE(distortion.ok());
  fct::FloatImage ideal = fct::FloatImage::filled(160, 120);
  const Eigen::Vector2d blob(130.0, 25.0);
  for (int row = 0; row < 120; ++row) {
    for (int col = 0; col < 160; ++col) {
      ideal.at(col, row) = static_cast<float>(std::exp(-(Eigen::Vector2d(col, row) - blob).squaredNorm() / (2 * 9.0)));
    }
  }
  auto observed = distortion.value().warp(ideal);
  ASSERT_TRUE(observed.ok()) << observed.error();
  const Eigen::Vector2d moved = centroid(observed.value());
  EXPECT_GT((moved - blob).norm(), 1.0);
  // The warped blob sits where the distortion maps its centre (up to the blob's own non-linear deformation).
  EXPECT_LT((moved - distortion.value().distort(blob)).norm(), 0.3);
  auto restored = fct::IntensifierDistortion::dewarp(observed.value(), distortion.value().field());
  ASSERT_TRUE(restored.ok()) << restored.error();
  EXPECT_LT((centroid(restored.value()) - blob).norm(), 0.1);
}

TEST(IntensifierDistortion, RejectsStrongDistortionAndMismatchedSizes) {
  EXPECT_FALSE(fct::IntensifierDistortion::create(100, 100, 0.5, 0.0).ok());
  EXPECT_FALSE(fct::IntensifierDistortion::create(100, 100, 0.0, 45.0).ok());
  EXPECT_FALSE(fct::IntensifierDistortion::create(0, 100, 0.0, 0.0).ok());
  auto distortion = fct::IntensifierDistortion::create(100, 80, 0.02, 0.0);
  ASSERT_TRUE(distortion.ok());
  EXPECT_FALSE(distortion.value().warp(fct::FloatImage::filled(80, 100)).ok());
  EXPECT_FALSE(fct::IntensifierDistortion::dewarp(fct::FloatImage::filled(50, 50), distortion.value().field()).ok());
}
