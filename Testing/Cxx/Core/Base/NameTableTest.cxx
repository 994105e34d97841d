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

TEST(NameTable, ReadNamedReadsTheValueOrRejectsTheKeyListingTheNames) {
  const nlohmann::json object = {{"good", "green"}, {"bad", "pink"}, {"number", 3}};
  fct::JsonReader reader(object, "f.json");
  EXPECT_EQ(fct::readNamed(reader, "good", kColours, "red or green"), Colour::Green);
  EXPECT_TRUE(reader.ok());
  EXPECT_FALSE(fct::readNamed(reader, "bad", kColours, "red or green").has_value());
  EXPECT_EQ(reader.error(), "f.json: key 'bad' is 'pink'; use red or green");
  fct::JsonReader second(object, "f.json");
  EXPECT_FALSE(fct::readNamed(second, "number", kColours, "red or green").has_value());
  EXPECT_NE(second.error().find("key 'number' must be a string"), std::string::npos) << second.error();
}
