#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "Base/LargePages.h"

TEST(LargePages, AssignGivesCountCopiesOfTheFillWhateverTheSize) {
  for (const std::size_t count : {std::size_t{0}, std::size_t{3}, std::size_t{40'000'000}}) {
    std::vector<float> values(17, -1.0f);
    fct::assignWithLargePages(values, count, 2.5f);
    ASSERT_EQ(values.size(), count);
    EXPECT_TRUE(std::all_of(values.begin(), values.end(), [](float v) { return v == 2.5f; }));
  }
}

TEST(LargePages, AdviceOnRangesSmallerThanAPageOrUnalignedChangesNothing) {
  std::vector<float> values(1000, 1.0f);
  fct::adviseLargePages(values.data() + 1, 10);
  fct::adviseLargePages(values.data(), values.size() * sizeof(float));
  fct::adviseLargePages(nullptr, 0);
  EXPECT_TRUE(std::all_of(values.begin(), values.end(), [](float v) { return v == 1.0f; }));
}

TEST(LargePages, AllocatedBuffersHoldWhatIsWritten) {
  for (const std::size_t count : {std::size_t{1}, std::size_t{40'000'000}}) {
    std::unique_ptr<float[]> values = fct::allocateWithLargePages(count);
    for (std::size_t n = 0; n < count; n += 4093) values[n] = static_cast<float>(n);
    values[count - 1] = -1.0f;
    for (std::size_t n = 0; n + 1 < count; n += 4093) ASSERT_EQ(values[n], static_cast<float>(n));
    EXPECT_EQ(values[count - 1], -1.0f);
  }
}
