#include <gtest/gtest.h>

#include "Base/JsonDocument.h"
#include "Base/JsonReader.h"

TEST(JsonDocument, FormatKeepsNumberRowsOnOneLineAndRoundTripsDoublesExactly) {
  Eigen::Matrix2d m;
  m << 0.1, 1.0 / 3.0, -2e-17, 12345.678901234567;
  const nlohmann::ordered_json document{{"name", "ÄP \"x\""}, {"m", fct::JsonDocument::array(m)}, {"empty", {}}};
  const std::string text = fct::JsonDocument::format(document);
  EXPECT_NE(text.find("\n    [0.1, 0.3333333333333333],\n"), std::string::npos) << text;
  const auto parsed = fct::JsonDocument::parseText(text, "mem");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  fct::JsonReader reader(parsed.value(), "mem");
  EXPECT_EQ(reader.matrix("m", 2, 2), Eigen::MatrixXd(m));
  EXPECT_EQ(reader.string("name"), "ÄP \"x\"");
  EXPECT_TRUE(reader.ok());
}

TEST(JsonDocument, ParseErrorsNameSourceLineColumnAndKeyPath) {
  auto parsed = fct::JsonDocument::parseText("// comment\n{\"a\": [1, {\"b\": Infinity}]}", "f.json");
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.error().find("f.json: not valid JSON: parse error at line 2, column"), std::string::npos)
      << parsed.error();
  EXPECT_NE(parsed.error().find("'a[1].b'"), std::string::npos) << parsed.error();
  EXPECT_NE(parsed.error().find("JSON has no NaN or Infinity"), std::string::npos) << parsed.error();
  parsed = fct::JsonDocument::parseText("{\"a\": 1e999}", "f.json");
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.error().find("f.json: not valid JSON"), std::string::npos) << parsed.error();
  EXPECT_FALSE(fct::JsonDocument::parseText("", "f.json").ok());
}

TEST(JsonReader, FirstErrorWinsAndNamesPlaceAndKey) {
  const nlohmann::json object = {{"d", {{"n", 2.5}, {"s", "x"}}}, {"i", 3}};
  fct::JsonReader reader(object, "here");
  EXPECT_EQ(reader.number("d.n"), 2.5);
  EXPECT_EQ(reader.integer("i", 1), 3);
  EXPECT_TRUE(reader.ok());
  EXPECT_EQ(reader.integer("d.n", 0), 0);
  EXPECT_EQ(reader.error(), "here: key 'd.n' must be a whole number >= 0, got 2.5");
  EXPECT_EQ(reader.number("d.s"), 0.0);
  EXPECT_EQ(reader.error(), "here: key 'd.n' must be a whole number >= 0, got 2.5");
  fct::JsonReader notObject(nlohmann::json::array(), "there");
  EXPECT_EQ(notObject.error(), "there: must be a JSON object {...}, got an array of 0 values");
}

TEST(JsonReader, BooleanAcceptsOnlyTrueOrFalse) {
  const nlohmann::json object = {{"on", true}, {"off", false}, {"word", "yes"}};
  fct::JsonReader reader(object, "here");
  EXPECT_TRUE(reader.boolean("on"));
  EXPECT_FALSE(reader.boolean("off"));
  EXPECT_TRUE(reader.ok());
  EXPECT_FALSE(reader.boolean("word"));
  EXPECT_EQ(reader.error(), "here: key 'word' must be true or false, got the string \"yes\"");
  fct::JsonReader missing(object, "there");
  EXPECT_FALSE(missing.boolean("gone"));
  EXPECT_EQ(missing.error(), "there: key 'gone' is missing");
}
