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

TEST(JsonReader, ArrayAndObjectReturnTheContainerOrRejectTheKeyWithWhatWasExpected) {
  const nlohmann::json object = {{"list", {1, 2}}, {"map", {{"a", 1}}}, {"n", 3}};
  fct::JsonReader reader(object, "here");
  ASSERT_NE(reader.array("list", "an array of numbers"), nullptr);
  EXPECT_EQ(reader.array("list", "an array of numbers")->size(), 2u);
  ASSERT_NE(reader.object("map", "an object of numbers"), nullptr);
  EXPECT_TRUE(reader.ok());
  EXPECT_EQ(reader.array("map", "an array of numbers"), nullptr);
  EXPECT_EQ(reader.error(), "here: key 'map' must be an array of numbers, got an object");
  fct::JsonReader second(object, "here");
  EXPECT_EQ(second.object("n", "an object {<view>: fraction}"), nullptr);
  EXPECT_EQ(second.error(), "here: key 'n' must be an object {<view>: fraction}, got 3");
  fct::JsonReader third(object, "here");
  EXPECT_EQ(third.array("missing", "an array"), nullptr);
  EXPECT_EQ(third.error(), "here: key 'missing' is missing");
}

TEST(JsonReader, FormatVersionAcceptsOneToNewestAndNamesTheKindOrTheUpdate) {
  const nlohmann::json current = {{"format", "fluoroct-x"}, {"version", 2}};
  fct::JsonReader ok(current, "f.json");
  EXPECT_EQ(ok.formatVersion("fluoroct-x", "x file", 2), 2);
  EXPECT_TRUE(ok.ok());
  const nlohmann::json foreign = {{"format", "other"}, {"version", 1}};
  fct::JsonReader other(foreign, "f.json");
  EXPECT_EQ(other.formatVersion("fluoroct-x", "x file", 2), 0);
  EXPECT_EQ(other.error(), "f.json: key 'format' is 'other', not 'fluoroct-x': this is not a FluoroCT x file");
  const nlohmann::json future = {{"format", "fluoroct-x"}, {"version", 3}};
  fct::JsonReader newer(future, "f.json");
  EXPECT_EQ(newer.formatVersion("fluoroct-x", "x file", 2), 0);
  EXPECT_EQ(newer.error(), "f.json: key 'version' is 3; this program reads versions 1 to 2 (update FluoroCT)");
  const nlohmann::json versionZero = {{"format", "fluoroct-x"}, {"version", 0}};
  fct::JsonReader zero(versionZero, "f.json");
  EXPECT_EQ(zero.formatVersion("fluoroct-x", "x file", 2), 0);
  EXPECT_FALSE(zero.ok());
}
