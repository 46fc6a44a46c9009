// The one IEC 61131-3 duration parser: ST literals (T#1h2m), spec files and command-line
// options all read durations through it, exactly, in integer nanoseconds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace plcfi::common {

inline constexpr int64_t kNsPerUs = 1'000;
inline constexpr int64_t kNsPerMs = 1'000'000;
inline constexpr int64_t kNsPerS = 1'000'000'000;
inline constexpr int64_t kNsPerMin = 60 * kNsPerS;
inline constexpr int64_t kNsPerHour = 60 * kNsPerMin;
inline constexpr int64_t kNsPerDay = 24 * kNsPerHour;

// The result of a parse: the value, or an error message and the offset in the text where
// the trouble starts (for a caret or a column).
struct DurationParse {
  int64_t ns = 0;
  std::string error;     // empty: ok
  size_t error_at = 0;   // offset into the parsed text
  bool beyond_signed = false;  // parse_unsigned_duration_body: above INT64_MAX
  bool ok() const { return error.empty(); }
};

// Parses what follows the '#' of a duration literal: an optional sign, then one or more
// parts NUMBER[.FRACTION]UNIT with the units d h m s ms us ns (any case), '_' between
// digits and between parts ("1h_30m", "1_000ms"). The arithmetic is exact: "8.2ms" is
// 8,200,000 ns; a fraction finer than 1 ns, a value beyond int64 nanoseconds (about 292
// years) and malformed text ("1.2.3ms", "5", "ms", "10xs") are errors.
DurationParse parse_duration_body(std::string_view body);
// LTIME as CODESYS and TwinCAT hold it: unsigned 64-bit nanoseconds, up to
// 213503d23h34m33s709ms551us615ns (2^64 - 1). `ns` holds the bits; `beyond_signed` says the
// value is above INT64_MAX (then it is no signed duration). A negative value keeps the
// signed limit.
DurationParse parse_unsigned_duration_body(std::string_view body);

// The same, with an optional T#, TIME#, LT# or LTIME# prefix (any case): the form of
// spec files and options. error_at counts from the start of `text`, prefix included.
DurationParse parse_duration(std::string_view text);

// Convenience for options and spec values: on failure *err reads
// "'TEXT' is not a duration: MESSAGE".
bool parse_duration(std::string_view text, int64_t* ns, std::string* err);

// The canonical text of a duration ("1h2m3s4ms", "-5s", "0s"), without a prefix; parsing
// it back gives the same value.
std::string format_duration(int64_t ns);

}  // namespace plcfi::common
