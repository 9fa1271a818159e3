#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "experiments/runner/json.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::runner {
namespace {

TEST(Json, ParsesNestedDocument) {
  const Json j = parse_json(R"({"a": [1, -2.5e3, true, null], "b": {"c": "x\"y\u00e9"}})", "t");
  ASSERT_TRUE(j.is_object());
  const auto& a = j.as_object().at("a").as_array();
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(a[0].as_number(), 1.0);
  EXPECT_EQ(a[1].as_number(), -2500.0);
  EXPECT_TRUE(a[2].as_bool());
  EXPECT_TRUE(a[3].is_null());
  EXPECT_EQ(j.as_object().at("b").as_object().at("c").as_string(), "x\"y\xc3\xa9");
}

// Each malformed document must raise InputError naming source, line and column.
TEST(Json, MalformedInputsGiveLocatedErrors) {
  const struct {
    const char* text;
    const char* expect;
  } cases[] = {
      {"{\"a\": 1,}", "expected a string key"},
      {"{\"a\" 1}", "expected ':'"},
      {"[1, 2", "expected ',' or ']'"},
      {"\"abc", "unterminated string"},
      {"01", "unexpected characters"},
      {"1.", "digits expected after '.'"},
      {"{\"a\":1, \"a\":2}", "duplicate key"},
      {"nul", "unexpected character"},
      {"{\"a\": \"\xC3\"}", "invalid UTF-8 byte \\xc3"},
      {"\"\xED\xA0\x80\"", "invalid UTF-8"},
      {"\"\xC0\xAF\"", "invalid UTF-8"},
      {"", "unexpected end of input"},
      {"\n\n  ]", "t:3:3"},
  };
  for (const auto& c : cases) {
    try {
      parse_json(c.text, "t");
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos)
          << c.text << " -> " << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("t:", 0), 0u) << e.what();
    }
  }
}

// Beyond the double range: +-infinity (overflow) or +-0 (underflow), for the
// scene reader to refuse naming the field.
TEST(Json, NumbersBeyondTheDoubleRangeBecomeInfinityOrZero) {
  const Json j = parse_json("[1e999, -1e400, 1e-999, -1e-400, 0.0000e99999, 123456789e301]", "t");
  const auto& a = j.as_array();
  EXPECT_EQ(a[0].as_number(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(a[1].as_number(), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(a[2].as_number(), 0.0);
  EXPECT_EQ(a[3].as_number(), 0.0);
  EXPECT_EQ(a[4].as_number(), 0.0);
  EXPECT_EQ(a[5].as_number(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(parse_json("\"\xC3\xA9\xF0\x9F\x98\x80\"", "t").as_string(),
            "\xC3\xA9\xF0\x9F\x98\x80");
}

TEST(Json, TooManyValuesAreRefused) {
  std::string many = "[0";
  for (int i = 0; i < (1 << 20); ++i) many += ",0";
  many += "]";
  try {
    parse_json(many, "many");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than 1048576 values"), std::string::npos);
  }
}

TEST(Json, DeepNestingIsRejectedNotOverflowed) {
  const std::string deep(100000, '[');
  EXPECT_THROW(parse_json(deep, "deep"), InputError);
}

TEST(Json, MissingFileNamesThePath) {
  try {
    read_json_file("/nonexistent/scene.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace icd::runner
