// Reader of CPTest+ scripts: a small line-oriented scanner, one error per bad line.
#include "script/cpt.hpp"

#include <cctype>
#include <limits>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "common/file.hpp"

namespace plcfi::script {

namespace {

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

// One line under the scanner: words separated by blanks, each with its column.
class Line {
 public:
  Line(std::string_view text, uint32_t line_no) : s_(text), line_(line_no) {}

  void skip_blanks() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t')) ++i_;
  }
  bool at_end() {
    skip_blanks();
    return i_ >= s_.size();
  }
  Pos pos() const { return Pos{line_, static_cast<uint32_t>(i_ + 1)}; }
  // The next blank-separated word (empty at the end of the line).
  std::string_view word(Pos* at) {
    skip_blanks();
    *at = pos();
    size_t b = i_;
    while (i_ < s_.size() && s_[i_] != ' ' && s_[i_] != '\t') ++i_;
    return s_.substr(b, i_ - b);
  }
  // The rest of the line, trailing blanks removed.
  std::string_view rest(Pos* at) {
    skip_blanks();
    *at = pos();
    std::string_view r = s_.substr(i_);
    while (!r.empty() && (r.back() == ' ' || r.back() == '\t')) r.remove_suffix(1);
    i_ = s_.size();
    return r;
  }
  size_t index() const { return i_; }
  void set_index(size_t i) { i_ = i; }

 private:
  std::string_view s_;
  size_t i_ = 0;
  uint32_t line_;
};

struct Failure {
  Pos at;
  std::string message;
};

bool parse_count(std::string_view w, int64_t* out) {
  if (w.empty() || w.size() > 18) return false;
  int64_t v = 0;
  for (char c : w) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  *out = v;
  return true;
}

// Where a `//` comment starts outside a string literal, or npos.
size_t comment_start(std::string_view s) {
  char quote = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    char c = s[i];
    if (quote) {
      if (c == '$' && i + 1 < s.size()) ++i;  // ST escape ($', $$)
      else if (c == quote) quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '/' && i + 1 < s.size() && s[i + 1] == '/') {
      return i;
    }
  }
  return std::string_view::npos;
}

bool parse_op(std::string_view w, CmpOp* op) {
  static const std::pair<const char*, CmpOp> kOps[] = {
      {"EQ", CmpOp::Eq},   {"NEQ", CmpOp::Neq}, {"LT", CmpOp::Lt},         {"LTE", CmpOp::Lte},
      {"GT", CmpOp::Gt},   {"GTE", CmpOp::Gte}, {"ISTRUE", CmpOp::IsTrue}, {"ISFALSE", CmpOp::IsFalse},
  };
  std::string u = upper(w);
  for (auto [n, o] : kOps)
    if (u == n) {
      *op = o;
      return true;
    }
  return false;
}

// A variable path: a name with dots and [index] parts, or a direct address (%IX0.1).
bool plausible_var(std::string_view w) {
  if (w.empty()) return false;
  char c = w[0];
  return c == '%' || c == '_' || std::isalpha(static_cast<unsigned char>(c));
}

// The amount and unit of WAIT n MS|S|C or FOR n MS|S.
std::optional<Failure> amount_and_unit(Line& ln, Command& c, bool cycles_ok, const char* what) {
  Pos at;
  std::string_view n = ln.word(&at);
  if (n.empty()) return Failure{at, fmt::format("{} needs a number and a unit (MS, S{})", what, cycles_ok ? " or C" : "")};
  if (!parse_count(n, &c.amount))
    return Failure{at, fmt::format("{}: '{}' is not a whole number of {}", what, n, cycles_ok ? "milliseconds, seconds or cycles" : "milliseconds or seconds")};
  std::string_view u = ln.word(&at);
  std::string uu = upper(u);
  if (uu == "MS") c.unit = WaitUnit::Ms;
  else if (uu == "S") c.unit = WaitUnit::S;
  else if (uu == "C" && cycles_ok) c.unit = WaitUnit::Cycles;
  else if (u.empty()) return Failure{at, fmt::format("{} {}: the unit is missing (MS, S{})", what, n, cycles_ok ? " or C" : "")};
  else return Failure{at, fmt::format("{}: unknown unit '{}' (expected MS, S{})", what, u, cycles_ok ? " or C" : "")};
  if (c.unit != WaitUnit::Cycles && duration_ns(c.amount, c.unit) < 0)
    return Failure{at, fmt::format("{} {} {}: too long", what, n, u)};
  return std::nullopt;
}

std::optional<Failure> parse_line(std::string_view raw, uint32_t line_no, Command& c, bool* empty) {
  Line ln(raw, line_no);
  *empty = false;
  if (ln.at_end()) {
    *empty = true;
    return std::nullopt;
  }
  // An optional line number: digits and a colon.
  {
    size_t save = ln.index();
    Pos at;
    std::string_view w = ln.word(&at);
    size_t colon = w.find(':');
    int64_t n = 0;
    if (colon != std::string_view::npos && colon > 0 && parse_count(w.substr(0, colon), &n)) {
      c.number = std::string(w.substr(0, colon));
      ln.set_index(static_cast<size_t>(w.data() - raw.data()) + colon + 1);
    } else {
      ln.set_index(save);
    }
  }
  if (ln.at_end()) {
    *empty = true;  // a numbered blank line
    return std::nullopt;
  }
  Pos at;
  std::string_view kw = ln.word(&at);
  if (kw.substr(0, 2) == "//") {
    *empty = true;  // a comment line
    return std::nullopt;
  }
  c.at = at;
  std::string k = upper(kw);
  size_t text_from = at.col - 1;
  auto finish = [&]() -> std::optional<Failure> {
    c.text = std::string(raw.substr(text_from));
    while (!c.text.empty() && (c.text.back() == ' ' || c.text.back() == '\t')) c.text.pop_back();
    return std::nullopt;
  };
  auto need_var = [&](const char* what) -> std::optional<Failure> {
    Pos vat;
    std::string_view v = ln.word(&vat);
    if (v.empty()) return Failure{vat, fmt::format("{} needs a variable", what)};
    if (!plausible_var(v)) return Failure{vat, fmt::format("{}: '{}' is not a variable name", what, v)};
    c.var = std::string(v);
    c.var_at = vat;
    return std::nullopt;
  };
  auto no_more = [&](const char* what) -> std::optional<Failure> {
    if (!ln.at_end()) {
      Pos xat = ln.pos();
      std::string_view extra = ln.rest(&xat);
      return Failure{xat, fmt::format("{}: unexpected '{}' at the end of the line", what, extra)};
    }
    return std::nullopt;
  };
  if (k == "LOG") {
    c.kind = CmdKind::Log;
    Pos mat;
    c.message = std::string(ln.rest(&mat));
    return finish();
  }
  // Everything else may carry a comment.
  std::string_view body = raw;
  if (size_t cs = comment_start(raw); cs != std::string_view::npos) body = raw.substr(0, cs);
  Line rest(body, line_no);
  rest.set_index(ln.index());
  ln = rest;
  if (k == "SET" || k == "RESET") {
    c.kind = k == "SET" ? CmdKind::Set : CmdKind::Reset;
    if (auto f = need_var(k.c_str())) return f;
    if (auto f = no_more(k.c_str())) return f;
  } else if (k == "ASSIGN") {
    c.kind = CmdKind::Assign;
    if (auto f = need_var("ASSIGN")) return f;
    Pos vat;
    std::string_view v = ln.rest(&vat);
    if (v.empty()) return Failure{vat, "ASSIGN " + c.var + " needs a value"};
    c.has_value = true;
    c.value = std::string(v);
    c.value_at = vat;
  } else if (k == "WAIT") {
    c.kind = CmdKind::Wait;
    if (auto f = amount_and_unit(ln, c, true, "WAIT")) return f;
    if (auto f = no_more("WAIT")) return f;
  } else if (k == "ASSERT" || k == "ASSERT_COM") {
    c.kind = k == "ASSERT" ? CmdKind::Assert : CmdKind::AssertCom;
    Pos oat;
    std::string_view o = ln.word(&oat);
    if (o.empty()) return Failure{oat, k + " needs an operator (EQ, NEQ, LT, LTE, GT, GTE, ISTRUE, ISFALSE)"};
    if (!parse_op(o, &c.op))
      return Failure{oat, fmt::format("{}: unknown operator '{}' (expected EQ, NEQ, LT, LTE, GT, GTE, ISTRUE or ISFALSE)", k, o)};
    if (auto f = need_var(k.c_str())) return f;
    if (op_takes_value(c.op)) {
      Pos vat;
      std::string_view v = ln.rest(&vat);
      if (v.empty()) return Failure{vat, fmt::format("{} {} {} needs a value to compare with", k, op_name(c.op), c.var)};
      c.has_value = true;
      c.value = std::string(v);
      c.value_at = vat;
    } else if (auto f = no_more(fmt::format("{} {}", k, op_name(c.op)).c_str())) {
      return f;
    }
  } else if (k == "FAULT") {
    c.kind = CmdKind::FaultLink;
    Pos fat;
    std::string_view what = ln.word(&fat);
    if (upper(what) != "LINK")
      return Failure{fat, what.empty() ? std::string("FAULT needs a kind: FAULT LINK device FOR n MS")
                                       : fmt::format("FAULT: unknown kind '{}' (expected LINK)", what)};
    Pos dat;
    std::string_view dev = ln.word(&dat);
    if (dev.empty()) return Failure{dat, "FAULT LINK needs a device (offline: plant)"};
    c.device = std::string(dev);
    c.device_at = dat;
    Pos forat;
    std::string_view f = ln.word(&forat);
    if (upper(f) != "FOR") return Failure{forat, "FAULT LINK " + c.device + ": expected FOR n MS"};
    if (auto e = amount_and_unit(ln, c, false, "FAULT LINK")) return e;
    if (c.amount == 0) return Failure{forat, "FAULT LINK " + c.device + ": the duration must be more than 0"};
    if (auto e = no_more("FAULT LINK")) return e;
  } else {
    return Failure{at, fmt::format("unknown command '{}' (expected SET, RESET, ASSIGN, WAIT, LOG, ASSERT, ASSERT_COM or FAULT)", kw)};
  }
  // The text as written: from the command word to the comment.
  c.text = std::string(body.substr(text_from));
  while (!c.text.empty() && (c.text.back() == ' ' || c.text.back() == '\t')) c.text.pop_back();
  return std::nullopt;
}

}  // namespace

const char* op_name(CmpOp op) {
  switch (op) {
    case CmpOp::Eq: return "EQ";
    case CmpOp::Neq: return "NEQ";
    case CmpOp::Lt: return "LT";
    case CmpOp::Lte: return "LTE";
    case CmpOp::Gt: return "GT";
    case CmpOp::Gte: return "GTE";
    case CmpOp::IsTrue: return "ISTRUE";
    case CmpOp::IsFalse: return "ISFALSE";
  }
  return "?";
}

bool op_takes_value(CmpOp op) { return op != CmpOp::IsTrue && op != CmpOp::IsFalse; }

const char* unit_name(WaitUnit u) {
  switch (u) {
    case WaitUnit::Ms: return "MS";
    case WaitUnit::S: return "S";
    case WaitUnit::Cycles: return "C";
  }
  return "?";
}

int64_t duration_ns(int64_t amount, WaitUnit u) {
  const int64_t scale = u == WaitUnit::S ? 1'000'000'000 : 1'000'000;
  if (u == WaitUnit::Cycles || amount < 0 || amount > std::numeric_limits<int64_t>::max() / scale) return -1;
  return amount * scale;
}

bool parse_script(const std::string& path, const std::string& text, Script* out, std::string* err) {
  Script s;
  s.path = path;
  std::string_view base = path;
  if (size_t slash = base.find_last_of('/'); slash != std::string_view::npos) base = base.substr(slash + 1);
  if (base.size() > 4 && upper(base.substr(base.size() - 4)) == ".CPT") base = base.substr(0, base.size() - 4);
  s.name = std::string(base);
  uint32_t line_no = 0;
  size_t b = 0;
  while (b <= text.size()) {
    size_t e = text.find('\n', b);
    if (e == std::string::npos) e = text.size();
    std::string_view line(text.data() + b, e - b);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++line_no;
    if (line.find('\0') != std::string_view::npos) {
      *err = fmt::format("{}:{}:{}: a NUL byte in the script (a binary file?)", path, line_no, line.find('\0') + 1);
      return false;
    }
    Command c;
    bool empty = false;
    if (auto f = parse_line(line, line_no, c, &empty)) {
      *err = fmt::format("{}:{}:{}: {}", path, f->at.line, f->at.col, f->message);
      return false;
    }
    if (!empty) s.commands.push_back(std::move(c));
    if (e == text.size()) break;
    b = e + 1;
  }
  *out = std::move(s);
  return true;
}

bool load_script(const std::string& path, Script* out, std::string* err) {
  std::string text;
  if (!common::read_file(path, common::kMaxSpecBytes, &text, err)) return false;
  return parse_script(path, text, out, err);
}

}  // namespace plcfi::script
