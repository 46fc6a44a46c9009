// Strict YAML reading: parsing with located syntax errors, the duplicate-key walk that
// yaml-cpp does not do, and the typed getters with the project's one error wording.
#include "common/yaml.hpp"

#include <charconv>
#include <cmath>
#include <map>

#include "common/duration.hpp"

namespace plcfi::common {

namespace {

// Marks are 0-based; a node made up by yaml-cpp (an empty document) has none: 1:1 then.
uint32_t one_based(int v) { return v < 0 ? 1u : static_cast<uint32_t>(v) + 1u; }

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

std::string choice_list(std::initializer_list<std::string_view> items, std::string_view last_sep) {
  std::string out;
  size_t i = 0;
  for (auto item : items) {
    if (i > 0) out += i + 1 == items.size() ? std::string(last_sep) : std::string(", ");
    out += item;
    ++i;
  }
  return out;
}

YamlDoc YamlDoc::open(const std::string& path, size_t max_bytes) {
  std::string text, err;
  if (!read_file(path, max_bytes, &text, &err)) throw InputError(err);
  return parse(path, text);
}

YamlDoc YamlDoc::parse(const std::string& path, const std::string& text) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path + ":" + std::to_string(one_based(e.mark.line)) + ":" + std::to_string(one_based(e.mark.column)) +
                     ": " + e.msg);
  }
  YamlDoc doc(path, root);
  // Aliases share nodes, so a small file can expand to a huge tree: the walk has a budget.
  size_t budget = 4 * text.size() + 4096;
  doc.check_duplicates(doc.root_, &budget);
  return doc;
}

void YamlDoc::check_duplicates(const YAML::Node& n, size_t* budget) const {
  if (*budget == 0) fail(root_, "the document expands to too many nodes (aliases of aliases?)");
  --*budget;
  if (n.IsSequence()) {
    for (const auto& item : n) check_duplicates(item, budget);
  } else if (n.IsMap()) {
    // yaml-cpp keeps every entry of a map but operator[] finds only the first: a second
    // value of the same key would be ignored without this check.
    std::map<std::string, YAML::Mark> seen;
    for (const auto& kv : n) {
      if (kv.first.IsScalar()) {
        auto [it, fresh] = seen.emplace(kv.first.Scalar(), kv.first.Mark());
        if (!fresh)
          fail(kv.first, "duplicate key '" + kv.first.Scalar() + "' (first at " + std::to_string(one_based(it->second.line)) +
                             ":" + std::to_string(one_based(it->second.column)) + ")");
      }
      check_duplicates(kv.first, budget);
      check_duplicates(kv.second, budget);
    }
  }
}

uint32_t YamlDoc::line(const YAML::Node& n) const { return one_based(n.Mark().line); }
uint32_t YamlDoc::col(const YAML::Node& n) const { return one_based(n.Mark().column); }

uint32_t YamlDoc::text_col(const YAML::Node& n) const {
  // A quoted scalar carries the non-specific tag "!"; its text starts after the quote.
  return col(n) + (n.IsScalar() && n.Tag() == "!" ? 1u : 0u);
}

std::string YamlDoc::where(const YAML::Node& n) const {
  return path_ + ":" + std::to_string(line(n)) + ":" + std::to_string(col(n));
}

void YamlDoc::fail(const YAML::Node& n, const std::string& message) const { throw InputError(where(n) + ": " + message); }

void YamlDoc::fail_in(const YAML::Node& n, size_t offset, const std::string& message) const {
  uint32_t c = col(n);
  if (n.IsScalar() && n.Scalar().find('\n') == std::string::npos) c = text_col(n) + static_cast<uint32_t>(offset);
  throw InputError(path_ + ":" + std::to_string(line(n)) + ":" + std::to_string(c) + ": " + message);
}

std::string YamlDoc::describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "'" + n.Scalar() + "'";
}

void YamlDoc::check_keys(const YAML::Node& map, std::initializer_list<std::string_view> known, std::string_view what,
                         bool allow_null) const {
  if (allow_null && map.IsNull()) return;
  if (!map.IsMap()) fail(map, std::string(what) + ": expected a map, got " + describe(map));
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) fail(kv.first, std::string(what) + ": expected a key name, got " + describe(kv.first));
    const std::string& k = kv.first.Scalar();
    bool ok = false;
    for (auto a : known) ok = ok || a == k;
    if (!ok) fail(kv.first, "unknown key '" + k + "' in " + std::string(what) + " (expected one of: " + choice_list(known, ", ") + ")");
  }
}

YAML::Node YamlDoc::required(const YAML::Node& map, const char* key, std::string_view what) const {
  if (!map.IsMap()) fail(map, std::string(what) + ": expected a map, got " + describe(map));
  YAML::Node n = map[key];
  if (!n) fail(map, "missing key '" + std::string(key) + "' in " + std::string(what));
  return n;
}

YAML::Node YamlDoc::list(const YAML::Node& n, std::string_view what, bool allow_empty) const {
  if (!n.IsSequence()) fail(n, std::string(what) + ": expected a list, got " + describe(n));
  if (!allow_empty && n.size() == 0) fail(n, std::string(what) + ": expected a non-empty list, got an empty one");
  return n;
}

std::string YamlDoc::scalar(const YAML::Node& n, std::string_view what) const {
  if (!n.IsScalar()) fail(n, std::string(what) + ": expected a single value, got " + describe(n));
  return n.Scalar();
}

int64_t YamlDoc::integer(const YAML::Node& n, std::string_view what, int64_t lo, int64_t hi) const {
  if (!n.IsScalar()) fail(n, std::string(what) + ": expected an integer, got " + describe(n));
  const std::string s = n.Scalar();
  std::string_view digits = s;
  bool negative = false;
  if (!digits.empty() && (digits[0] == '-' || digits[0] == '+')) {
    negative = digits[0] == '-';
    digits.remove_prefix(1);
  }
  int base = 10;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    base = 16;
    digits.remove_prefix(2);
  }
  uint64_t magnitude = 0;
  auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), magnitude, base);
  if (digits.empty() || end != digits.data() + digits.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
    fail(n, std::string(what) + ": expected an integer, got " + describe(n));
  const uint64_t max_magnitude = negative ? uint64_t{1} << 63 : static_cast<uint64_t>(INT64_MAX);
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  if (ec == std::errc::result_out_of_range || magnitude > max_magnitude)
    fail(n, std::string(what) + ": " + s + " is outside " + range);
  const int64_t v = negative ? static_cast<int64_t>(uint64_t{0} - magnitude) : static_cast<int64_t>(magnitude);
  if (v < lo || v > hi) fail(n, std::string(what) + ": " + s + " is outside " + range);
  return v;
}

double YamlDoc::number(const YAML::Node& n, std::string_view what) const {
  if (!n.IsScalar()) fail(n, std::string(what) + ": expected a number, got " + describe(n));
  const std::string s = n.Scalar();
  std::string_view text = s;
  if (!text.empty() && text[0] == '+') text.remove_prefix(1);
  double v = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    fail(n, std::string(what) + ": expected a number, got " + describe(n));
  return v;
}

bool YamlDoc::boolean(const YAML::Node& n, std::string_view what) const {
  if (n.IsScalar()) {
    const std::string v = lower(n.Scalar());
    if (v == "true" || v == "yes" || v == "on") return true;
    if (v == "false" || v == "no" || v == "off") return false;
  }
  fail(n, std::string(what) + ": expected true or false, got " + describe(n));
}

int64_t YamlDoc::duration(const YAML::Node& n, std::string_view what, int64_t min_ns) const {
  if (!n.IsScalar()) fail(n, std::string(what) + ": expected a duration, got " + describe(n));
  const std::string s = n.Scalar();
  const DurationParse r = parse_duration(s);
  if (!r.ok()) fail_in(n, r.error_at, std::string(what) + ": expected a duration, got '" + s + "': " + r.error);
  if (r.ns < min_ns) {
    if (min_ns == 0) fail(n, std::string(what) + ": must not be negative, got '" + s + "'");
    if (min_ns == 1) fail(n, std::string(what) + ": must be positive, got '" + s + "'");
    fail(n, std::string(what) + ": must be at least " + format_duration(min_ns) + ", got '" + s + "'");
  }
  return r.ns;
}

std::string YamlDoc::word(const YAML::Node& n, std::string_view what, std::initializer_list<std::string_view> allowed) const {
  if (n.IsScalar())
    for (auto a : allowed)
      if (n.Scalar() == a) return n.Scalar();
  fail(n, std::string(what) + ": expected " + choice_list(allowed) + ", got " + describe(n));
}

}  // namespace plcfi::common
