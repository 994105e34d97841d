#include <gtest/gtest.h>

#include <cmath>

#include "XrayPrep/GridBeadDetector.h"

namespace {

/// A bright 120x100 image (value 1000) with dark discs of radius 2.5 px at the given sub-pixel centres; the disc
/// edge is anti-aliased by 4x4 supersampling.
fct::FloatImage discs(const std::vector<Eigen::Vector2d>& centres) {
  fct::FloatImage image = fct::FloatImage::filled(120, 100, 1000.0f);
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      double covered = 0.0;
      for (int sy = 0; sy < 4; ++sy) {
        for (int sx = 0; sx < 4; ++sx) {
          const Eigen::Vector2d p(col - 0.375 + 0.25 * sx, row - 0.375 + 0.25 * sy);
          for (const Eigen::Vector2d& c : centres) covered += (p - c).norm() <= 2.5 ? 1.0 / 16 : 0.0;
        }
      }
      image.at(col, row) = static_cast<float>(1000.0 * (1.0 - 0.6 * covered));
    }
  }
  return image;
}

}  // namespace

TEST(GridBeadDetector, FindsDiscCentresToAFewHundredthsOfAPixel) {
  const std::vector<Eigen::Vector2d> centres{{20.3, 30.7}, {60.0, 50.25}, {95.8, 20.1}, {40.45, 80.9}};
  const fct::FloatImage image = discs(centres);
  auto beads = fct::GridBeadDetector().detect(image, fct::ValidMask::allValid(image.cols, image.rows));
  ASSERT_TRUE(beads.ok()) << beads.error();
  ASSERT_EQ(beads.value().size(), centres.size());
  for (const Eigen::Vector2d& c : centres) {
    double best = 1e9;
    for (const fct::PixelCircle& bead : beads.value()) best = std::min(best, (bead.centre_px - c).norm());
    EXPECT_LT(best, 0.03) << c.transpose();
  }
}

TEST(GridBeadDetector, SkipsBeadsCutByTheBorderOrTheMaskAndAFlatImageHasNone) {
  const fct::FloatImage image = discs({{1.5, 50.0}, {60.0, 50.0}, {100.0, 50.0}});
  fct::ValidMask mask = fct::ValidMask::allValid(image.cols, image.rows);
  mask.excludeInside({Eigen::Vector2d(104.0, 50.0), 3.0});
  auto beads = fct::GridBeadDetector().detect(image, mask);
  ASSERT_TRUE(beads.ok()) << beads.error();
  ASSERT_EQ(beads.value().size(), 1u);
  EXPECT_LT((beads.value()[0].centre_px - Eigen::Vector2d(60.0, 50.0)).norm(), 0.05);
  const fct::FloatImage flat = fct::FloatImage::filled(50, 40, 500.0f);
  auto none = fct::GridBeadDetector().detect(flat, fct::ValidMask::allValid(50, 40));
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none.value().empty());
}

TEST(GridBeadDetector, RejectsBadOptionsAMismatchedMaskAndANonPositiveBackground) {
  const fct::FloatImage image = fct::FloatImage::filled(50, 40, 500.0f);
  EXPECT_FALSE(fct::GridBeadDetector({3.0, 2.0, 0.1}).detect(image, fct::ValidMask::allValid(50, 40)).ok());
  EXPECT_FALSE(fct::GridBeadDetector().detect(image, fct::ValidMask::allValid(40, 50)).ok());
  auto negative = fct::GridBeadDetector().detect(fct::FloatImage::filled(50, 40, -1.0f), fct::ValidMask::allValid(50, 40));
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.error().find("background"), std::string::npos) << negative.error();
}
