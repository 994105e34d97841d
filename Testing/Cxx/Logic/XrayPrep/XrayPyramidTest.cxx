#include <gtest/gtest.h>

#include "XrayPrep/XrayPyramid.h"

namespace {

fct::Camera testCamera(int cols, int rows) {
  return fct::Camera::lookingAt({0, 0, 0}, Eigen::Matrix3d::Identity(), 700.0, 1100.0, cols, rows, 0.4);
}

}  // namespace

TEST(XrayPyramid, LevelsAreBlockMeansWithStrictMasksAndExactCameras) {
  fct::FloatImage image = fct::FloatImage::filled(37, 22);  // odd size: the last column is dropped
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) image.at(c, r) = static_cast<float>(3 * c + 100 * r);
  }
  fct::ValidMask mask = fct::ValidMask::allValid(37, 22);
  mask.valid[5 * 37 + 6] = 0;  // pixel (6,5)
  const fct::Camera camera = testCamera(37, 22);
  const auto pyramid = fct::XrayPyramid::build(image, mask, camera, 3);
  ASSERT_TRUE(pyramid.ok()) << pyramid.error();
  ASSERT_EQ(pyramid.value().levelCount(), 3);
  const fct::PyramidLevel& l1 = pyramid.value().level(1);
  const fct::PyramidLevel& l2 = pyramid.value().level(2);
  EXPECT_EQ(l1.image.cols, 18);
  EXPECT_EQ(l1.image.rows, 11);
  EXPECT_EQ(l2.image.cols, 9);
  EXPECT_EQ(l2.image.rows, 5);
  // A linear ramp's block mean is its value at the block centre: 4x4 block of (c,r) starts at 4c,4r, centre +1.5.
  EXPECT_FLOAT_EQ(l2.image.at(2, 3), 3.0f * (8 + 1.5f) + 100.0f * (12 + 1.5f));
  EXPECT_FLOAT_EQ(l1.image.at(5, 7), 3.0f * (10 + 0.5f) + 100.0f * (14 + 0.5f));
  EXPECT_FALSE(l1.mask.isValid(3, 2));  // block (6..7, 4..5) holds the invalid pixel
  EXPECT_FALSE(l2.mask.isValid(1, 1));
  EXPECT_EQ(l1.mask.validCount(), 18u * 11u - 1u);
  EXPECT_EQ(l2.mask.validCount(), 9u * 5u - 1u);
  ASSERT_TRUE(l2.camera.has_value());
  EXPECT_EQ(l2.camera->intrinsics().cols, 9);
  EXPECT_NEAR((l2.camera->intrinsics().principalPoint_px - camera.downsampled(2).intrinsics().principalPoint_px).norm(),
              0.0, 1e-12);
  EXPECT_NEAR(l2.camera->intrinsics().pixelSpacing_mm.x(), 1.6, 1e-12);
}

TEST(XrayPyramid, RejectsBadLevelCountsSizesAndForeignCameras) {
  const fct::FloatImage image = fct::FloatImage::filled(8, 8, 1.0f);
  const fct::ValidMask mask = fct::ValidMask::allValid(8, 8);
  EXPECT_FALSE(fct::XrayPyramid::build(image, mask, std::nullopt, 0).ok());
  EXPECT_FALSE(fct::XrayPyramid::build(image, mask, std::nullopt, 5).ok());  // 8 >> 4 = 0
  EXPECT_TRUE(fct::XrayPyramid::build(image, mask, std::nullopt, 4).ok());
  EXPECT_FALSE(fct::XrayPyramid::build(image, fct::ValidMask::allValid(8, 7), std::nullopt, 2).ok());
  EXPECT_FALSE(fct::XrayPyramid::build(image, mask, testCamera(16, 8), 2).ok());
}
