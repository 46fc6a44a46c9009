// The FMEA table of a campaign (CSV as spreadsheets export it: ',' or ';', RFC 4180
// quoting): one row per failure mode with S/O/D ratings, RPN, fault class and alarm.
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
  };
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
                                  "detection, D, RPN, fault_class, alarm, fault_model)",
                                  path, cols[h], header[h]));
  }
  for (size_t c = 0; c < columns.size(); ++c)
    if (columns[c].required && index[c] < 0)
      throw common::InputError(fmt::format("{}:1:1: the header lacks the column '{}'", path, columns[c].names.front()));
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
    out->rows.push_back(r);
  }
  if (out->rows.empty()) throw common::InputError(path + ":2:1: the FMEA has no rows");
}

}  // namespace detail

bool load_fmea(const std::string& path, Fmea* out, std::string* err) {
  return common::catch_input_error(err, [&] { detail::parse_fmea(path, out); });
}

}  // namespace plcfi::campaign
