// CSV and VCD trace readers and the trace program generator.
#include "trace_reader.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <istream>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "syntax/lexer.hpp"

namespace plcfi::monitor {

namespace {

constexpr size_t kBlockBytes = 64 * 1024;

std::string where(const std::string& name, size_t line, size_t col) {
  return name + ":" + std::to_string(line) + ":" + std::to_string(col) + ": ";
}

// A byte no text trace holds: NUL (a binary file, /dev/zero) or another control
// character (tab, CR and LF are fine; the VCD also allows vertical tab and form feed).
std::string bad_byte(unsigned char c) {
  if (c == 0) return "NUL byte (not a text trace)";
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", c);
  return std::string("control character ") + hex + " (not a text trace)";
}

// `name` as a path of at most kMaxNameDepth parts: deeper names would nest that many
// STRUCTs in the trace program.
bool name_too_deep(std::string_view name) {
  size_t parts = 1;
  for (char c : name)
    if (c == '.' && ++parts > TraceLimits::kMaxNameDepth) return true;
  return false;
}

// Seconds (CSV time column) to nanoseconds; false when outside what int64 ns can hold.
bool seconds_to_ns(double sec, int64_t* ns) {
  double v = std::nearbyint(sec * 1e9);
  if (!(v > -9.2e18 && v < 9.2e18)) return false;
  *ns = static_cast<int64_t>(v);
  return true;
}

// ---------------------------------------------------------------------------------------
// CSV

// The lines of a stream read in blocks (the cost is linear in the bytes, whatever the
// line length). A line longer than kMaxLineBytes and a NUL or control byte are errors at
// their line and column.
class LineSource {
 public:
  LineSource(std::istream* in, const std::string* name) : in_(in), name_(name) {}

  // The next line without "\n" or "\r\n"; false at the end (err empty) or on an error.
  bool next(std::string_view* line, std::string* err) {
    size_t scan = pos_;
    size_t nl;
    for (;;) {
      nl = buf_.find('\n', scan);
      if (nl != std::string::npos || eof_) break;
      if (buf_.size() - pos_ > TraceLimits::kMaxLineBytes) {
        *err = where(*name_, line_ + 1, TraceLimits::kMaxLineBytes + 1) + "line longer than " +
               std::to_string(TraceLimits::kMaxLineBytes >> 20) + " MiB (not a text trace?)";
        return false;
      }
      buf_.erase(0, pos_);
      pos_ = 0;
      scan = buf_.size();
      size_t old = buf_.size();
      buf_.resize(old + kBlockBytes);
      in_->read(buf_.data() + old, static_cast<std::streamsize>(kBlockBytes));
      auto got = static_cast<size_t>(in_->gcount());
      buf_.resize(old + got);
      if (in_->bad()) {
        *err = *name_ + ": read error: " + std::strerror(errno);
        return false;
      }
      if (got == 0 || in_->eof()) eof_ = true;
    }
    size_t end = nl == std::string::npos ? buf_.size() : nl;
    if (nl == std::string::npos && pos_ == buf_.size()) return false;
    if (end - pos_ > TraceLimits::kMaxLineBytes) {
      *err = where(*name_, line_ + 1, TraceLimits::kMaxLineBytes + 1) + "line longer than " +
             std::to_string(TraceLimits::kMaxLineBytes >> 20) + " MiB (not a text trace?)";
      return false;
    }
    std::string_view l(buf_.data() + pos_, end - pos_);
    pos_ = nl == std::string::npos ? buf_.size() : nl + 1;
    ++line_;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    for (size_t i = 0; i < l.size(); ++i) {
      auto c = static_cast<unsigned char>(l[i]);
      if (c < 0x20 && c != '\t') {
        *err = where(*name_, line_, i + 1) + bad_byte(c);
        return false;
      }
    }
    *line = l;
    return true;
  }

  size_t line() const { return line_; }

  // Back to the first line (the second pass of the CSV reader).
  bool rewind() {
    in_->clear();
    in_->seekg(0);
    buf_.clear();
    pos_ = 0;
    eof_ = false;
    line_ = 0;
    return static_cast<bool>(*in_);
  }

 private:
  std::istream* in_;
  const std::string* name_;
  std::string buf_;
  size_t pos_ = 0;  // start of the unread part of buf_
  bool eof_ = false;
  size_t line_ = 0;  // the line last returned, 1-based
};

struct Cell {
  std::string_view text;
  size_t col;  // 1-based column of its first character
};

// Splits on commas and trims blanks; appends to *cells (cleared first).
void split_csv(std::string_view line, std::vector<Cell>* cells) {
  cells->clear();
  size_t start = 0;
  for (;;) {
    size_t comma = line.find(',', start);
    size_t stop = comma == std::string_view::npos ? line.size() : comma;
    size_t b = start, e = stop;
    while (b < e && (line[b] == ' ' || line[b] == '\t')) ++b;
    while (e > b && (line[e - 1] == ' ' || line[e - 1] == '\t')) --e;
    cells->push_back(Cell{line.substr(b, e - b), b + 1});
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

// A finite number, TRUE or FALSE. `scratch` keeps strtod's NUL-terminated copy.
bool parse_number(std::string_view s, double* v, std::string* scratch) {
  if (s == "TRUE" || s == "true") {
    *v = 1;
    return true;
  }
  if (s == "FALSE" || s == "false") {
    *v = 0;
    return true;
  }
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return false;
  scratch->assign(s);
  char* end = nullptr;
  *v = std::strtod(scratch->c_str(), &end);
  return end == scratch->c_str() + scratch->size() && std::isfinite(*v);
}

// Whether a cell is written as a typed literal (a prefix, then '#'): T#1s, DT#..., ...
bool looks_like_literal(std::string_view s) {
  size_t hash = s.find('#');
  return hash != std::string_view::npos && hash > 0 && std::isalpha(static_cast<unsigned char>(s[0]));
}

// A TIME, LTIME, DATE, TOD or DT literal (any spelling of the prefix ST takes) read by
// the ST lexer itself, so that a trace takes exactly what a program takes: its value in
// nanoseconds and its column kind. False with *why (empty for a literal of another
// type) and the 0-based offset of the trouble in *at otherwise.
bool parse_time_literal(std::string_view s, int64_t* ns, TraceColumn::Kind* kind, std::string* why, size_t* at) {
  st::SourceManager sm;
  const uint32_t f = sm.add("<cell>", std::string(s));
  st::DiagEngine diags(sm);
  std::vector<st::Token> toks = st::lex_file(sm, f, diags);
  for (const auto& d : diags.all())
    if (d.severity == st::Severity::Error) {
      // The lexer names the literal first ("T#1s5: missing ..."); the message names it already.
      *why = d.message.rfind(std::string(s) + ": ", 0) == 0 ? d.message.substr(s.size() + 2) : d.message;
      *at = d.loc.col > 0 ? d.loc.col - 1 : 0;
      return false;
    }
  *at = 0;
  if (toks.empty() || toks[0].kind != st::Tok::TimeLit) {
    why->clear();  // a literal of another type (INT#5): the message says enough
    return false;
  }
  if (toks.size() > 1 && toks[1].kind != st::Tok::Eof) {
    *why = "unexpected text after the literal";
    *at = toks[1].offset;
    return false;
  }
  switch (toks[0].lit) {
    case st::LiteralKind::Date: *kind = TraceColumn::Kind::Date; break;
    case st::LiteralKind::TimeOfDay: *kind = TraceColumn::Kind::Tod; break;
    case st::LiteralKind::DateTime: *kind = TraceColumn::Kind::Dt; break;
    default: *kind = TraceColumn::Kind::Time; break;
  }
  *ns = toks[0].time_ns;
  return true;
}

const char* time_kind_name(TraceColumn::Kind k) {
  switch (k) {
    case TraceColumn::Kind::Date: return "DATE";
    case TraceColumn::Kind::Tod: return "TOD";
    case TraceColumn::Kind::Dt: return "DT";
    default: return "TIME";
  }
}

class CsvReader final : public TraceReader {
 public:
  bool init(std::string name, std::unique_ptr<std::istream> in, int64_t cycle_ns, std::string* err) {
    name_ = std::move(name);
    in_ = std::move(in);
    cycle_ns_ = cycle_ns;
    lines_ = std::make_unique<LineSource>(in_.get(), &name_);
    std::string_view header;
    if (!lines_->next(&header, err)) {
      if (err->empty()) *err = where(name_, 1, 1) + "empty trace (a header line 'time,var,...' is expected)";
      return false;
    }
    split_csv(header, &cells_);
    has_time_ = cells_[0].text == "time" || cells_[0].text == "t";
    size_t first = has_time_ ? 1 : 0;
    if (cells_.size() - first > TraceLimits::kMaxColumns) {
      *err = where(name_, 1, cells_[first + TraceLimits::kMaxColumns].col) + "more than " +
             std::to_string(TraceLimits::kMaxColumns) + " columns";
      return false;
    }
    columns_.reserve(cells_.size() - first);
    for (size_t i = first; i < cells_.size(); ++i) {
      const Cell& c = cells_[i];
      if (c.text.empty()) {
        *err = where(name_, 1, c.col) + "column " + std::to_string(i + 1) + " has no name";
        return false;
      }
      if (name_too_deep(c.text)) {
        *err = where(name_, 1, c.col) + "column name with more than " + std::to_string(TraceLimits::kMaxNameDepth) +
               " dotted parts";
        return false;
      }
      columns_.push_back(TraceColumn{std::string(c.text), TraceColumn::Kind::Bool});
    }
    if (columns_.empty()) {
      *err = where(name_, 1, 1) + "no variable columns";
      return false;
    }
    // First pass: every row is checked, and each column gets its kind (BOOL when only
    // 0/1, integer, else real; the literals' type when it holds TIME, DATE, TOD or DT
    // literals) before the monitors are compiled against the columns.
    std::string_view line;
    int64_t t;
    first_pass_ = true;
    while (lines_->next(&line, err)) {
      if (line.empty()) continue;
      if (!parse_row(line, &t, &values_, err)) return false;
      for (size_t c = 0; c < columns_.size(); ++c) {
        double v = values_[c];
        auto& k = columns_[c].kind;
        if (k >= TraceColumn::Kind::Time) continue;
        if (v != std::floor(v)) k = TraceColumn::Kind::Real;
        else if (k == TraceColumn::Kind::Bool && v != 0 && v != 1) k = TraceColumn::Kind::Int;
      }
    }
    if (!err->empty()) return false;
    first_pass_ = false;
    for (const auto& c : columns_)
      if (c.is_time()) time_values_.assign(columns_.size(), 0);
    if (!lines_->rewind() || !lines_->next(&line, err)) {
      if (err->empty()) *err = name_ + ": cannot read the trace a second time";
      return false;
    }
    have_prev_ = false;
    state_ = 0;
    return true;
  }

  bool next(int64_t* t, std::vector<double>* values, std::string* err) override {
    std::string_view line;
    while (lines_->next(&line, err)) {
      if (line.empty()) continue;
      return parse_row(line, t, values, err);
    }
    return false;
  }

 private:
  // One data row: its values and its time; checks the field count, the numbers and that
  // time does not go back.
  bool parse_row(std::string_view line, int64_t* t, std::vector<double>* values, std::string* err) {
    size_t line_no = lines_->line();
    split_csv(line, &cells_);
    size_t off = has_time_ ? 1 : 0;
    size_t expected = columns_.size() + off;
    if (cells_.size() != expected) {
      size_t col = cells_.size() > expected ? cells_[expected].col : line.size() + 1;
      *err = where(name_, line_no, col) + std::to_string(cells_.size()) + " fields, the header has " + std::to_string(expected);
      return false;
    }
    if (has_time_) {
      double sec;
      if (!parse_number(cells_[0].text, &sec, &scratch_) || !seconds_to_ns(sec, t)) {
        *err = where(name_, line_no, cells_[0].col) + "time '" + std::string(cells_[0].text) +
               "' is not a number of seconds (within +-292 years)";
        return false;
      }
      if (have_prev_ && *t < prev_t_) {
        *err = where(name_, line_no, cells_[0].col) + "time " + std::string(cells_[0].text) +
               " s goes back (the row before is at " + prev_text_ + " s)";
        return false;
      }
      prev_text_.assign(cells_[0].text);
    } else {
      *t = static_cast<int64_t>(state_) * cycle_ns_;
    }
    values->resize(columns_.size());
    for (size_t c = 0; c < columns_.size(); ++c) {
      const Cell& cell = cells_[c + off];
      if (looks_like_literal(cell.text)) {
        int64_t ns = 0;
        TraceColumn::Kind kind{};
        std::string why;
        size_t at = 0;
        if (!parse_time_literal(cell.text, &ns, &kind, &why, &at)) {
          *err = where(name_, line_no, cell.col + at) + "'" + std::string(cell.text) + "' in column " + columns_[c].name +
                 " is not a number or a TIME, DATE, TOD or DT literal" + (why.empty() ? "" : ": " + why);
          return false;
        }
        if (first_pass_) {
          // A column holds one type: the kind of its first literal.
          auto& k = columns_[c].kind;
          if (!columns_[c].is_time()) k = kind;
          else if (k != kind) {
            *err = where(name_, line_no, cell.col) + "'" + std::string(cell.text) + "' in column " + columns_[c].name +
                   " is a " + time_kind_name(kind) + " literal; the column's earlier literals are " + time_kind_name(k);
            return false;
          }
        }
        (*values)[c] = static_cast<double>(ns);
        if (!time_values_.empty()) time_values_[c] = ns;
        continue;
      }
      if (!parse_number(cell.text, &(*values)[c], &scratch_)) {
        *err = where(name_, line_no, cell.col) + "'" + std::string(cell.text) + "' in column " + columns_[c].name +
               " is not a number";
        return false;
      }
      if (!time_values_.empty() && columns_[c].is_time()) {
        // Nanoseconds, as traces wrote time columns before the literals: read exactly.
        int64_t ns = 0;
        auto [end, ec] = std::from_chars(cell.text.data(), cell.text.data() + cell.text.size(), ns);
        if (ec != std::errc() || end != cell.text.data() + cell.text.size()) {
          double v = std::nearbyint((*values)[c]);
          if (!(v > -9.2e18 && v < 9.2e18)) {
            *err = where(name_, line_no, cell.col) + "'" + std::string(cell.text) + "' in column " + columns_[c].name +
                   " is outside what a TIME can hold (nanoseconds within +-9.2e18)";
            return false;
          }
          ns = static_cast<int64_t>(v);
        }
        time_values_[c] = ns;
      }
    }
    prev_t_ = *t;
    have_prev_ = true;
    ++state_;
    return true;
  }

  std::string name_;
  std::unique_ptr<std::istream> in_;
  std::unique_ptr<LineSource> lines_;
  std::vector<Cell> cells_;
  std::vector<double> values_;
  std::string scratch_, prev_text_;
  int64_t cycle_ns_ = 0, prev_t_ = 0;
  bool have_prev_ = false;
  bool first_pass_ = false;  // the pass that finds the columns' kinds
  uint64_t state_ = 0;
};

// ---------------------------------------------------------------------------------------
// VCD: header ($scope/$var/$upscope), then #time and value changes.

class VcdReader final : public TraceReader {
 public:
  bool init(std::string name, std::unique_ptr<std::istream> in, int64_t cycle_ns, std::string* err) {
    name_ = std::move(name);
    in_ = std::move(in);
    cycle_ns_ = cycle_ns;
    has_time_ = true;
    // The open scopes as one prefix "a.b." and where each scope's part starts in it:
    // a variable's full name costs its own length, not the depth times the prefix.
    std::string prefix;
    std::vector<size_t> scope_starts;
    std::string tok;
    size_t end_line = 0, end_col = 0;  // of $enddefinitions
    while (word(&tok)) {
      size_t tok_line = word_line_, tok_col = word_col_;
      if (tok == "$scope") {
        std::string kind, scope;
        if (!expect_word(&kind, "$scope", "its kind") || !expect_word(&scope, "$scope", "its name")) return fail(err);
        if (scope_starts.size() + 1 >= TraceLimits::kMaxNameDepth) {
          error_ = where(name_, tok_line, tok_col) + "more than " + std::to_string(TraceLimits::kMaxNameDepth - 1) +
                   " nested $scope sections";
          return fail(err);
        }
        scope_starts.push_back(prefix.size());
        prefix += scope;
        prefix += '.';
        if (!skip_end(tok, tok_line, tok_col)) return fail(err);
      } else if (tok == "$upscope") {
        if (scope_starts.empty()) {
          error_ = where(name_, tok_line, tok_col) + "$upscope without an open $scope";
          return fail(err);
        }
        prefix.resize(scope_starts.back());
        scope_starts.pop_back();
        if (!skip_end(tok, tok_line, tok_col)) return fail(err);
      } else if (tok == "$var") {
        if (!read_var(prefix, scope_starts.size(), tok_line, tok_col)) return fail(err);
      } else if (tok == "$timescale") {
        if (!read_timescale(tok_line, tok_col)) return fail(err);
      } else if (tok == "$enddefinitions") {
        end_line = tok_line;
        end_col = tok_col;
        if (!skip_end(tok, tok_line, tok_col)) return fail(err);
        break;
      } else if (tok[0] == '$') {
        if (!skip_end(tok, tok_line, tok_col)) return fail(err);
      } else {
        error_ = where(name_, tok_line, tok_col) + "unexpected '" + tok + "' in the VCD header";
        return fail(err);
      }
    }
    if (!error_.empty()) return fail(err);
    if (columns_.empty()) {
      *err = (end_line ? where(name_, end_line, end_col) : where(name_, line_, col_ + 1)) + "no $var in the VCD header";
      return false;
    }
    cur_.assign(columns_.size(), 0.0);
    return true;
  }

  bool next(int64_t* t, std::vector<double>* values, std::string* err) override {
    // Resampled: states every cycle_ns, each holding the values of the last change.
    if (cycle_ns_ > 0) {
      if (sampling_done_) return false;
      if (!started_) {
        if (!advance()) return fail(err);
        started_ = true;
        sample_t_ = pending_t_;
      }
      while (!ended_ && next_change_t_ <= sample_t_)
        if (!advance() && !error_.empty()) return fail(err);
      if (ended_ && sample_t_ > last_t_) return false;
      *t = sample_t_;
      *values = cur_;
      // The last representable sample ends the trace instead of wrapping around.
      if (__builtin_add_overflow(sample_t_, cycle_ns_, &sample_t_)) sampling_done_ = true;
      return true;
    }
    if (!advance()) return fail(err);
    *t = pending_t_;
    *values = cur_;
    return true;
  }

 private:
  bool fail(std::string* err) {
    *err = error_;
    return false;
  }

  // Next byte, or EOF; counts lines and columns; blocks read at a time.
  int get() {
    if (pos_ == buf_.size()) {
      if (eof_) return EOF;
      buf_.resize(kBlockBytes);
      in_->read(buf_.data(), static_cast<std::streamsize>(kBlockBytes));
      buf_.resize(static_cast<size_t>(in_->gcount()));
      pos_ = 0;
      if (in_->bad()) {
        error_ = name_ + ": read error: " + std::strerror(errno);
        eof_ = true;
        buf_.clear();
        return EOF;
      }
      if (buf_.empty()) {
        eof_ = true;
        return EOF;
      }
    }
    auto c = static_cast<unsigned char>(buf_[pos_++]);
    if (c == '\n') {
      ++line_;
      col_ = 0;
    } else {
      ++col_;
    }
    return c;
  }

  static bool is_blank(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

  // The next whitespace-separated word, with its position in word_line_/word_col_.
  // False at the end or on an error (error_ set).
  bool word(std::string* out) {
    out->clear();
    if (!error_.empty()) return false;
    int c;
    while ((c = get()) != EOF && is_blank(c)) {
    }
    word_line_ = line_;
    word_col_ = col_;
    while (c != EOF && !is_blank(c)) {
      if (c < 0x20 || c == 0x7f) {
        error_ = where(name_, line_, col_) + bad_byte(static_cast<unsigned char>(c));
        return false;
      }
      if (out->size() >= TraceLimits::kMaxWordBytes) {
        error_ = where(name_, word_line_, word_col_) + "a word longer than " +
                 std::to_string(TraceLimits::kMaxWordBytes >> 20) + " MiB (not a VCD trace?)";
        return false;
      }
      *out += static_cast<char>(c);
      c = get();
    }
    return !out->empty();
  }

  // A word that must be there (part of `section`), else an error naming `what`.
  bool expect_word(std::string* out, const char* section, const char* what) {
    if (word(out) && *out != "$end") return true;
    if (error_.empty())
      error_ = where(name_, out->empty() ? line_ : word_line_, out->empty() ? col_ + 1 : word_col_) + section +
               ": expected " + what;
    return false;
  }

  // Skips to the $end of the section `section` opened at line:col.
  bool skip_end(const std::string& section, size_t line, size_t col) {
    std::string w;
    size_t bytes = 0;
    while (word(&w)) {
      if (w == "$end") return true;
      bytes += w.size() + 1;
      if (bytes > TraceLimits::kMaxSectionBytes) {
        error_ = where(name_, line, col) + section + " without $end in the next " +
                 std::to_string(TraceLimits::kMaxSectionBytes >> 20) + " MiB";
        return false;
      }
    }
    if (error_.empty()) error_ = where(name_, line, col) + section + " without $end";
    return false;
  }

  // $var kind width id name [range] $end
  bool read_var(const std::string& prefix, size_t depth, size_t line, size_t col) {
    std::string kind, width, id, var;
    if (!expect_word(&kind, "$var", "its type") || !expect_word(&width, "$var", "its width")) return false;
    size_t width_line = word_line_, width_col = word_col_;
    if (!expect_word(&id, "$var", "its identifier code") || !expect_word(&var, "$var", "its name")) return false;
    size_t name_line = word_line_, name_col = word_col_;
    unsigned w = 0;
    auto [p, ec] = std::from_chars(width.data(), width.data() + width.size(), w);
    if (ec != std::errc() || p != width.data() + width.size() || w < 1 || w > 64) {
      error_ = where(name_, width_line, width_col) + "width '" + width + "' is not 1..64";
      return false;
    }
    if (columns_.size() >= TraceLimits::kMaxColumns) {
      error_ = where(name_, line, col) + "more than " + std::to_string(TraceLimits::kMaxColumns) + " $var";
      return false;
    }
    if (depth + 1 + static_cast<size_t>(std::count(var.begin(), var.end(), '.')) > TraceLimits::kMaxNameDepth) {
      error_ = where(name_, name_line, name_col) + "name nested deeper than " +
               std::to_string(TraceLimits::kMaxNameDepth) + " scopes and dotted parts";
      return false;
    }
    TraceColumn c{prefix + var, TraceColumn::Kind::Int};
    if (kind == "real") c.kind = TraceColumn::Kind::Real;
    else if (w == 1) c.kind = TraceColumn::Kind::Bool;
    // Several $var may share one identifier code (the same signal seen in two scopes).
    ids_[id].push_back(columns_.size());
    columns_.push_back(std::move(c));
    widths_.push_back(w);
    signed_.push_back(kind == "integer");
    return skip_end("$var", line, col);
  }

  // $timescale 1ns $end, or "1 ns": 1, 10 or 100 of s, ms, us, ns.
  bool read_timescale(size_t line, size_t col) {
    std::string ts;
    if (!expect_word(&ts, "$timescale", "a time unit")) return false;
    size_t k = 0;
    while (k < ts.size() && std::isdigit(static_cast<unsigned char>(ts[k]))) ++k;
    int64_t mult = 1;
    if (k > 0) {
      auto [p, ec] = std::from_chars(ts.data(), ts.data() + k, mult);
      if (ec != std::errc() || mult < 1 || mult > 1000) {
        error_ = where(name_, word_line_, word_col_) + "$timescale '" + ts + "': the factor is not 1..1000";
        return false;
      }
    }
    std::string unit = ts.substr(k);
    bool separate = unit.empty();  // "1 ns"
    if (separate && !expect_word(&unit, "$timescale", "a time unit")) return false;
    int64_t u = unit == "s" ? 1'000'000'000 : unit == "ms" ? 1'000'000 : unit == "us" ? 1'000 : unit == "ns" ? 1 : 0;
    if (u == 0) {
      error_ = where(name_, line, col) + "unsupported $timescale '" + ts + (separate ? " " + unit : "") +
               "' (s, ms, us or ns)";
      return false;
    }
    timescale_ = mult * u;
    return skip_end("$timescale", line, col);
  }

  // "#123" scaled to ns; an error when it is no number, overflows or goes back.
  bool read_time(const std::string& w, int64_t* t) {
    int64_t v = 0;
    auto [p, ec] = std::from_chars(w.data() + 1, w.data() + w.size(), v);
    if (ec != std::errc() || p != w.data() + w.size() || v < 0) {
      error_ = where(name_, word_line_, word_col_) + "'" + w + "' is not a time stamp (#, then a non-negative integer)";
      return false;
    }
    if (__builtin_mul_overflow(v, timescale_, t)) {
      error_ = where(name_, word_line_, word_col_) + "time stamp '" + w + "' overflows 64-bit nanoseconds";
      return false;
    }
    if (seen_time_ && *t < last_t_) {
      error_ = where(name_, word_line_, word_col_) + "time " + w + " goes back (the time before is #" +
               std::to_string(last_t_ / timescale_) + ")";
      return false;
    }
    seen_time_ = true;
    last_t_ = *t;
    return true;
  }

  // Applies the changes of one time stamp to cur_; pending_t_ is that time, and
  // next_change_t_ the following one (INT64_MAX at the end). False at the end or on an
  // error (error_ set).
  bool advance() {
    if (ended_) return false;
    std::string w;
    if (have_next_) {
      have_next_ = false;
      pending_t_ = next_t_;
    } else {
      // Up to the first time stamp only keywords may come.
      for (;;) {
        if (!word(&w)) {
          ended_ = true;
          return false;
        }
        if (w[0] == '#') break;
        if (w == "$dumpvars" || w == "$end" || w == "$dumpall" || w == "$dumpon" || w == "$dumpoff") continue;
        if (w == "$comment") {
          if (!skip_end(w, word_line_, word_col_)) return false;
          continue;
        }
        error_ = where(name_, word_line_, word_col_) +
                 (w[0] == '$' ? "unexpected '" + w + "' in the VCD body" : "value change before the first #time");
        return false;
      }
      if (!read_time(w, &pending_t_)) return false;
    }
    for (;;) {
      if (!word(&w)) {
        if (!error_.empty()) return false;
        ended_ = true;
        next_change_t_ = INT64_MAX;
        return true;
      }
      if (w[0] == '#') {
        if (!read_time(w, &next_t_)) return false;
        have_next_ = true;
        next_change_t_ = next_t_;
        return true;
      }
      if (w == "$dumpvars" || w == "$end" || w == "$dumpall" || w == "$dumpon" || w == "$dumpoff") continue;
      if (w == "$comment") {
        if (!skip_end(w, word_line_, word_col_)) return false;
        continue;
      }
      if (!apply_change(w)) return false;
    }
  }

  // One value change: 0! 1! x! z!, b0101 !, r1.5 !.
  bool apply_change(const std::string& w) {
    size_t line = word_line_, col = word_col_;
    char k = w[0];
    std::string value, id;
    if (k == 'b' || k == 'B' || k == 'r' || k == 'R') {
      value = w.substr(1);
      if (!word(&id)) {
        if (error_.empty()) error_ = where(name_, line, col) + "value change '" + w + "' without an identifier";
        return false;
      }
    } else if (k == '0' || k == '1' || k == 'x' || k == 'X' || k == 'z' || k == 'Z') {
      value = std::string(1, k);
      id = w.substr(1);
      if (id.empty()) {
        error_ = where(name_, line, col) + "value change '" + w + "' without an identifier";
        return false;
      }
    } else {
      error_ = where(name_, line, col) + "unexpected '" + w + "' in the VCD body";
      return false;
    }
    auto it = ids_.find(id);
    if (it == ids_.end()) {
      error_ = where(name_, word_line_, word_col_) + "value change for undeclared identifier '" + id + "'";
      return false;
    }
    for (size_t c : it->second) {
      double v = 0;
      if (!decode(k, value, c, &v)) {
        error_ = where(name_, line, col) + "'" + w + "' is not a value of " + columns_[c].name + " (" +
                 std::to_string(widths_[c]) + " bit" + (widths_[c] == 1 ? "" : "s") + ")";
        return false;
      }
      cur_[c] = v;
    }
    return true;
  }

  bool decode(char k, const std::string& value, size_t c, double* v) {
    if (k == 'r' || k == 'R') {
      char* end = nullptr;
      *v = std::strtod(value.c_str(), &end);
      return !value.empty() && end == value.c_str() + value.size() && std::isfinite(*v);
    }
    size_t width = widths_[c];
    if (value.empty() || value.size() > width) return false;
    uint64_t bits = 0;
    for (char ch : value) {
      if (ch != '0' && ch != '1' && ch != 'x' && ch != 'X' && ch != 'z' && ch != 'Z') return false;
      bits = (bits << 1) | (ch == '1' ? 1u : 0u);
    }
    // A shorter value is zero-extended (VCD); a signed "integer" that fills its width
    // with a leading 1 is negative (two's complement).
    if (signed_[c] && value.size() == width && value[0] == '1' && width > 1 && width < 64)
      *v = static_cast<double>(static_cast<int64_t>(bits) - (static_cast<int64_t>(1) << width));
    else if (signed_[c] && width == 64 && value.size() == 64)
      *v = static_cast<double>(static_cast<int64_t>(bits));
    else
      *v = static_cast<double>(bits);
    return true;
  }

  std::string name_;
  std::unique_ptr<std::istream> in_;
  std::string buf_;
  size_t pos_ = 0;
  bool eof_ = false;
  size_t line_ = 1, col_ = 0;  // of the byte last read
  size_t word_line_ = 1, word_col_ = 1;
  std::string error_;
  int64_t cycle_ns_ = 0, timescale_ = 1;
  std::unordered_map<std::string, std::vector<size_t>> ids_;
  std::vector<unsigned> widths_;
  std::vector<bool> signed_;
  std::vector<double> cur_;
  int64_t pending_t_ = 0, next_change_t_ = 0, sample_t_ = 0, last_t_ = 0, next_t_ = 0;
  bool seen_time_ = false, have_next_ = false;
  bool started_ = false, ended_ = false, sampling_done_ = false;
};

bool is_identifier(std::string_view s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

std::unique_ptr<TraceReader> make_reader(const std::string& name, std::unique_ptr<std::istream> in, TraceFormat format,
                                         int64_t cycle_ns, std::string* err) {
  err->clear();
  if (format == TraceFormat::Vcd) {
    auto r = std::make_unique<VcdReader>();
    if (!r->init(name, std::move(in), cycle_ns, err)) return nullptr;
    return r;
  }
  auto r = std::make_unique<CsvReader>();
  if (!r->init(name, std::move(in), cycle_ns, err)) return nullptr;
  return r;
}

}  // namespace

std::unique_ptr<TraceReader> TraceReader::open(const std::string& path, int64_t cycle_ns, std::string* err) {
  bool vcd = path.size() > 4 && path.substr(path.size() - 4) == ".vcd";
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    *err = path + ": cannot open: " + std::strerror(errno);
    return nullptr;
  }
  if (S_ISDIR(st.st_mode)) {
    *err = path + ": is a directory, not a trace";
    return nullptr;
  }
  // The CSV reader's first pass must be repeatable; a VCD is read once and may come
  // from a pipe.
  if (!vcd && !S_ISREG(st.st_mode)) {
    *err = path + ": not a regular file (a CSV trace is read twice)";
    return nullptr;
  }
  auto in = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*in) {
    *err = path + ": cannot open: " + std::strerror(errno);
    return nullptr;
  }
  return make_reader(path, std::move(in), vcd ? TraceFormat::Vcd : TraceFormat::Csv, cycle_ns, err);
}

std::unique_ptr<TraceReader> TraceReader::from_text(const std::string& name, std::string text, TraceFormat format,
                                                    int64_t cycle_ns, std::string* err) {
  return make_reader(name, std::make_unique<std::istringstream>(std::move(text)), format, cycle_ns, err);
}

bool trace_program(const std::vector<TraceColumn>& cols, std::string* source, std::string* err) {
  // A tree of names: leaves are variables, inner nodes programs (top) or structs.
  struct Node {
    std::map<std::string, Node, std::less<>> children;
    const TraceColumn* leaf = nullptr;
  };
  Node root;
  for (const auto& c : cols) {
    if (!c.name.empty() && c.name[0] == '%') continue;  // image addresses need no declaration
    if (name_too_deep(c.name)) {
      *err = "trace column '" + c.name + "' is nested deeper than " + std::to_string(TraceLimits::kMaxNameDepth) + " names";
      return false;
    }
    Node* n = &root;
    std::string_view rest = c.name;
    for (;;) {
      size_t dot = rest.find('.');
      std::string_view part = rest.substr(0, dot);
      if (!is_identifier(part)) {
        *err = "trace column '" + c.name + "' is not an ST name (letters, digits, '_', dots between names)";
        return false;
      }
      if (n->leaf) {
        *err = "trace column '" + c.name + "' is inside the column of a plain variable";
        return false;
      }
      auto it = n->children.find(part);
      if (it == n->children.end()) it = n->children.emplace(std::string(part), Node{}).first;
      n = &it->second;
      if (dot == std::string_view::npos) break;
      rest = rest.substr(dot + 1);
    }
    if (n->leaf || !n->children.empty()) {
      *err = "trace column '" + c.name + "' appears twice or also has members";
      return false;
    }
    n->leaf = &c;
  }
  auto type_of = [](const TraceColumn& c) {
    switch (c.kind) {
      case TraceColumn::Kind::Bool: return "BOOL";
      case TraceColumn::Kind::Int: return "LINT";
      case TraceColumn::Kind::Real: return "LREAL";
      case TraceColumn::Kind::Time: return "TIME";
      case TraceColumn::Kind::Date: return "DATE";
      case TraceColumn::Kind::Tod: return "TOD";
      case TraceColumn::Kind::Dt: return "DT";
    }
    return "LREAL";
  };
  std::string types, globals, programs;
  int struct_id = 0;
  // Recursion depth is bounded by kMaxNameDepth (checked above).
  auto struct_of = [&](const Node& n, auto& self) -> std::string {
    std::string name = "__TraceStruct" + std::to_string(++struct_id);
    std::string body;
    for (const auto& [k, child] : n.children)
      body += "  " + k + " : " + (child.leaf ? std::string(type_of(*child.leaf)) : self(child, self)) + ";\n";
    types += "TYPE " + name + " : STRUCT\n" + body + "END_STRUCT; END_TYPE\n";
    return name;
  };
  for (const auto& [k, child] : root.children) {
    if (child.leaf) {
      globals += "  " + k + " : " + type_of(*child.leaf) + ";\n";
      continue;
    }
    std::string vars;
    for (const auto& [m, gc] : child.children)
      vars += "  " + m + " : " + (gc.leaf ? std::string(type_of(*gc.leaf)) : struct_of(gc, struct_of)) + ";\n";
    programs += "PROGRAM " + k + "\nVAR\n" + vars + "END_VAR\nEND_PROGRAM\n";
  }
  *source = types;
  if (!globals.empty()) *source += "VAR_GLOBAL\n" + globals + "END_VAR\n";
  *source += programs;
  return true;
}

bool resolve_trace_columns(const st::Application& app, const std::vector<TraceColumn>& cols,
                           std::vector<st::VarHandle>* handles, std::string* err) {
  // ST names are case-insensitive: the indexes hold upper-case keys.
  auto key = [](std::string_view s) {
    std::string k(s);
    for (char& c : k) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return k;
  };
  struct Base {
    const st::Type* type;
    uint32_t addr;
  };
  // As st::resolve: a program instance first, then a global (the first of that name; a
  // located bit is left to st::resolve).
  std::unordered_map<std::string, Base> tops;
  for (const auto& g : app.globals)
    if (g.sym->where != st::Where::AbsBit) tops.emplace(key(g.sym->name), Base{g.sym->type, g.sym->offset});
  for (const auto& pi : app.programs) tops.insert_or_assign(key(pi.name), Base{pi.pou->type, pi.addr});
  std::unordered_map<const st::Type*, std::unordered_map<std::string, const st::Field*>> members;
  auto member = [&](const st::Type* t, std::string_view name) -> const st::Field* {
    if (t->kind != st::TypeKind::Struct && t->kind != st::TypeKind::Pou) return nullptr;
    auto [it, fresh] = members.try_emplace(t);
    if (fresh)
      for (const auto& f : t->fields) it->second.emplace(key(f.name), &f);
    auto f = it->second.find(key(name));
    return f == it->second.end() ? nullptr : f->second;
  };
  handles->clear();
  handles->reserve(cols.size());
  for (const auto& c : cols) {
    std::optional<st::VarHandle> h;
    if (c.name.empty() || c.name[0] != '%') {
      std::string_view rest = c.name;
      size_t dot = rest.find('.');
      auto top = tops.find(key(rest.substr(0, dot)));
      if (top != tops.end()) {
        const st::Type* t = top->second.type;
        uint32_t addr = top->second.addr;
        while (t && dot != std::string_view::npos) {
          rest = rest.substr(dot + 1);
          dot = rest.find('.');
          const st::Field* f = member(t, rest.substr(0, dot));
          t = f ? f->type : nullptr;
          if (f) addr += f->offset;
        }
        if (t && t->is_elementary()) {
          h = st::VarHandle{};
          h->path = c.name;
          h->type = t;
          h->addr = addr;
        }
      }
    }
    if (!h) h = st::resolve(app, c.name, err);
    if (!h) {
      *err = "column " + c.name + ": " + *err;
      return false;
    }
    handles->push_back(*h);
  }
  return true;
}

}  // namespace plcfi::monitor
