// Unit tests of the strict YAML reader: duplicate keys anywhere (generated documents),
// unknown and missing keys, every typed getter's exact "FILE:LINE:COL: message".
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include "common/yaml.hpp"

namespace plcfi::common {
namespace {

// The message of the InputError that f throws; "" when it throws none.
template <class F>
std::string error_of(F&& f) {
  std::string err;
  return catch_input_error(&err, std::forward<F>(f)) ? std::string() : err;
}

std::string parse_error(const std::string& text) {
  return error_of([&] { YamlDoc::parse("f.yaml", text); });
}

TEST(Yaml, DuplicateKeysAreErrorsAtEveryLevel) {
  EXPECT_EQ(parse_error("a: 1\nb: 2\na: 3\n"), "f.yaml:3:1: duplicate key 'a' (first at 1:1)");
  EXPECT_EQ(parse_error("top:\n  x: 1\n  x: 2\n"), "f.yaml:3:3: duplicate key 'x' (first at 2:3)");
  EXPECT_EQ(parse_error("list:\n  - {k: 1, k: 2}\n"), "f.yaml:2:12: duplicate key 'k' (first at 2:6)");
  EXPECT_EQ(parse_error("a: 1\nb: {a: 1}\n"), "");  // the same key in two maps is fine
}

// Documents of random maps nested in lists and maps, with one duplicate planted at a
// random place: the error names exactly that line and column and the first one.
TEST(Yaml, GeneratedDocumentsReportThePlantedDuplicate) {
  std::mt19937 rng(1131);
  for (int iter = 0; iter < 300; ++iter) {
    const int sections = 1 + static_cast<int>(rng() % 5);
    const int target = static_cast<int>(rng() % static_cast<unsigned>(sections));
    std::string text;
    int line = 0;
    std::string expected;
    for (int s = 0; s < sections; ++s) {
      const bool as_list = rng() % 2 == 0;
      text += "section" + std::to_string(s) + ":\n";
      ++line;
      const std::string indent = as_list ? "    " : "  ";
      if (as_list) {
        text += "  -\n";
        ++line;
      }
      const int keys = 2 + static_cast<int>(rng() % 6);
      int first_line = 0;
      int dup_of = -1;
      if (s == target) dup_of = static_cast<int>(rng() % static_cast<unsigned>(keys - 1));
      for (int k = 0; k < keys; ++k) {
        ++line;
        const bool plant = s == target && k == keys - 1;
        const int name = plant ? dup_of : k;
        if (s == target && k == dup_of) first_line = line;
        text += indent + "key" + std::to_string(name) + ": " + std::to_string(rng() % 1000) + "\n";
        if (plant) {
          const std::string col = std::to_string(indent.size() + 1);
          expected = "f.yaml:" + std::to_string(line) + ":" + col + ": duplicate key 'key" + std::to_string(dup_of) +
                     "' (first at " + std::to_string(first_line) + ":" + col + ")";
        }
      }
    }
    ASSERT_EQ(parse_error(text), expected) << text;
  }
}

TEST(Yaml, SyntaxErrorsAndFileErrorsAreLocated) {
  const std::string e = parse_error("a: [1, 2\nb: 3\n");
  EXPECT_EQ(e.rfind("f.yaml:", 0), 0u) << e;
  EXPECT_NE(e.find("end of sequence"), std::string::npos) << e;
  const std::string dir = std::filesystem::temp_directory_path().string();
  EXPECT_EQ(error_of([&] { YamlDoc::open(dir); }), dir + ": is a directory");
  EXPECT_EQ(error_of([&] { YamlDoc::open("/dev/zero"); }), "/dev/zero: is larger than 16 MiB");
  // Aliases of aliases: a few lines that expand beyond any real spec.
  std::string bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n";
  for (char c = 'b'; c <= 'k'; ++c) {
    const std::string prev(1, static_cast<char>(c - 1));
    bomb += std::string(1, c) + ": &" + c + " [*" + prev + ", *" + prev + ", *" + prev + ", *" + prev + ", *" + prev + ", *" +
            prev + ", *" + prev + ", *" + prev + ", *" + prev + ", *" + prev + "]\n";
  }
  EXPECT_EQ(parse_error(bomb), "f.yaml:1:1: the document expands to too many nodes (aliases of aliases?)");
}

TEST(Yaml, KeysKnownAndRequired) {
  const YamlDoc doc = YamlDoc::parse("f.yaml", "name: x\ncolour: red\nsub: 5\n");
  EXPECT_EQ(error_of([&] { doc.check_keys(doc.root(), {"name", "color", "sub"}, "a widget"); }),
            "f.yaml:2:1: unknown key 'colour' in a widget (expected one of: name, color, sub)");
  EXPECT_EQ(error_of([&] { doc.required(doc.root(), "size", "a widget"); }), "f.yaml:1:1: missing key 'size' in a widget");
  EXPECT_EQ(error_of([&] { doc.check_keys(doc.root()["sub"], {"a"}, "sub"); }), "f.yaml:3:6: sub: expected a map, got '5'");
  EXPECT_EQ(error_of([&] { doc.list(doc.root()["sub"], "sub"); }), "f.yaml:3:6: sub: expected a list, got '5'");
  const YamlDoc empty = YamlDoc::parse("g.yaml", "s:\nl: []\n");
  EXPECT_EQ(error_of([&] { empty.check_keys(empty.root()["s"], {"a"}, "s", true); }), "");
  // yaml-cpp places an empty value at the next token: here the start of line 2.
  EXPECT_EQ(error_of([&] { empty.check_keys(empty.root()["s"], {"a"}, "s"); }), "g.yaml:2:1: s: expected a map, got nothing");
  EXPECT_EQ(error_of([&] { empty.list(empty.root()["l"], "l"); }), "g.yaml:2:4: l: expected a non-empty list, got an empty one");
}

TEST(Yaml, TypedGettersAndTheirMessages) {
  const YamlDoc doc = YamlDoc::parse("f.yaml",
                                     "i: 42\nh: 0x1F\nneg: -7\nbad: 4x2\nbig: 300\n"
                                     "n: 2.5e3\nnan: .nan\nb: TRUE\nb2: maybe\n"
                                     "d: 1.2.3ms\nq: \"1.2.3ms\"\nok: T#8.2ms\nzero: 0s\nminus: -1s\n"
                                     "w: warm\nw2: hot\nlist: [1]\n");
  const YAML::Node& r = doc.root();
  EXPECT_EQ(doc.integer(r["i"], "i"), 42);
  EXPECT_EQ(doc.integer(r["h"], "h"), 31);
  EXPECT_EQ(doc.integer(r["neg"], "neg", -10, 10), -7);
  EXPECT_EQ(error_of([&] { doc.integer(r["bad"], "bad"); }), "f.yaml:4:6: bad: expected an integer, got '4x2'");
  EXPECT_EQ(error_of([&] { doc.integer(r["big"], "unit", 0, 247); }), "f.yaml:5:6: unit: 300 is outside 0..247");
  EXPECT_EQ(doc.number(r["n"], "n"), 2500.0);
  EXPECT_EQ(error_of([&] { doc.number(r["nan"], "nan"); }), "f.yaml:7:6: nan: expected a number, got '.nan'");
  EXPECT_TRUE(doc.boolean(r["b"], "b"));
  EXPECT_EQ(error_of([&] { doc.boolean(r["b2"], "b2"); }), "f.yaml:9:5: b2: expected true or false, got 'maybe'");
  // The column points at the trouble inside the value (after a quote when quoted).
  EXPECT_EQ(error_of([&] { doc.duration(r["d"], "d"); }),
            "f.yaml:10:7: d: expected a duration, got '1.2.3ms': unexpected '.' after '1.2'");
  EXPECT_EQ(error_of([&] { doc.duration(r["q"], "q"); }),
            "f.yaml:11:8: q: expected a duration, got '1.2.3ms': unexpected '.' after '1.2'");
  EXPECT_EQ(doc.duration(r["ok"], "ok"), 8'200'000);
  EXPECT_EQ(error_of([&] { doc.duration(r["zero"], "zero", 1); }), "f.yaml:13:7: zero: must be positive, got '0s'");
  EXPECT_EQ(error_of([&] { doc.duration(r["minus"], "minus"); }), "f.yaml:14:8: minus: must not be negative, got '-1s'");
  EXPECT_EQ(doc.word(r["w"], "w", {"cold", "warm"}), "warm");
  EXPECT_EQ(error_of([&] { doc.word(r["w2"], "restart", {"cold", "warm"}); }),
            "f.yaml:16:5: restart: expected cold or warm, got 'hot'");
  EXPECT_EQ(error_of([&] { doc.scalar(r["list"], "list"); }), "f.yaml:17:7: list: expected a single value, got a list");
  EXPECT_EQ(error_of([&] { doc.number(r["list"], "list"); }), "f.yaml:17:7: list: expected a number, got a list");
  EXPECT_EQ(error_of([&] { doc.integer(r["list"], "list"); }), "f.yaml:17:7: list: expected an integer, got a list");
  EXPECT_EQ(error_of([&] { doc.duration(r["list"], "list"); }), "f.yaml:17:7: list: expected a duration, got a list");
  EXPECT_EQ(error_of([&] { doc.boolean(r["list"], "list"); }), "f.yaml:17:7: list: expected true or false, got a list");
}

// Random integers against random ranges: inside, the value; outside, the exact message.
TEST(Yaml, GeneratedIntegersAgainstRanges) {
  std::mt19937_64 rng(99);
  for (int iter = 0; iter < 2000; ++iter) {
    const int64_t lo = static_cast<int64_t>(rng() % 2000) - 1000;
    const int64_t hi = lo + static_cast<int64_t>(rng() % 2000);
    const int64_t v = static_cast<int64_t>(rng() % 6000) - 3000;
    const YamlDoc doc = YamlDoc::parse("g.yaml", "x:\n  value: " + std::to_string(v) + "\n");
    const YAML::Node n = doc.root()["x"]["value"];
    int64_t got = 0;
    const std::string err = error_of([&] { got = doc.integer(n, "x.value", lo, hi); });
    if (v >= lo && v <= hi) {
      EXPECT_EQ(err, "");
      EXPECT_EQ(got, v);
    } else {
      EXPECT_EQ(err, "g.yaml:2:10: x.value: " + std::to_string(v) + " is outside " + std::to_string(lo) + ".." +
                         std::to_string(hi));
    }
  }
}

}  // namespace
}  // namespace plcfi::common
