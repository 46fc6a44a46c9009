// Duration parsing in integer arithmetic: each part is whole units plus a decimal fraction
// scaled by 128-bit products, so no value goes through floating point.
#include "common/duration.hpp"

#include <cctype>
#include <limits>

namespace plcfi::common {

namespace {

// 128-bit intermediates hold count * unit (at most 10^19 * 8.64e13) without overflow;
// __extension__ keeps -Wpedantic quiet about the GCC/Clang type.
__extension__ typedef unsigned __int128 U128;

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_alpha(char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; }
char lower(char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); }

constexpr const char* kUnits = "(use d, h, m, s, ms, us or ns)";

// Nanoseconds per unit; 0 for an unknown unit.
int64_t unit_ns(std::string_view unit) {
  std::string u;
  for (char c : unit) u += lower(c);
  if (u == "d") return kNsPerDay;
  if (u == "h") return kNsPerHour;
  if (u == "m") return kNsPerMin;
  if (u == "s") return kNsPerS;
  if (u == "ms") return kNsPerMs;
  if (u == "us") return kNsPerUs;
  if (u == "ns") return 1;
  return 0;
}

DurationParse failure(size_t at, std::string message) {
  DurationParse r;
  r.error = std::move(message);
  r.error_at = at;
  return r;
}

// Reads digits with '_' between them from text[*i]; appends the digits to *digits.
void read_digits(std::string_view text, size_t* i, std::string* digits) {
  while (*i < text.size()) {
    const char c = text[*i];
    if (is_digit(c)) {
      *digits += c;
      ++*i;
    } else if (c == '_' && !digits->empty() && *i + 1 < text.size() && is_digit(text[*i + 1])) {
      ++*i;
    } else {
      break;
    }
  }
}

}  // namespace

namespace {
DurationParse parse_body(std::string_view text, bool unsigned64) {
  const char* kRange = unsigned64 ? "out of range (at most 213503d23h34m33s709ms551us615ns, 2^64 - 1 ns)"
                                  : "out of range (at most 106751d23h47m16s854ms775us807ns, about 292 years)";
  size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) {
    negative = text[i] == '-';
    ++i;
  }
  if (i >= text.size()) return failure(i, "expected a duration such as 1h2m3s4ms");
  // The sum is kept as a non-negative magnitude up to 2^63, so INT64_MIN itself is reachable.
  U128 total = 0;
  const U128 limit = negative ? (U128{1} << 63) : unsigned64 ? (U128{1} << 64) - 1 : (U128{1} << 63) - 1;
  bool first = true;
  while (i < text.size()) {
    if (!first && text[i] == '_' && i + 1 < text.size() && is_digit(text[i + 1])) ++i;  // 1s_500ms
    const size_t num_at = i;
    if (!is_digit(text[i])) {
      if (is_alpha(text[i])) {
        size_t k = i;
        while (k < text.size() && is_alpha(text[k])) ++k;
        return failure(i, "expected a number before '" + std::string(text.substr(i, k - i)) + "'");
      }
      return failure(i, std::string("unexpected '") + text[i] + "'" + (first ? " (expected a number)" : ""));
    }
    std::string whole, frac;
    read_digits(text, &i, &whole);
    if (i < text.size() && text[i] == '.') {
      ++i;
      if (i >= text.size() || !is_digit(text[i]))
        return failure(i, "expected digits after the decimal point in '" + std::string(text.substr(num_at, i - num_at)) + "'");
      read_digits(text, &i, &frac);
      if (i < text.size() && text[i] == '.')
        return failure(i, "unexpected '.' after '" + std::string(text.substr(num_at, i - num_at)) + "'");
    }
    const size_t unit_at = i;
    while (i < text.size() && is_alpha(text[i])) ++i;
    const std::string_view unit = text.substr(unit_at, i - unit_at);
    if (unit.empty()) {
      if (i < text.size() && !is_digit(text[i]))
        return failure(i, std::string("unexpected '") + text[i] + "' after '" + std::string(text.substr(num_at, i - num_at)) + "'");
      return failure(unit_at, "missing duration unit after '" + std::string(text.substr(num_at, unit_at - num_at)) + "' " + kUnits);
    }
    const int64_t per = unit_ns(unit);
    if (per == 0) return failure(unit_at, "unknown duration unit '" + std::string(unit) + "' " + kUnits);
    // Whole units: 21 digits already exceed 2^64 ns for every unit (and fit in 128 bits).
    size_t lead = 0;
    while (lead + 1 < whole.size() && whole[lead] == '0') ++lead;
    if (whole.size() - lead > 20) return failure(num_at, kRange);
    U128 count = 0;
    for (size_t k = lead; k < whole.size(); ++k) count = count * 10 + static_cast<unsigned>(whole[k] - '0');
    U128 part = count * static_cast<U128>(per);
    // The fraction: trailing zeros carry nothing; what remains must come out in whole ns.
    while (!frac.empty() && frac.back() == '0') frac.pop_back();
    if (!frac.empty()) {
      // per <= 8.64e13 < 10^14: a fraction of more than 14 significant places is always finer than 1 ns.
      bool exact = frac.size() <= 19;
      U128 num = 0, den = 1;
      if (exact) {
        for (char c : frac) {
          num = num * 10 + static_cast<unsigned>(c - '0');
          den *= 10;
        }
        num *= static_cast<U128>(per);
        exact = num % den == 0;
      }
      if (!exact)
        return failure(num_at, "'" + std::string(text.substr(num_at, i - num_at)) + "' is not a whole number of nanoseconds");
      part += num / den;
    }
    total += part;
    if (part > limit || total > limit) return failure(num_at, kRange);
    first = false;
  }
  DurationParse r;
  // total <= 2^63 when negative: the two's complement of its low 64 bits is the value.
  const uint64_t magnitude = static_cast<uint64_t>(total);
  r.ns = negative ? static_cast<int64_t>(uint64_t{0} - magnitude) : static_cast<int64_t>(magnitude);
  r.beyond_signed = !negative && magnitude > static_cast<uint64_t>(INT64_MAX);
  return r;
}
}  // namespace

DurationParse parse_duration_body(std::string_view text) { return parse_body(text, false); }
DurationParse parse_unsigned_duration_body(std::string_view text) { return parse_body(text, true); }

DurationParse parse_duration(std::string_view text) {
  size_t hash = text.find('#');
  size_t skip = 0;
  if (hash != std::string_view::npos) {
    std::string prefix;
    for (char c : text.substr(0, hash)) prefix += lower(c);
    if (prefix == "t" || prefix == "time" || prefix == "lt" || prefix == "ltime") skip = hash + 1;
    else return failure(0, "unknown prefix '" + std::string(text.substr(0, hash + 1)) + "' (use T#, TIME#, LT# or LTIME#)");
  }
  DurationParse r = parse_duration_body(text.substr(skip));
  r.error_at += skip;
  return r;
}

bool parse_duration(std::string_view text, int64_t* ns, std::string* err) {
  DurationParse r = parse_duration(text);
  if (!r.ok()) {
    *err = "'" + std::string(text) + "' is not a duration: " + r.error;
    return false;
  }
  *ns = r.ns;
  return true;
}

std::string format_duration(int64_t ns) {
  if (ns == 0) return "0s";
  std::string out;
  // The magnitude in unsigned arithmetic: -INT64_MIN does not fit int64.
  uint64_t rest = ns < 0 ? uint64_t{0} - static_cast<uint64_t>(ns) : static_cast<uint64_t>(ns);
  if (ns < 0) out += '-';
  const std::pair<const char*, uint64_t> units[] = {{"d", kNsPerDay}, {"h", kNsPerHour}, {"m", kNsPerMin}, {"s", kNsPerS},
                                                    {"ms", kNsPerMs}, {"us", kNsPerUs},  {"ns", 1}};
  for (const auto& [name, per] : units) {
    if (rest >= per) {
      out += std::to_string(rest / per) + name;
      rest %= per;
    }
  }
  return out;
}

}  // namespace plcfi::common
