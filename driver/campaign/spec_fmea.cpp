// The FMEA table of a campaign (CSV as spreadsheets export it: ',' or ';', RFC 4180
// quoting): one row per failure mode with S/O/D ratings, RPN, fault class and alarm, and
// optionally its failure rate, safety function and whether it is dangerous.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "campaign/spec_internal.hpp"

namespace plcfi::campaign {

namespace detail {

namespace {

// RFC 4180 fields of one record; `line` advances over quoted line breaks. cols[i] is the
// 1-based column where field i starts.
bool read_record(std::istream& in, char sep, std::vector<std::string>* fields, std::vector<uint32_t>* cols, uint32_t* line,
                 std::string* err, const std::string& path) {
  fields->clear();
  cols->clear();
  std::string text;
  if (!std::getline(in, text)) return false;
  if (!text.empty() && text.back() == '\r') text.pop_back();
  std::string cur;
  bool quoted = false, was_quoted = false;
  uint32_t col = 1, start_col = 1;
  size_t i = 0;
  uint32_t start_line = *line;
  while (true) {
    if (i >= text.size()) {
      if (quoted) {
        std::string more;
        if (!std::getline(in, more)) {
          *err = fmt::format("{}:{}:{}: unterminated quoted field", path, start_line, start_col);
          return false;
        }
        if (!more.empty() && more.back() == '\r') more.pop_back();
        ++*line;
        cur += '\n';
        text = more;
        i = 0;
        col = 1;
        continue;
      }
      break;
    }
    char c = text[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          cur += '"';
          i += 2;
          col += 2;
          continue;
        }
        quoted = false;
      } else {
        cur += c;
      }
    } else if (c == '"' && cur.empty() && !was_quoted) {
      quoted = was_quoted = true;
    } else if (c == sep) {
      fields->push_back(cur);
      cols->push_back(start_col);
      cur.clear();
      was_quoted = false;
      start_col = col + 1;
    } else {
      cur += c;
    }
    ++i;
    ++col;
  }
  fields->push_back(cur);
  cols->push_back(start_col);
  return true;
}

std::string trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The safety columns of one row. A row without a safety function stands outside the
// evidence and must leave the rate and `dangerous` empty; a row with one needs its rate.
void read_safety_columns(FmeaRow& r, const std::string& rate, const Loc& rate_at, const std::string& function,
                         const Loc& function_at, const std::string& dangerous, const Loc& dangerous_at, char sep) {
  r.safety_function = function;
  r.rate_loc = rate_at;
  if (function.empty()) {
    if (!rate.empty())
      throw common::InputError(function_at.str() + ": safety_function: row " + r.id + " has a failure rate but no safety function");
    if (!dangerous.empty())
      throw common::InputError(function_at.str() + ": safety_function: row " + r.id + " says dangerous '" + dangerous +
                               "' but names no safety function");
    return;
  }
  if (!valid_name(function))
    throw common::InputError(function_at.str() + ": safety_function: '" + function + "' is not an identifier");
  if (rate.empty())
    throw common::InputError(rate_at.str() + ": failure_rate: row " + r.id + " belongs to safety function " + function +
                             " but has no failure rate (FIT)");
  // A spreadsheet that separates with ';' writes a decimal comma.
  std::string text = rate;
  if (sep == ';') std::replace(text.begin(), text.end(), ',', '.');
  double v = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  bool digits_only = text.find_first_not_of("0123456789.eE+-") == std::string::npos;
  if (ec != std::errc() || end != text.data() + text.size() || !digits_only || !std::isfinite(v))
    throw common::InputError(rate_at.str() + ": failure_rate: expected a number of FIT (failures per 10^9 h), got '" + rate + "'");
  if (v < 0) throw common::InputError(rate_at.str() + ": failure_rate: " + rate + " is negative");
  r.failure_rate = v;
  std::string d = lower(dangerous);
  if (d.empty() || d == "yes") r.dangerous = true;
  else if (d == "no") r.dangerous = false;
  else throw common::InputError(dangerous_at.str() + ": dangerous: expected yes or no, got '" + dangerous + "'");
}

}  // namespace

void parse_fmea(const std::string& path, Fmea* out) {
  std::string text, read_err;
  if (!common::read_file(path, common::kMaxSpecBytes, &text, &read_err)) throw common::InputError(read_err);
  out->path = path;
  std::istringstream in(text);
  const std::string first = text.substr(0, text.find('\n'));
  // Spreadsheets in locales with a decimal comma export with ';'.
  char sep = first.find(';') != std::string::npos && first.find(',') == std::string::npos ? ';' : ',';
  std::vector<std::string> header, fields;
  std::vector<uint32_t> cols;
  uint32_t line = 1;
  std::string err;
  if (!read_record(in, sep, &header, &cols, &line, &err, path)) throw common::InputError(err.empty() ? path + ":1:1: empty file" : err);
  // Column names as a spreadsheet may spell them.
  struct Column {
    const char* key;
    std::vector<std::string> names;
    bool required;
  };
  const std::vector<Column> columns = {
      {"id", {"id", "no", "nr"}, false},
      {"transition", {"tsd_transition", "transition", "information from tsd", "tsd"}, true},
      {"failure_mode", {"failure_mode", "failure mode"}, false},
      {"s", {"s", "severity"}, true},
      {"effect", {"effect"}, false},
      {"cause", {"cause"}, false},
      {"o", {"o", "occurrence"}, true},
      {"detection", {"detection"}, false},
      {"d", {"d", "detectability"}, true},
      {"rpn", {"rpn"}, true},
      {"fault_class", {"fault_class", "fault class", "class"}, true},
      {"alarm", {"alarm", "alarm message", "message", "msg"}, true},
      {"fault_model", {"fault_model", "fault model", "fault"}, false},
      {"failure_rate", {"failure_rate", "failure rate", "fit", "lambda"}, false},
      {"safety_function", {"safety_function", "safety function", "sf"}, false},
      {"dangerous", {"dangerous"}, false},
  };
  enum : size_t { kRate = 13, kFunction = 14, kDangerous = 15 };
  std::vector<int> index(columns.size(), -1);
  for (size_t h = 0; h < header.size(); ++h) {
    std::string name = lower(trim(header[h]));
    if (name.empty()) continue;
    bool known = false;
    for (size_t c = 0; c < columns.size(); ++c)
      for (const auto& n : columns[c].names)
        if (n == name) {
          if (index[c] >= 0)
            throw common::InputError(fmt::format("{}:1:{}: column '{}' appears twice", path, cols[h], header[h]));
          index[c] = static_cast<int>(h);
          known = true;
        }
    if (!known)
      throw common::InputError(fmt::format("{}:1:{}: unknown column '{}' (expected id, tsd_transition, failure_mode, S, effect, cause, O, "
                                  "detection, D, RPN, fault_class, alarm, fault_model, failure_rate, safety_function, dangerous)",
                                  path, cols[h], header[h]));
  }
  for (size_t c = 0; c < columns.size(); ++c)
    if (columns[c].required && index[c] < 0)
      throw common::InputError(fmt::format("{}:1:1: the header lacks the column '{}'", path, columns[c].names.front()));
  // The safety columns go together: a rate means nothing without the function it threatens.
  for (size_t c : {kFunction, kDangerous})
    if (index[c] >= 0 && index[kRate] < 0)
      throw common::InputError(fmt::format("{}:1:{}: the column '{}' needs a 'failure_rate' column (FIT) beside it", path,
                                           cols[static_cast<size_t>(index[c])], header[static_cast<size_t>(index[c])]));
  if (index[kRate] >= 0 && index[kFunction] < 0)
    throw common::InputError(fmt::format("{}:1:{}: the column '{}' needs a 'safety_function' column beside it", path,
                                         cols[static_cast<size_t>(index[kRate])], header[static_cast<size_t>(index[kRate])]));
  out->has_rates = index[kRate] >= 0;
  std::set<std::string> ids;
  while (true) {
    ++line;
    uint32_t row_line = line;
    if (!read_record(in, sep, &fields, &cols, &line, &err, path)) {
      if (!err.empty()) throw common::InputError(err);
      break;
    }
    if (fields.size() == 1 && trim(fields[0]).empty()) continue;  // blank line
    if (fields.size() != header.size())
      throw common::InputError(fmt::format("{}:{}:1: {} fields, the header has {}", path, row_line, fields.size(), header.size()));
    auto get = [&](size_t c) { return index[c] < 0 ? std::string() : trim(fields[static_cast<size_t>(index[c])]); };
    auto at = [&](size_t c) { return Loc{path, row_line, index[c] < 0 ? 1 : cols[static_cast<size_t>(index[c])]}; };
    auto rating = [&](size_t c, const char* what, int lo, int hi) {
      std::string v = get(c);
      int n = 0;
      size_t used = 0;
      try {
        n = std::stoi(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (v.empty() || used != v.size()) throw common::InputError(at(c).str() + ": " + what + ": expected a whole number, got '" + v + "'");
      if (n < lo || n > hi) throw common::InputError(fmt::format("{}: {}: {} is outside {}..{}", at(c).str(), what, n, lo, hi));
      return n;
    };
    FmeaRow r;
    r.line = row_line;
    r.id = get(0).empty() ? fmt::format("row{}", row_line) : get(0);
    if (!ids.insert(r.id).second) throw common::InputError(at(0).str() + ": FMEA id '" + r.id + "' appears twice");
    r.transition = get(1);
    r.transition_loc = at(1);
    r.failure_mode = get(2);
    r.s = rating(3, "S", 1, 10);
    r.effect = get(4);
    r.cause = get(5);
    r.o = rating(6, "O", 1, 10);
    r.detection = get(7);
    r.d = rating(8, "D", 1, 10);
    r.rpn = rating(9, "RPN", 1, 1000);
    if (r.rpn != r.s * r.o * r.d)
      throw common::InputError(fmt::format("{}: RPN {} is not S x O x D = {} x {} x {} = {}", at(9).str(), r.rpn, r.s, r.o, r.d,
                                  r.s * r.o * r.d));
    r.fault_class = get(10);
    r.class_loc = at(10);
    if (r.fault_class.empty()) throw common::InputError(at(10).str() + ": the fault class is empty");
    r.alarm = get(11);
    r.alarm_loc = at(11);
    if (r.alarm.empty()) throw common::InputError(at(11).str() + ": the alarm variable is empty");
    r.fault_model = get(12);
    r.fault_loc = at(12);
    if (out->has_rates) read_safety_columns(r, get(kRate), at(kRate), get(kFunction), at(kFunction), get(kDangerous),
                                            at(kDangerous), sep);
    out->rows.push_back(r);
  }
  if (out->rows.empty()) throw common::InputError(path + ":2:1: the FMEA has no rows");
}

}  // namespace detail

bool load_fmea(const std::string& path, Fmea* out, std::string* err) {
  return common::catch_input_error(err, [&] { detail::parse_fmea(path, out); });
}

}  // namespace plcfi::campaign
