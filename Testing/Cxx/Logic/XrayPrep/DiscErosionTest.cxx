#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <limits>
#include <random>

#include "XrayPrep/DiscErosion.h"

namespace {

constexpr float kOutside = std::numeric_limits<float>::max();

/// A random image with some pixels at kOutside (the masked pixels of the metal detection).
cv::Mat randomImage(int rows, int cols, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> value(-3.0f, 5.0f);
  std::bernoulli_distribution masked(0.05);
  cv::Mat image(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x) image.at<float>(y, x) = masked(random) ? kOutside : value(random);
  return image;
}

}  // namespace

TEST(DiscErosion, MatchesOpenCvErosionWithItsEllipticElement) {
  for (const cv::Size size : {cv::Size(37, 23), cv::Size(64, 64), cv::Size(200, 150)}) {
    for (const int side : {1, 3, 9, 33, 67}) {
      const cv::Mat image = randomImage(size.height, size.width, static_cast<unsigned>(side * 1000 + size.width));
      cv::Mat expected;
      cv::erode(image, expected, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(side, side)),
                cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(kOutside));
      const cv::Mat eroded = fct::discErosion(image, side, kOutside);
      ASSERT_EQ(eroded.size(), image.size());
      EXPECT_EQ(cv::countNonZero(eroded != expected), 0) << size << " side " << side;
    }
  }
}

TEST(DiscErosion, RefusesAnEvenSideAndANonFloatImage) {
  const cv::Mat image = randomImage(10, 10, 1);
  EXPECT_THROW(fct::discErosion(image, 4, kOutside), cv::Exception);
  EXPECT_THROW(fct::discErosion(cv::Mat::zeros(10, 10, CV_8U), 3, kOutside), cv::Exception);
}
