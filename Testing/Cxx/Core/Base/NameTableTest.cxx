#include <gtest/gtest.h>

#include "Base/NameTable.h"

namespace {

enum class Colour { Red, Green, Blue };

constexpr fct::NameTable<Colour, 2> kColours{{{"red", Colour::Red}, {"green", Colour::Green}}};

}  // namespace

TEST(NameTable, NamesAndValuesRoundTrip) {
  for (const auto& [name, value] : kColours) {
    EXPECT_EQ(fct::nameOf(value, kColours), name);
    ASSERT_TRUE(fct::valueNamed(name, kColours).has_value()) << name;
    EXPECT_EQ(*fct::valueNamed(name, kColours), value);
  }
  EXPECT_EQ(fct::namesOf(kColours), "red, green");
}

TEST(NameTable, UnknownNamesAndValuesAreNotGuessed) {
  EXPECT_FALSE(fct::valueNamed("Red", kColours).has_value()) << "names are case-sensitive";
  EXPECT_FALSE(fct::valueNamed("", kColours).has_value());
  EXPECT_EQ(fct::nameOf(Colour::Blue, kColours), "unknown");
}
