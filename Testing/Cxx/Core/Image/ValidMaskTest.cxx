#include <gtest/gtest.h>

#include "Image/ValidMask.h"

TEST(ValidMask, MarginAndCirclesExcludeExactlyTheirPixels) {
  fct::ValidMask mask = fct::ValidMask::allValid(20, 10);
  mask.excludeMargin(2);
  EXPECT_EQ(mask.validCount(), 16u * 6u);
  EXPECT_FALSE(mask.isValid(1, 5));
  EXPECT_FALSE(mask.isValid(18, 5));
  EXPECT_TRUE(mask.isValid(2, 2));
  mask.excludeInside(fct::PixelCircle{{10.0, 5.0}, 1.0});  // the centre and its 4 neighbours
  EXPECT_EQ(mask.validCount(), 16u * 6u - 5u);
  mask.excludeOutside(fct::PixelCircle{{10.0, 5.0}, 3.0});
  for (const std::int32_t i : mask.pixelList()) {
    EXPECT_LE(std::hypot(i % 20 - 10.0, i / 20 - 5.0), 3.0);
    EXPECT_GT(std::hypot(i % 20 - 10.0, i / 20 - 5.0), 1.0);
  }
  EXPECT_EQ(mask.pixelList().size(), mask.validCount());
}

TEST(ValidMask, RejectsMasksOfAnotherSize) {
  fct::ValidMask mask = fct::ValidMask::allValid(4, 4);
  EXPECT_FALSE(mask.intersect(fct::ValidMask::allValid(4, 5)).ok());
  EXPECT_EQ(mask.validCount(), 16u);
  EXPECT_FALSE(mask.excludedFractionWithin(fct::ValidMask::allValid(4, 4), fct::ValidMask::allValid(5, 4)).ok());
  EXPECT_FALSE(mask.excludedFractionWithin(fct::ValidMask::allValid(3, 4), fct::ValidMask::allValid(4, 4)).ok());
  EXPECT_FALSE(fct::ValidMask::fromBytes(4, 4, std::vector<std::uint8_t>(15, 1)).ok());
  const auto fromBytes = fct::ValidMask::fromBytes(2, 2, {0, 7, 1, 0});
  ASSERT_TRUE(fromBytes.ok());
  EXPECT_EQ(fromBytes.value().validCount(), 2u);
}

TEST(ValidMask, ExcludedFractionCountsOnlyPixelsValidInBothMaskAndRegion) {
  fct::ValidMask field = fct::ValidMask::allValid(10, 10);
  field.excludeMargin(1);  // 64 field pixels
  fct::ValidMask kept = field;
  for (int col = 1; col < 9; ++col) kept.valid[static_cast<std::size_t>(2) * 10 + col] = 0;  // row 2: 8 taken out
  kept.valid[static_cast<std::size_t>(7) * 10 + 4] = 0;                                     // one pixel in row 7
  fct::ValidMask upperHalf = fct::ValidMask::allValid(10, 10);
  for (int row = 5; row < 10; ++row) {
    for (int col = 0; col < 10; ++col) upperHalf.valid[static_cast<std::size_t>(row) * 10 + col] = 0;
  }
  // Field pixels in rows 1-4: 32, of which row 2's 8 are excluded; row 7's pixel lies outside the region.
  EXPECT_DOUBLE_EQ(field.excludedFractionWithin(kept, upperHalf).value(), 8.0 / 32.0);
  EXPECT_DOUBLE_EQ(field.excludedFractionWithin(kept, fct::ValidMask::allValid(10, 10)).value(), 9.0 / 64.0);
  EXPECT_DOUBLE_EQ(field.excludedFractionWithin(field, upperHalf).value(), 0.0);
  // No pixel valid in both: nothing is taken from nothing.
  fct::ValidMask none = fct::ValidMask::allValid(10, 10);
  none.valid.assign(none.valid.size(), 0);
  EXPECT_DOUBLE_EQ(field.excludedFractionWithin(kept, none).value(), 0.0);
}
