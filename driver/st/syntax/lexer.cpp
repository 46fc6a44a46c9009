// ST lexer: turns a source buffer into tokens and decodes every literal form.
#include "lexer.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <string>

#include "common/duration.hpp"

namespace plcfi::st {

namespace {

constexpr std::array<std::string_view, static_cast<size_t>(Tok::Count)> kTokNames = {
    "end of file", "identifier", "integer literal", "real literal", "string literal",
    "wide string literal", "time literal", "direct address",
    "'('", "')'", "'['", "']'", "','", "';'", "':'", "':='", "'=>'", "'REF='",
    "'.'", "'..'", "'#'", "'^'", "'+'", "'-'", "'*'", "'**'", "'/'", "'&'",
    "'='", "'<>'", "'<'", "'>'", "'<='", "'>='",
#define PLCFI_ST_KW_NAME(name, text) text,
    PLCFI_ST_KEYWORDS(PLCFI_ST_KW_NAME)
#undef PLCFI_ST_KW_NAME
};

struct KeywordEntry {
  std::string_view text;
  Tok kind;
};

constexpr KeywordEntry kKeywords[] = {
#define PLCFI_ST_KW_ENTRY(name, text) {text, Tok::name},
    PLCFI_ST_KEYWORDS(PLCFI_ST_KW_ENTRY)
#undef PLCFI_ST_KW_ENTRY
};

bool is_ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
char upper(char c) { return static_cast<char>(std::toupper(static_cast<unsigned char>(c))); }

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  c = upper(c);
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
int64_t days_from_civil(int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<int64_t>(doe) - 719468;
}

unsigned days_in_month(int64_t y, unsigned m) {
  static constexpr unsigned kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (m == 2 && ((y % 4 == 0 && y % 100 != 0) || y % 400 == 0)) return 29;
  return kDays[m - 1];
}

enum class TimePrefix { None, Duration, Date, TimeOfDay, DateTime };

TimePrefix classify_prefix(std::string_view word, bool* is_long) {
  const std::string w = canon(word);
  *is_long = false;
  if (w == "T" || w == "TIME") return TimePrefix::Duration;
  if (w == "LT" || w == "LTIME") return *is_long = true, TimePrefix::Duration;
  if (w == "D" || w == "DATE") return TimePrefix::Date;
  if (w == "LD" || w == "LDATE") return *is_long = true, TimePrefix::Date;
  if (w == "TOD" || w == "TIME_OF_DAY") return TimePrefix::TimeOfDay;
  if (w == "LTOD" || w == "LTIME_OF_DAY") return *is_long = true, TimePrefix::TimeOfDay;
  if (w == "DT" || w == "DATE_AND_TIME") return TimePrefix::DateTime;
  if (w == "LDT" || w == "LDATE_AND_TIME") return *is_long = true, TimePrefix::DateTime;
  return TimePrefix::None;
}

constexpr int64_t kNsPerSec = 1'000'000'000;
constexpr int64_t kNsPerDay = 86'400 * kNsPerSec;

}  // namespace

std::string_view tok_name(Tok kind) {
  const auto i = static_cast<size_t>(kind);
  return i < kTokNames.size() ? kTokNames[i] : "token";
}

Tok keyword_kind(std::string_view word) {
  if (word.empty() || word.size() > 20) return Tok::Ident;
  for (const auto& kw : kKeywords)
    if (iequals(kw.text, word)) return kw.kind;
  return Tok::Ident;
}

Lexer::Lexer(const SourceManager& sm, uint32_t file, DiagEngine& diags)
    : src_(sm.file(file)), file_(file), diags_(diags), text_(src_.text) {
  // Editors on Windows (and CODESYS exports) often start files with a UTF-8 byte order mark.
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
}

SourceLoc Lexer::loc_at(size_t offset) const {
  const auto& starts = src_.line_starts;
  auto it = std::upper_bound(starts.begin(), starts.end(), static_cast<uint32_t>(offset));
  const size_t line = static_cast<size_t>(it - starts.begin());  // >= 1: starts[0] == 0
  return SourceLoc{file_, static_cast<uint32_t>(line), static_cast<uint32_t>(offset - starts[line - 1] + 1)};
}

void Lexer::error(std::string_view code, size_t offset, std::string message) {
  diags_.error(std::string(code), loc_at(offset), std::move(message));
}

Token Lexer::make(Tok kind, size_t begin) const {
  Token t;
  t.kind = kind;
  t.offset = static_cast<uint32_t>(begin);
  t.loc = loc_at(begin);
  t.end = loc_at(pos_);
  // A token never spans lines except an unterminated construct; keep `end` on the start line
  // so "after the previous token" locations stay on the statement's line.
  if (t.end.line != t.loc.line) t.end = SourceLoc{file_, t.loc.line, t.loc.col + 1};
  t.text = text_.substr(begin, pos_ - begin);
  return t;
}

void Lexer::skip_trivia() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v') {
      ++pos_;
    } else if (c == '/' && peek(1) == '/') {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else if ((c == '(' && peek(1) == '*') || (c == '/' && peek(1) == '*')) {
      // Both comment styles nest, each counting only its own delimiters, so that commenting
      // out code that already contains comments works.
      const char open = c;
      const char close = c == '(' ? ')' : '/';
      const size_t begin = pos_;
      int depth = 0;
      while (pos_ < text_.size()) {
        if (text_[pos_] == open && peek(1) == '*') {
          ++depth;
          pos_ += 2;
        } else if (text_[pos_] == '*' && peek(1) == close) {
          pos_ += 2;
          if (--depth == 0) break;
        } else {
          ++pos_;
        }
      }
      if (depth != 0) {
        junk_ = true;
        error("ST002", begin, open == '(' ? "unterminated comment: '(*' has no matching '*)'"
                                          : "unterminated comment: '/*' has no matching '*/'");
        pos_ = text_.size();
      }
    } else if (c == '{' && peek(1) == '{') {
      // Beremiz runs C written between {{ and }} in an ST body; plcfi cannot, and ignoring
      // it like a pragma would run a different program.
      const size_t begin = pos_;
      const size_t close = text_.find("}}", pos_ + 2);
      junk_ = true;
      error("ST014", begin, "inline C code ({{ ... }}) is a Beremiz extension: plcfi runs IEC 61131-3 code, not C; "
                            "write this part in ST");
      pos_ = close == std::string_view::npos ? text_.size() : close + 2;
    } else if (c == '{') {
      const size_t begin = pos_;
      const size_t close = text_.find('}', pos_);
      if (close == std::string_view::npos) {
        junk_ = true;
        error("ST011", begin, "unterminated pragma: '{' has no matching '}'");
        pos_ = text_.size();
      } else {
        pos_ = close + 1;
        pragma(begin, close);
        if (!active()) skip_inactive();
      }
    } else {
      break;
    }
  }
  if (pos_ >= text_.size() && !conds_.empty()) {
    error("ST011", conds_.back().at, "{IF} without {END_IF} before the end of the file");
    conds_.clear();
  }
}

bool Lexer::active() const { return conds_.empty() || conds_.back().active; }

namespace {
std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}
std::string upper_word(std::string_view s) {
  std::string w;
  for (char ch : s) {
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_') break;
    w += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  }
  return w;
}
// The text between the first pair of single quotes, or all of s.
std::string_view quoted(std::string_view s) {
  size_t a = s.find('\'');
  size_t b = a == std::string_view::npos ? a : s.find('\'', a + 1);
  return b == std::string_view::npos ? trim(s) : s.substr(a + 1, b - a - 1);
}
}  // namespace

void Lexer::pragma(size_t begin, size_t end) {
  std::string_view body = trim(text_.substr(begin + 1, end - begin - 1));
  std::string word = upper_word(body);
  std::string_view rest = trim(body.substr(word.size()));
  bool outer = active();
  if (word == "IF") {
    bool on = outer && eval_condition(rest, begin);
    conds_.push_back({on, on, outer, begin});
    return;
  }
  if (word == "ELSIF" || word == "ELSE" || word == "END_IF") {
    if (conds_.empty()) {
      error("ST011", begin, "{" + word + "} without {IF}");
      return;
    }
    Cond& c = conds_.back();
    if (word == "END_IF") {
      conds_.pop_back();
    } else if (word == "ELSE") {
      c.active = c.outer && !c.taken;
      c.taken = true;
    } else {
      bool on = c.outer && !c.taken && eval_condition(rest, begin);
      c.active = on;
      c.taken = c.taken || on;
    }
    return;
  }
  if (!outer) return;
  if (word == "DEFINE" || word == "UNDEFINE") {
    std::string name = upper_word(rest);
    if (name.empty()) {
      error("ST011", begin, "{" + std::string(body.substr(0, word.size())) + "} needs a name");
      return;
    }
    defines_.erase(std::remove(defines_.begin(), defines_.end(), name), defines_.end());
    if (word == "DEFINE") defines_.push_back(name);
    return;
  }
  if (word == "WARNING" || word == "INFO" || word == "TEXT") {
    if (word == "WARNING") diags_.warning("ST406", loc_at(begin), std::string(quoted(rest)));
    return;
  }
  if (word == "ERROR") {
    error("ST013", begin, std::string(quoted(rest)));
    return;
  }
  // Pragmas that change nothing a run depends on: declarations' attributes (qualified_only,
  // hide, call_after_init, ...), regions, library and flag pragmas, CODESYS's messageguid.
  static const char* const kQuiet[] = {"ATTRIBUTE", "REGION", "ENDREGION", "LIBRARY", "FLAG", "MESSAGEGUID", "BITACCESS",
                                       "LINKALWAYS", "PRAGMA"};
  for (const char* q : kQuiet)
    if (word == q) return;
  std::string shown(body.substr(0, std::min<size_t>(body.size(), 40)));
  diags_.warning("ST406", loc_at(begin), "unknown pragma {" + shown + (body.size() > 40 ? "..." : "") + "} ignored");
}

// defined(NAME), NOT, AND, OR and parentheses; other conditions (hasattribute, hastype,
// ...) are false, with a warning.
bool Lexer::eval_condition(std::string_view expr, size_t at) {
  size_t i = 0;
  bool unknown = false;
  auto skip_ws = [&] {
    while (i < expr.size() && std::isspace(static_cast<unsigned char>(expr[i]))) ++i;
  };
  auto word = [&] {
    skip_ws();
    std::string w = upper_word(expr.substr(i));
    return w;
  };
  // Recursive descent over a few levels; the depth is bounded by the pragma's length,
  // which is bounded by the line, and a guard stops runaway nesting.
  int depth = 0;
  std::function<bool()> disj, conj, unary;
  unary = [&]() -> bool {
    if (++depth > 64) {
      unknown = true;
      i = expr.size();
      return false;
    }
    skip_ws();
    bool v = false;
    std::string w = word();
    if (w == "NOT") {
      i += 3;
      v = !unary();
    } else if (i < expr.size() && expr[i] == '(') {
      ++i;
      v = disj();
      skip_ws();
      if (i < expr.size() && expr[i] == ')') ++i;
    } else if (w == "DEFINED") {
      i += w.size();
      skip_ws();
      if (i < expr.size() && expr[i] == '(') ++i;
      skip_ws();
      std::string name = upper_word(expr.substr(i));
      i += name.size();
      skip_ws();
      if (i < expr.size() && expr[i] == ')') ++i;
      v = std::find(defines_.begin(), defines_.end(), name) != defines_.end();
    } else {
      unknown = true;
      // Skip the unknown operand: a name and a parenthesised argument list.
      i += w.size();
      skip_ws();
      if (i < expr.size() && expr[i] == '(') {
        int open = 0;
        for (; i < expr.size(); ++i) {
          if (expr[i] == '(') ++open;
          if (expr[i] == ')' && --open == 0) {
            ++i;
            break;
          }
        }
      } else if (w.empty()) {
        i = expr.size();
      }
    }
    --depth;
    return v;
  };
  conj = [&]() -> bool {
    bool v = unary();
    while (word() == "AND") {
      i += 3;
      v = unary() && v;
    }
    return v;
  };
  disj = [&]() -> bool {
    bool v = conj();
    while (word() == "OR") {
      i += 2;
      v = conj() || v;
    }
    return v;
  };
  bool v = disj();
  if (unknown)
    diags_.warning("ST406", loc_at(at), "condition '" + std::string(expr) +
                                            "': only defined(NAME), NOT, AND and OR are evaluated; the rest counts as FALSE");
  return v;
}

// Text in a conditional branch not taken is skipped as text: comments and strings are
// stepped over (a '{' in them is no pragma), up to the next pragma, which skip_trivia
// then reads.
void Lexer::skip_inactive() {
  while (pos_ < text_.size() && !active()) {
    const char c = text_[pos_];
    if (c == '{') {
      const size_t begin = pos_;
      const size_t close = text_.find('}', pos_);
      if (close == std::string_view::npos) {
        error("ST011", begin, "unterminated pragma: '{' has no matching '}'");
        pos_ = text_.size();
        return;
      }
      pos_ = close + 1;
      pragma(begin, close);
    } else if (c == '/' && peek(1) == '/') {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else if ((c == '(' || c == '/') && peek(1) == '*') {
      const char close = c == '(' ? ')' : '/';
      size_t e = text_.find(std::string{'*', close}, pos_ + 2);
      pos_ = e == std::string_view::npos ? text_.size() : e + 2;
    } else if (c == '\'' || c == '"') {
      size_t e = pos_ + 1;
      while (e < text_.size() && text_[e] != c && text_[e] != '\n') e += text_[e] == '$' ? 2 : 1;
      pos_ = std::min(text_.size(), e + 1);
    } else {
      ++pos_;
    }
  }
}

Token Lexer::next() {
  Token tok = [this]() -> Token {
    skip_trivia();
    const size_t begin = pos_;
    if (pos_ >= text_.size()) {
      // "found end of file" points just after the last visible character, not at a line
      // past the end that no editor shows.
      size_t last = text_.size();
      while (last > 0 && std::isspace(static_cast<unsigned char>(text_[last - 1]))) --last;
      Token eof = make(Tok::Eof, begin);
      eof.loc = eof.end = loc_at(last);
      return eof;
    }
    const char c = text_[pos_];
    if (is_ident_start(c)) return lex_identifier();
    if (is_digit(c)) return lex_number();
    if (c == '\'' || c == '"') return lex_string(c);
    if (c == '%') return lex_direct_address();
    auto two = [&](char second) { return peek(1) == second; };
    Tok kind = Tok::Eof;
    size_t len = 1;
    switch (c) {
      case '(': kind = Tok::LParen; break;
      case ')': kind = Tok::RParen; break;
      case '[': kind = Tok::LBracket; break;
      case ']': kind = Tok::RBracket; break;
      case ',': kind = Tok::Comma; break;
      case ';': kind = Tok::Semi; break;
      case ':': if (two('=')) kind = Tok::Assign, len = 2; else kind = Tok::Colon; break;
      case '=': if (two('>')) kind = Tok::Arrow, len = 2; else kind = Tok::Eq; break;
      case '.': if (two('.')) kind = Tok::DotDot, len = 2; else kind = Tok::Dot; break;
      case '#': kind = Tok::Hash; break;
      case '^': kind = Tok::Caret; break;
      case '+': kind = Tok::Plus; break;
      case '-': kind = Tok::Minus; break;
      case '*': if (two('*')) kind = Tok::Power, len = 2; else kind = Tok::Star; break;
      case '/': kind = Tok::Slash; break;
      case '&': kind = Tok::Amp; break;
      case '<':
        if (two('>')) kind = Tok::Ne, len = 2;
        else if (two('=')) kind = Tok::Le, len = 2;
        else kind = Tok::Lt;
        break;
      case '>': if (two('=')) kind = Tok::Ge, len = 2; else kind = Tok::Gt; break;
      default: break;
    }
    if (kind != Tok::Eof) {
      pos_ += len;
      return make(kind, begin);
    }
    // Garbage: report a run of unknown bytes once (a UTF-8 character is several bytes).
    size_t end = pos_ + 1;
    while (end < text_.size() && (static_cast<unsigned char>(text_[end]) & 0xC0) == 0x80) ++end;
    const std::string shown(text_.substr(pos_, end - pos_));
    error("ST001", begin, "unexpected character '" + shown + "'");
    junk_ = true;
    pos_ = end;
    return next();
  }();
  prev_ = tok.kind;
  tok.after_junk = tok.after_junk || junk_;  // (garbage recurses into next())
  junk_ = false;
  return tok;
}

Token Lexer::lex_identifier() {
  const size_t begin = pos_;
  while (pos_ < text_.size() && is_ident_char(text_[pos_])) ++pos_;
  const std::string_view word = text_.substr(begin, pos_ - begin);
  if (peek() == '#') {
    bool is_long = false;
    if (classify_prefix(word, &is_long) != TimePrefix::None) return lex_time_literal(begin, word);
  }
  // REF= is one token; REF alone is an ordinary name (the REF() operator).
  if (peek() == '=' && peek(1) != '>' && iequals(word, "REF")) {
    ++pos_;
    return make(Tok::RefAssign, begin);
  }
  return make(keyword_kind(word), begin);
}

Token Lexer::lex_number() {
  const size_t begin = pos_;
  auto digits = [&](size_t from) {
    size_t p = from;
    while (p < text_.size() && (is_digit(text_[p]) || text_[p] == '_')) ++p;
    return p;
  };
  pos_ = digits(pos_);
  // After '.', digits are a bit number (w.3) or an address part, never a fraction.
  const bool bit_context = prev_ == Tok::Dot;
  bool is_real = false;
  if (!bit_context && peek() == '.' && is_digit(peek(1))) {
    is_real = true;
    pos_ = digits(pos_ + 1);
  }
  if (!bit_context && (peek() == 'e' || peek() == 'E') &&
      (is_digit(peek(1)) || ((peek(1) == '+' || peek(1) == '-') && is_digit(peek(2))))) {
    is_real = true;
    pos_ = digits(pos_ + 2);
  }
  Token tok;
  if (!is_real && peek() == '#') {
    // Based integer: 2#1010, 8#17, 16#FF.
    std::string base_text;
    for (size_t i = begin; i < pos_; ++i)
      if (text_[i] != '_') base_text += text_[i];
    ++pos_;
    const size_t body = pos_;
    while (pos_ < text_.size() && is_ident_char(text_[pos_])) ++pos_;
    tok = make(Tok::IntLit, begin);
    const std::string_view lit = tok.text;
    const int base = base_text == "2" ? 2 : base_text == "8" ? 8 : base_text == "10" ? 10 : base_text == "16" ? 16 : 0;
    if (base == 0) {
      error("ST006", begin, "unsupported base '" + base_text + "' in literal '" + std::string(lit) +
                                "' (expected 2, 8, 10 or 16)");
      tok.bad = true;
      return tok;
    }
    if (body == pos_) {
      error("ST005", begin, "missing digits after '" + base_text + "#' in literal '" + std::string(lit) + "'");
      tok.bad = true;
      return tok;
    }
    uint64_t value = 0;
    bool overflow = false;
    for (size_t i = body; i < pos_; ++i) {
      const char d = text_[i];
      if (d == '_') continue;
      const int v = hex_value(d);
      if (v < 0 || v >= base) {
        error("ST006", i, "invalid digit '" + std::string(1, d) + "' in base-" + std::to_string(base) +
                              " literal '" + std::string(lit) + "'");
        tok.bad = true;
        return tok;
      }
      if (__builtin_mul_overflow(value, static_cast<uint64_t>(base), &value) ||
          __builtin_add_overflow(value, static_cast<uint64_t>(v), &value))
        overflow = true;
    }
    if (overflow) {
      error("ST007", begin, "integer literal '" + std::string(lit) + "' does not fit in 64 bits");
      tok.bad = true;
    }
    tok.int_value = overflow ? 0 : value;
    return tok;
  }
  // A letter glued to a number (12abc, 1.5x) is a malformed literal, not two tokens.
  if (pos_ < text_.size() && is_ident_char(text_[pos_])) {
    while (pos_ < text_.size() && (is_ident_char(text_[pos_]) || text_[pos_] == '.')) ++pos_;
    tok = make(is_real ? Tok::RealLit : Tok::IntLit, begin);
    error("ST005", begin, "invalid numeric literal '" + std::string(tok.text) + "'");
    tok.bad = true;
    return tok;
  }
  tok = make(is_real ? Tok::RealLit : Tok::IntLit, begin);
  std::string clean;
  for (char d : tok.text)
    if (d != '_') clean += d;
  if (is_real) {
    tok.lit = LiteralKind::Real;
    double v = 0;
    auto [ptr, ec] = std::from_chars(clean.data(), clean.data() + clean.size(), v);
    if (ec == std::errc::result_out_of_range || !std::isfinite(v)) {
      error("ST012", begin, "real literal '" + std::string(tok.text) + "' is out of range");
      tok.bad = true;
    } else if (ec != std::errc() || ptr != clean.data() + clean.size()) {
      error("ST005", begin, "invalid numeric literal '" + std::string(tok.text) + "'");
      tok.bad = true;
    }
    tok.real_value = v;
    return tok;
  }
  uint64_t value = 0;
  for (char d : clean) {
    if (__builtin_mul_overflow(value, uint64_t{10}, &value) ||
        __builtin_add_overflow(value, static_cast<uint64_t>(d - '0'), &value)) {
      error("ST007", begin, "integer literal '" + std::string(tok.text) + "' does not fit in 64 bits");
      tok.bad = true;
      value = 0;
      break;
    }
  }
  tok.int_value = value;
  return tok;
}

Token Lexer::lex_string(char quote) {
  const size_t begin = pos_;
  ++pos_;
  std::string value;
  bool terminated = false;
  bool bad = false;
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == quote) {
      // A doubled quote stands for one ('it''s'), as CODESYS and TwinCAT write it. Two
      // string literals side by side are never valid ST, so no program changes meaning.
      if (peek(1) == quote) {
        value += c;
        pos_ += 2;
        continue;
      }
      ++pos_;
      terminated = true;
      break;
    }
    // Strings cannot span lines: stopping at the line end keeps one missing quote from
    // swallowing the rest of the file.
    if (c == '\n' || c == '\r') break;
    if (c != '$') {
      value += c;
      ++pos_;
      continue;
    }
    const char e = peek(1);
    const char u = upper(e);
    if (e == '$' || e == '\'' || e == '"') {
      value += e;
      pos_ += 2;
    } else if (u == 'L' || u == 'N') {
      value += '\n';
      pos_ += 2;
    } else if (u == 'P') {
      value += '\f';
      pos_ += 2;
    } else if (u == 'R') {
      value += '\r';
      pos_ += 2;
    } else if (u == 'T') {
      value += '\t';
      pos_ += 2;
    } else if (hex_value(e) >= 0 && hex_value(peek(2)) >= 0) {
      if (quote == '"' && hex_value(peek(3)) >= 0 && hex_value(peek(4)) >= 0) {
        // WSTRING: $hhhh is one UTF-16 code unit; store it as UTF-8.
        const unsigned cp = static_cast<unsigned>(hex_value(e) << 12 | hex_value(peek(2)) << 8 |
                                                  hex_value(peek(3)) << 4 | hex_value(peek(4)));
        if (cp < 0x80) {
          value += static_cast<char>(cp);
        } else if (cp < 0x800) {
          value += static_cast<char>(0xC0 | (cp >> 6));
          value += static_cast<char>(0x80 | (cp & 0x3F));
        } else {
          value += static_cast<char>(0xE0 | (cp >> 12));
          value += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
          value += static_cast<char>(0x80 | (cp & 0x3F));
        }
        pos_ += 5;
      } else {
        value += static_cast<char>(hex_value(e) * 16 + hex_value(peek(2)));
        pos_ += 3;
      }
    } else {
      const std::string shown = (e == '\0' || e == '\n' || e == '\r') ? std::string("$") : std::string("$") + e;
      error("ST004", pos_, "invalid escape sequence '" + shown +
                               "' in string (use $$, $', $\", $L, $N, $P, $R, $T or $hh)");
      bad = true;
      pos_ += (e == '\0' || e == '\n' || e == '\r') ? 1 : 2;
    }
  }
  Token tok = make(quote == '\'' ? Tok::StringLit : Tok::WStringLit, begin);
  tok.lit = quote == '\'' ? LiteralKind::String : LiteralKind::WString;
  tok.str_value = std::move(value);
  if (!terminated) {
    error("ST003", begin, std::string("unterminated string literal: missing closing quote (") + quote +
                              ") before the end of the line");
    bad = true;
  }
  tok.bad = bad;
  return tok;
}

Token Lexer::lex_direct_address() {
  const size_t begin = pos_;
  ++pos_;
  while (pos_ < text_.size() && (is_ident_char(text_[pos_]) || text_[pos_] == '*' ||
                                 (text_[pos_] == '.' && is_digit(peek(1)))))
    ++pos_;
  Token tok = make(Tok::DirectAddr, begin);
  const std::string written(tok.text);
  auto fail = [&](size_t at, const std::string& why) {
    error("ST010", at, "invalid direct address '" + written + "': " + why);
    tok.bad = true;
    return tok;
  };
  size_t p = begin + 1;
  const char area = upper(p < pos_ ? text_[p] : '\0');
  if (area != 'I' && area != 'Q' && area != 'M')
    return fail(begin, "the location prefix must be I, Q or M");
  tok.area = area;
  ++p;
  if (p < pos_ && std::isalpha(static_cast<unsigned char>(text_[p]))) {
    const char size = upper(text_[p]);
    if (size != 'X' && size != 'B' && size != 'W' && size != 'D' && size != 'L')
      return fail(p, std::string("unknown size '") + text_[p] + "' (expected X, B, W, D or L)");
    tok.size = size;
    ++p;
  }
  if (p < pos_ && text_[p] == '*') {
    // Partly specified address (x AT %I* : BOOL), completed by VAR_CONFIG.
    if (p + 1 != pos_) return fail(p, "'*' must end the address");
    return tok;
  }
  if (p >= pos_) return fail(pos_, "missing address number after '" + written + "'");
  while (p < pos_) {
    if (!is_digit(text_[p])) return fail(p, std::string("unexpected '") + text_[p] + "' in address");
    uint64_t v = 0;
    while (p < pos_ && is_digit(text_[p])) {
      v = v * 10 + static_cast<uint64_t>(text_[p] - '0');
      if (v > UINT32_MAX) return fail(begin, "address part too large");
      ++p;
    }
    tok.parts.push_back(static_cast<uint32_t>(v));
    if (p < pos_) {
      if (text_[p] != '.') return fail(p, std::string("unexpected '") + text_[p] + "' in address");
      ++p;
    }
  }
  return tok;
}

// pos_ is at the '#' after a time prefix (T, TIME, D, TOD, DT, their long forms, ...).
Token Lexer::lex_time_literal(size_t begin, std::string_view prefix) {
  bool is_long = false;
  const TimePrefix kind = classify_prefix(prefix, &is_long);
  ++pos_;  // '#'
  bool ok = true;
  std::string why;
  size_t why_at = pos_;
  auto fail = [&](size_t at, std::string message) {
    if (ok) {
      ok = false;
      why_at = at;
      why = std::move(message);
    }
    return false;
  };
  // Reads up to max_digits decimal digits ('_' allowed between them); false when none.
  auto read_uint = [&](uint64_t* v, size_t* ndigits) {
    *v = 0;
    *ndigits = 0;
    while (pos_ < text_.size() && (is_digit(text_[pos_]) || (text_[pos_] == '_' && *ndigits > 0 && is_digit(peek(1))))) {
      if (text_[pos_] != '_') {
        if (*v > UINT64_MAX / 10 - 9) return fail(pos_, "number too large");
        *v = *v * 10 + static_cast<uint64_t>(text_[pos_] - '0');
        ++*ndigits;
      }
      ++pos_;
    }
    return *ndigits > 0;
  };
  // Nanoseconds of a decimal fraction (digits after the '.') of `unit` nanoseconds.
  auto read_fraction = [&](int64_t unit) {
    int64_t ns = 0;
    int64_t place = unit;
    while (pos_ < text_.size() && (is_digit(text_[pos_]) || text_[pos_] == '_')) {
      if (text_[pos_] != '_') {
        place /= 10;
        ns += place * (text_[pos_] - '0');
      }
      ++pos_;
    }
    return ns;
  };
  auto expect_char = [&](char c, const char* what) {
    if (peek() == c) {
      ++pos_;
      return true;
    }
    return fail(pos_, std::string("expected '") + c + "' " + what);
  };
  // YYYY-MM-DD -> days since 1970-01-01.
  auto read_date = [&](int64_t* days) {
    uint64_t y = 0, m = 0, d = 0;
    size_t n = 0;
    const size_t at = pos_;
    if (!read_uint(&y, &n) || n != 4) return fail(at, "expected a date as YYYY-MM-DD");
    if (!expect_char('-', "after the year (YYYY-MM-DD)")) return false;
    if (!read_uint(&m, &n) || n > 2) return fail(pos_, "expected a month (YYYY-MM-DD)");
    if (!expect_char('-', "after the month (YYYY-MM-DD)")) return false;
    if (!read_uint(&d, &n) || n > 2) return fail(pos_, "expected a day (YYYY-MM-DD)");
    if (m < 1 || m > 12) return fail(at, "month " + std::to_string(m) + " is not in 1..12");
    const unsigned dim = days_in_month(static_cast<int64_t>(y), static_cast<unsigned>(m));
    if (d < 1 || d > dim)
      return fail(at, "day " + std::to_string(d) + " is not in 1.." + std::to_string(dim) + " for month " +
                          std::to_string(m));
    *days = days_from_civil(static_cast<int64_t>(y), static_cast<unsigned>(m), static_cast<unsigned>(d));
    return true;
  };
  // hh:mm[:ss[.fff]] -> ns since midnight.
  auto read_tod = [&](int64_t* ns) {
    uint64_t h = 0, m = 0, s = 0;
    size_t n = 0;
    const size_t at = pos_;
    if (!read_uint(&h, &n) || n > 2) return fail(at, "expected a time of day as hh:mm:ss");
    if (!expect_char(':', "after the hour (hh:mm:ss)")) return false;
    if (!read_uint(&m, &n) || n > 2) return fail(pos_, "expected minutes (hh:mm:ss)");
    int64_t frac = 0;
    if (peek() == ':') {
      ++pos_;
      if (!read_uint(&s, &n) || n > 2) return fail(pos_, "expected seconds (hh:mm:ss)");
      if (peek() == '.' && is_digit(peek(1))) {
        ++pos_;
        frac = read_fraction(kNsPerSec);
      }
    }
    if (h > 23) return fail(at, "hour " + std::to_string(h) + " is not in 0..23");
    if (m > 59) return fail(at, "minute " + std::to_string(m) + " is not in 0..59");
    if (s > 59) return fail(at, "second " + std::to_string(s) + " is not in 0..59");
    *ns = static_cast<int64_t>((h * 3600 + m * 60 + s)) * kNsPerSec + frac;
    return true;
  };

  int64_t value = 0;
  bool beyond_signed = false;  // an LTIME# above INT64_MAX (value holds its bits)
  LiteralKind lit = LiteralKind::Time;
  // Nanoseconds since the epoch in 64 bits reach from 1677 to 2262.
  auto date_ns = [&](int64_t days, int64_t tod) {
    if (__builtin_mul_overflow(days, kNsPerDay, &value) || __builtin_add_overflow(value, tod, &value))
      return fail(begin, "date out of range (representable: 1677-09-22 to 2262-04-11)");
    return true;
  };
  if (kind == TimePrefix::Duration) {
    // The literal's extent: a sign, then letters, digits, '_' and '.' (a TIME has no
    // subranges, so no '..' can follow); its value is the shared parser's, so T#8.2ms here
    // and "8.2ms" in a spec file are the same nanoseconds, and a malformed literal is one
    // token with the parser's message.
    size_t end = pos_;
    if (end < text_.size() && (text_[end] == '-' || text_[end] == '+')) ++end;
    while (end < text_.size() && (is_ident_char(text_[end]) || text_[end] == '.')) ++end;
    // LTIME# reads up to 2^64 - 1 ns (CODESYS's unsigned LTIME); the compiler decides
    // whether the dialect has such values.
    const std::string_view body = text_.substr(pos_, end - pos_);
    const common::DurationParse d = is_long ? common::parse_unsigned_duration_body(body) : common::parse_duration_body(body);
    if (d.ok()) value = d.ns;
    else fail(pos_ + d.error_at, d.error);
    beyond_signed = d.ok() && d.beyond_signed;
    pos_ = end;
    lit = LiteralKind::Time;
  } else if (kind == TimePrefix::Date) {
    int64_t days = 0;
    if (read_date(&days)) date_ns(days, 0);
    lit = LiteralKind::Date;
  } else if (kind == TimePrefix::TimeOfDay) {
    read_tod(&value);
    lit = LiteralKind::TimeOfDay;
  } else {
    int64_t days = 0, tod = 0;
    if (read_date(&days) && expect_char('-', "between date and time (YYYY-MM-DD-hh:mm:ss)") && read_tod(&tod))
      date_ns(days, tod);
    lit = LiteralKind::DateTime;
  }
  if (ok && pos_ < text_.size() && (is_ident_char(text_[pos_]) || text_[pos_] == '.' || text_[pos_] == ':'))
    fail(pos_, std::string("unexpected '") + text_[pos_] + "'");
  if (!ok) {
    // Swallow the rest of the malformed literal so the parser does not see its pieces.
    while (pos_ < text_.size() && (is_ident_char(text_[pos_]) || text_[pos_] == '.' || text_[pos_] == ':' ||
                                   (text_[pos_] == '-' && is_digit(peek(1)))))
      ++pos_;
  }
  Token tok = make(Tok::TimeLit, begin);
  tok.lit = lit;
  tok.time_ns = ok ? value : 0;
  tok.is_long = is_long;
  tok.beyond_signed = ok && beyond_signed;
  tok.prefix = prefix;
  if (!ok) {
    const bool duration = kind == TimePrefix::Duration;
    error(duration ? "ST008" : "ST009", why_at, std::string(tok.text) + ": " + why);
    tok.bad = true;
  }
  return tok;
}

std::vector<Token> lex_file(const SourceManager& sm, uint32_t file, DiagEngine& diags) {
  Lexer lexer(sm, file, diags);
  std::vector<Token> out;
  for (;;) {
    out.push_back(lexer.next());
    if (out.back().kind == Tok::Eof) break;
  }
  return out;
}

}  // namespace plcfi::st
