// Unit tests of the JSON layouts: compact and spaced lines, any bytes in strings, and
// parse errors with their column.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "common/json.hpp"

namespace plcfi::common {
namespace {

TEST(Json, LayoutsKeepTheFieldOrder) {
  Json j;
  j["z"] = 1;
  j["a"] = "x\"y\n";
  j["list"] = {1, 2};
  j["nothing"] = nullptr;
  j["inner"] = Json::object();
  j["inner"]["k"] = true;
  EXPECT_EQ(json_compact(j), R"({"z":1,"a":"x\"y\n","list":[1,2],"nothing":null,"inner":{"k":true}})");
  EXPECT_EQ(json_line(j), R"({"z": 1, "a": "x\"y\n", "list": [1, 2], "nothing": null, "inner": {"k": true}})");
  EXPECT_EQ(json_line(Json::array()), "[]");
}

TEST(Json, InvalidUtf8IsReplacedNotThrown) {
  Json j = std::string("a\xff" "b");
  EXPECT_EQ(json_compact(j), "\"a\xEF\xBF\xBD" "b\"");
}

// Random strings of every byte 1..127 survive a write and a read.
TEST(Json, GeneratedStringsRoundTrip) {
  std::mt19937 rng(5);
  for (int iter = 0; iter < 2000; ++iter) {
    std::string s;
    const size_t n = rng() % 40;
    for (size_t i = 0; i < n; ++i) s += static_cast<char>(1 + rng() % 127);
    Json j;
    j["s"] = s;
    Json back;
    std::string err;
    size_t column = 0;
    ASSERT_TRUE(json_parse(json_compact(j), &back, &err, &column)) << err;
    EXPECT_EQ(back["s"].get<std::string>(), s);
  }
}

TEST(Json, ParseErrorsGiveReasonAndColumn) {
  Json j;
  std::string err;
  size_t column = 0;
  EXPECT_FALSE(json_parse("{\"a\":1,}", &j, &err, &column));
  EXPECT_EQ(column, 8u);
  EXPECT_EQ(err.rfind("syntax error", 0), 0u) << err;
  EXPECT_FALSE(json_parse("not json", &j, &err, &column));
  EXPECT_EQ(column, 2u);
}

}  // namespace
}  // namespace plcfi::common
