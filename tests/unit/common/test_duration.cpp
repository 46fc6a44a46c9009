// Unit tests of the one duration parser: exact values, every malformed form with its
// message and offset, generated durations read back, and agreement with the ST lexer.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/duration.hpp"
#include "runtime/schedule.hpp"
#include "st/syntax/lexer.hpp"

namespace plcfi::common {
namespace {

__extension__ typedef __int128 I128;

// The ST lexer's value of T#<body>: ok and the value, or !ok with the ST008 message.
struct Lexed {
  bool ok = false;
  int64_t ns = 0;
  std::string message;
};

Lexed lex_duration(const std::string& body) {
  st::SourceManager sm;
  st::DiagEngine diags{sm};
  const uint32_t f = sm.add("t.st", "T#" + body);
  const auto toks = st::lex_file(sm, f, diags);
  Lexed out;
  out.ok = !diags.has_errors() && toks.size() == 2 && toks[0].kind == st::Tok::TimeLit;
  if (out.ok) out.ns = toks[0].time_ns;
  if (!diags.all().empty()) out.message = diags.all().front().message;
  return out;
}

TEST(Duration, ExactValues) {
  const std::vector<std::pair<std::string, int64_t>> cases = {
      {"8.2ms", 8'200'000},
      {"T#8.2ms", 8'200'000},
      {"10ms", 10'000'000},
      {"1h30m", 5'400 * kNsPerS},
      {"1d2h3m4s5ms6us7ns", kNsPerDay + 2 * kNsPerHour + 3 * kNsPerMin + 4 * kNsPerS + 5 * kNsPerMs + 6 * kNsPerUs + 7},
      {"1s_500ms", 1'500'000'000},
      {"1_000ms", kNsPerS},
      {"TIME#5S", 5 * kNsPerS},
      {"ltime#1us", 1'000},
      {"LT#1ns", 1},
      {"-5s", -5 * kNsPerS},
      {"+5s", 5 * kNsPerS},
      {"0.5ms", 500'000},
      {"2.5h", 9'000 * kNsPerS},
      {"1.000000001s", 1'000'000'001},
      {"1.001us", 1'001},
      {"0.1s", 100'000'000},
      {"0.3m", 18 * kNsPerS},
      {"1.5000000000000000000000s", 1'500'000'000},  // trailing zeros are exact
      {"106751d23h47m16s854ms775us807ns", std::numeric_limits<int64_t>::max()},
      {"-106751d23h47m16s854ms775us808ns", std::numeric_limits<int64_t>::min()},
      {"0s", 0},
  };
  for (const auto& [text, ns] : cases) {
    const DurationParse r = parse_duration(text);
    EXPECT_TRUE(r.ok()) << text << ": " << r.error;
    EXPECT_EQ(r.ns, ns) << text;
  }
}

TEST(Duration, MalformedTextIsRejectedWithTheOffset) {
  struct Case {
    std::string text;
    size_t at;
    std::string message;
  };
  const std::string units = " (use d, h, m, s, ms, us or ns)";
  const std::vector<Case> cases = {
      {"1.2.3ms", 3, "unexpected '.' after '1.2'"},
      {"5", 1, "missing duration unit after '5'" + units},
      {"ms", 0, "expected a number before 'ms'"},
      {"1.5.ms", 3, "unexpected '.' after '1.5'"},
      {"10xs", 2, "unknown duration unit 'xs'" + units},
      {"5sec", 1, "unknown duration unit 'sec'" + units},
      {"1.ms", 2, "expected digits after the decimal point in '1.'"},
      {"1.5ns", 0, "'1.5ns' is not a whole number of nanoseconds"},
      {"1.0001us", 0, "'1.0001us' is not a whole number of nanoseconds"},
      {"1s1.00000000001s", 2, "'1.00000000001s' is not a whole number of nanoseconds"},
      {"", 0, "expected a duration such as 1h2m3s4ms"},
      {"T#", 2, "expected a duration such as 1h2m3s4ms"},
      {"-", 1, "expected a duration such as 1h2m3s4ms"},
      {"1s 5ms", 2, "unexpected ' '"},
      {"500 parsecs", 3, "unexpected ' ' after '500'"},
      {"1s5", 3, "missing duration unit after '5'" + units},
      {"106751d23h47m16s854ms775us808ns", 26, "out of range (at most 106751d23h47m16s854ms775us807ns, about 292 years)"},
      {"99999999999999999999s", 0, "out of range (at most 106751d23h47m16s854ms775us807ns, about 292 years)"},
      {"X#5s", 0, "unknown prefix 'X#' (use T#, TIME#, LT# or LTIME#)"},
      {"T#1.2.3ms", 5, "unexpected '.' after '1.2'"},
  };
  for (const auto& c : cases) {
    const DurationParse r = parse_duration(c.text);
    EXPECT_FALSE(r.ok()) << c.text << " = " << r.ns;
    EXPECT_EQ(r.error, c.message) << c.text;
    EXPECT_EQ(r.error_at, c.at) << c.text;
  }
  int64_t ns = 0;
  std::string err;
  EXPECT_FALSE(parse_duration(std::string_view("1.2.3ms"), &ns, &err));
  EXPECT_EQ(err, "'1.2.3ms' is not a duration: unexpected '.' after '1.2'");
}

TEST(Duration, OptionParserDelegatesAndRejectsNegatives) {
  int64_t ns = 0;
  std::string err;
  ASSERT_TRUE(rt::parse_duration("8.2ms", &ns, &err)) << err;
  EXPECT_EQ(ns, 8'200'000);  // through double this was 8,199,999
  EXPECT_FALSE(rt::parse_duration("1.2.3ms", &ns, &err));
  EXPECT_EQ(err, "'1.2.3ms' is not a duration: unexpected '.' after '1.2'");
  EXPECT_FALSE(rt::parse_duration("-5s", &ns, &err));
  EXPECT_EQ(err, "'-5s': a duration here must not be negative");
}

TEST(Duration, FormatReadsBack) {
  std::mt19937_64 rng(20261124);
  std::vector<int64_t> values = {0, 1, -1, std::numeric_limits<int64_t>::max(), std::numeric_limits<int64_t>::min(),
                                 kNsPerDay, 8'200'000};
  for (int i = 0; i < 5000; ++i) values.push_back(static_cast<int64_t>(rng()));
  for (int i = 0; i < 5000; ++i) values.push_back(static_cast<int64_t>(rng() % 100'000'000'000'000ULL) - 50'000'000'000'000LL);
  for (int64_t v : values) {
    const std::string text = format_duration(v);
    const DurationParse r = parse_duration(text);
    ASSERT_TRUE(r.ok()) << text << ": " << r.error;
    EXPECT_EQ(r.ns, v) << text;
  }
  EXPECT_EQ(format_duration(5'400 * kNsPerS + 1), "1h30m1ns");
  EXPECT_EQ(format_duration(-5 * kNsPerS), "-5s");
}

// Random texts built from parts whose exact value the test computes on its own (128-bit):
// every spelling the grammar allows (any case, '_' separators, fractions exact in the
// unit, a sign, prefixes) must give that value, and a sum beyond int64 must be an error.
TEST(Duration, GeneratedTextsGiveTheirValueAndTheLexerAgrees) {
  struct Unit {
    const char* name;
    int64_t ns;
    int exact_digits;  // fraction digits that always come out in whole ns
  };
  const Unit units[] = {{"d", kNsPerDay, 11}, {"h", kNsPerHour, 11}, {"m", kNsPerMin, 10}, {"s", kNsPerS, 9},
                        {"ms", kNsPerMs, 6},  {"us", kNsPerUs, 3},   {"ns", 1, 0}};
  std::mt19937_64 rng(61131);
  auto pick = [&](uint64_t n) { return rng() % n; };
  const char* prefixes[] = {"", "T#", "t#", "TIME#", "time#", "LT#", "LTIME#"};
  int ok_count = 0, overflow_count = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    std::string body;
    I128 expected = 0;
    const bool negative = pick(4) == 0;
    if (negative) body += '-';
    else if (pick(8) == 0) body += '+';
    const int parts = 1 + static_cast<int>(pick(4));
    for (int p = 0; p < parts; ++p) {
      if (p > 0 && pick(3) == 0) body += '_';
      const Unit& u = units[pick(7)];
      // Mostly small counts, sometimes huge ones (overflow).
      const uint64_t count = pick(10) == 0 ? rng() % 10'000'000'000'000'000'000ULL : pick(pick(2) ? 100 : 100'000);
      std::string digits = std::to_string(count);
      if (digits.size() > 3 && pick(4) == 0) digits.insert(1, "_");
      body += digits;
      expected += static_cast<I128>(count) * u.ns;
      if (u.exact_digits > 0 && pick(3) == 0) {
        const int k = 1 + static_cast<int>(pick(static_cast<uint64_t>(u.exact_digits)));
        std::string frac;
        for (int d = 0; d < k; ++d) frac += static_cast<char>('0' + pick(10));
        body += "." + frac;
        I128 scale = 1;
        for (int d = 0; d < k; ++d) scale *= 10;
        expected += static_cast<I128>(std::stoull(frac)) * u.ns / scale;
      }
      std::string name = u.name;
      if (pick(2)) for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      body += name;
    }
    if (negative) expected = -expected;
    const std::string text = prefixes[pick(7)] + body;
    const DurationParse r = parse_duration(text);
    const bool fits = expected >= std::numeric_limits<int64_t>::min() && expected <= std::numeric_limits<int64_t>::max();
    const Lexed lexed = lex_duration(body);
    if (fits) {
      ++ok_count;
      ASSERT_TRUE(r.ok()) << text << ": " << r.error;
      ASSERT_EQ(r.ns, static_cast<int64_t>(expected)) << text;
      ASSERT_TRUE(lexed.ok) << "T#" << body << ": " << lexed.message;
      ASSERT_EQ(lexed.ns, r.ns) << "T#" << body;
    } else {
      ++overflow_count;
      ASSERT_FALSE(r.ok()) << text << " = " << r.ns;
      ASSERT_NE(r.error.find("out of range"), std::string::npos) << text << ": " << r.error;
      ASSERT_FALSE(lexed.ok) << "T#" << body;
    }
  }
  // The generator must exercise both sides.
  EXPECT_GT(ok_count, 10000);
  EXPECT_GT(overflow_count, 100);
}

// Mutated texts (a character inserted, removed or replaced): whatever the parser says, the
// lexer says the same: both accept with the same value, or both reject with the same message.
TEST(Duration, LexerAndParserAgreeOnMutatedTexts) {
  std::mt19937_64 rng(4242);
  const std::string alphabet = "0123456789._dhmsunxDHMS";
  const std::vector<std::string> seeds = {"1h2m3s4ms5us6ns", "8.2ms", "1s_500ms", "1_000ms", "2.5h", "1.2.3ms",
                                          "5", "10xs", "1.5.ms", "0.5us", "1d"};
  int rejected = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    std::string t = seeds[rng() % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      const size_t at = t.empty() ? 0 : rng() % (t.size() + 1);
      const char c = alphabet[rng() % alphabet.size()];
      switch (rng() % 3) {
        case 0: t.insert(t.begin() + static_cast<std::ptrdiff_t>(at), c); break;
        case 1: if (at < t.size()) t.erase(at, 1); break;
        default: if (at < t.size()) t[at] = c; break;
      }
    }
    const DurationParse r = parse_duration_body(t);
    const Lexed lexed = lex_duration(t);
    ASSERT_EQ(r.ok(), lexed.ok) << "'" << t << "': parser '" << r.error << "', lexer '" << lexed.message << "'";
    if (r.ok()) {
      ASSERT_EQ(r.ns, lexed.ns) << t;
    } else {
      ++rejected;
      // The lexer's message is "T#TEXT: REASON".
      ASSERT_EQ(lexed.message, "T#" + t + ": " + r.error) << "parser '" << r.error << "'";
    }
  }
  EXPECT_GT(rejected, 1000);
}

}  // namespace
}  // namespace plcfi::common
