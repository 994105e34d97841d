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
  EXPECT_FALSE(fct::ValidMask::fromBytes(4, 4, std::vector<std::uint8_t>(15, 1)).ok());
  const auto fromBytes = fct::ValidMask::fromBytes(2, 2, {0, 7, 1, 0});
  ASSERT_TRUE(fromBytes.ok());
  EXPECT_EQ(fromBytes.value().validCount(), 2u);
}
