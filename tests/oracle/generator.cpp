// Random well-typed ST programs: FUNCTIONs, FBs with METHODs and PROPERTYs, an INTERFACE
// implemented by two FBs, a PROGRAM with scalars of many types, arrays, structures and
// globals; expressions nest calls of every kind in arguments of every kind.
#include "generator.hpp"

#include <cctype>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <vector>

namespace plcfi::oracle {
namespace {

enum class T { Bool, Sint, Int, Dint, Lint, Usint, Uint, Udint, Byte, Word, Dword, Real, LReal, Time, Str };

const char* name(T t) {
  static const char* kNames[] = {"BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT",
                                 "BYTE", "WORD", "DWORD", "REAL", "LREAL", "TIME", "STRING"};
  return kNames[static_cast<int>(t)];
}
bool is_int(T t) { return t >= T::Sint && t <= T::Udint; }
bool is_signed(T t) { return t >= T::Sint && t <= T::Lint; }
bool is_bits(T t) { return t >= T::Byte && t <= T::Dword; }
bool is_real(T t) { return t == T::Real || t == T::LReal; }
int width(T t) {
  switch (t) {
    case T::Sint: case T::Usint: case T::Byte: return 8;
    case T::Int: case T::Uint: case T::Word: return 16;
    case T::Dint: case T::Udint: case T::Dword: return 32;
    default: return 64;
  }
}
// True when an expression's text has no variable, property or user call in it: the
// compiler folds such an expression and rejects one that overflows (ST216), so no
// arithmetic node may have two constant operands. Places and user calls all contain a
// lower-case letter, THIS or `F<digit>(`; string and TIME literals are skipped.
bool is_const(const std::string& e) {
  for (size_t i = 0; i < e.size(); ++i) {
    char c = e[i];
    if (c == '\'') {
      i = e.find('\'', i + 1);
      continue;
    }
    if (c == 'T' && i + 1 < e.size() && e[i + 1] == '#' && (i == 0 || !std::isalnum(static_cast<unsigned char>(e[i - 1])))) {
      i += 2;
      while (i < e.size() && std::isalnum(static_cast<unsigned char>(e[i]))) ++i;
      --i;
      continue;
    }
    if (c >= 'a' && c <= 'z') return false;
    if (e.compare(i, 4, "THIS") == 0) return false;
    if (c == 'F' && i + 1 < e.size() && std::isdigit(static_cast<unsigned char>(e[i + 1])) &&
        (i == 0 || !std::isalnum(static_cast<unsigned char>(e[i - 1]))))
      return false;
  }
  return true;
}

// An integer type that converts implicitly to t (IEC widening), or t itself when none.
T narrower(T t, int r) {
  static const T kSigned[] = {T::Sint, T::Int, T::Dint, T::Lint};
  static const T kUnsigned[] = {T::Usint, T::Uint, T::Udint};
  std::vector<T> ok;
  for (T u : kSigned)
    if (is_signed(t) && width(u) < width(t)) ok.push_back(u);
  for (T u : kUnsigned)
    if (width(u) < width(t) && (is_signed(t) || !is_signed(u))) ok.push_back(u);
  return ok.empty() ? t : ok[static_cast<size_t>(r) % ok.size()];
}

const T kScalars[] = {T::Bool, T::Sint, T::Int, T::Dint, T::Lint, T::Usint, T::Uint, T::Udint,
                      T::Byte, T::Word, T::Dword, T::Real, T::LReal, T::Time, T::Str};

// A readable (and maybe writable) place of a scalar type: `x`, `THIS^.x`, `a[i]`, `r.f`,
// `recs[i].f`, `fb.out0`. Array places carry their bounds; the index is generated.
struct Place {
  std::string base;   // text before the index (or the whole place)
  std::string after;  // text after the index (".f" for arrays of structures)
  T t = T::Dint;
  bool writable = true;
  bool indexed = false;
  int lo = 0, hi = 0;
  bool bit = false;  // `w.3`: no address (VAR_IN_OUT) can be taken
};

// Something callable that yields a value: a FUNCTION, a method, a property getter, an
// interface method. `prefix` is the callee text (`F1`, `fa.M0`, `THIS^.M1`, `itf.Calc`).
struct Callable {
  std::string prefix;
  T ret = T::Dint;
  std::vector<std::pair<std::string, T>> params;  // empty and is_property: `fa.P0`
  bool is_method = false;
  bool is_property = false;
  bool itf_param = false;  // the first parameter is an IGen: an instance or itf is passed
};

struct Scope {
  std::vector<Place> places;
  std::vector<Callable> calls;
  std::vector<std::pair<std::string, int>> insts;  // FB instances statements may call, and their FB index
  bool fb_statements = false;  // Main: the interface may be reassigned, structures copied
};

struct FbInfo {
  std::string type;
  std::vector<std::pair<std::string, T>> inputs, outputs;
  std::vector<Callable> methods;   // pure: callable in expressions (prefix without the instance)
  std::vector<Callable> props;     // with a setter
  std::vector<std::pair<std::string, T>> step_params;
  T step_output = T::Dint;  // Step's VAR_OUTPUT q
  bool has_calc = false;
  bool derived = false;  // EXTENDS another FB and has no body: never called as an FB
  std::vector<std::pair<std::string, T>> state;
};

class Gen {
 public:
  Gen(uint64_t seed, const GenOptions& o) : rng_(seed), opt_(o) {}
  std::string program();

 private:
  int pick(int n) { return static_cast<int>(rng_() % static_cast<uint64_t>(n)); }
  bool chance(int percent) { return pick(100) < percent; }
  T any_scalar() { return kScalars[pick(sizeof kScalars / sizeof kScalars[0])]; }
  T any_num() {
    static const T k[] = {T::Sint, T::Int, T::Dint, T::Lint, T::Usint, T::Uint, T::Udint, T::Real, T::LReal};
    return k[pick(9)];
  }
  std::string type_text(T t) { return t == T::Str ? "STRING[" + std::to_string(str_len_) + "]" : name(t); }

  std::string literal(T t);
  std::string small_literal(T t);
  std::string leaf(T t, const Scope& s);
  std::string variable(T t, const Scope& s);
  std::string place_text(const Place& p, const Scope& s, int depth);
  std::string expr(T t, const Scope& s, int depth);
  std::string call_text(const Callable& c, const Scope& s, int depth);
  std::string date_literal();  // D#, TOD# and DT# with random fields
  std::string tod_literal();
  std::string dt_literal();
  static std::string two(int v) { return (v < 10 ? "0" : "") + std::to_string(v); }
  std::string stmt(const Scope& s, int depth);
  std::string stmts(const Scope& s, int n, int depth, const std::string& sep = " ");
  std::string assign(const Place& p, const Scope& s, int depth);
  std::string pou_vars(const std::string& section, const std::vector<std::pair<std::string, T>>& v);
  void function(int k);
  void fb(int k, bool implements, int inner);
  void derived_fb(int k, const FbInfo& base);

  std::mt19937_64 rng_;
  GenOptions opt_;
  std::ostringstream out_;
  std::vector<Callable> functions_;
  std::vector<FbInfo> fbs_;
  int str_len_ = 12;
  int loops_ = 0;
  std::vector<std::pair<std::string, std::vector<Place>>> refs_;  // Main's references and their targets
  T fio_type_ = T::Dint;                          // FIO's parameters and result
  std::vector<std::string> fio_order_;             // FIO's parameters in declaration order
  std::vector<std::pair<std::string, T>> globals_;  // read everywhere, written by FB bodies, Step and Main
  std::vector<std::string> loop_vars_;   // FOR control variables not in use by an outer loop
  std::vector<std::string> while_vars_;  // WHILE/REPEAT counters not in use
};

std::string Gen::literal(T t) {
  switch (t) {
    case T::Bool: return chance(50) ? "TRUE" : "FALSE";
    case T::Real:
    case T::LReal: {
      int v = pick(4001) - 2000;
      std::string s = std::to_string(v / 4) + "." + std::to_string((v < 0 ? -v : v) % 4 * 25);
      if (v < 0 && v / 4 == 0) s = "-" + s;
      if (s[0] == '-') return "(-" + std::string(name(t)) + "#" + s.substr(1) + ")";
      return std::string(name(t)) + "#" + s;
    }
    case T::Time: return "T#" + std::to_string(pick(5000)) + "ms";
    case T::Str: {
      static const char* kWords[] = {"", "a", "ab", "abc", "xyz", "Hello", "plc", "q1w2", "ZZ", "k"};
      return "'" + std::string(kWords[pick(10)]) + "'";
    }
    default: {
      int w = width(t);
      uint64_t max = is_signed(t) ? (uint64_t{1} << (w - 1)) - 1 : (w == 64 ? ~uint64_t{0} : (uint64_t{1} << w) - 1);
      uint64_t v;
      int r = pick(10);
      if (r == 0) v = max;  // wraparound at the type's limit
      else if (r == 1) v = max / 2 + 3;
      else v = static_cast<uint64_t>(pick(w == 8 ? 100 : 1000));
      std::string lit = std::string(name(t)) + "#" + std::to_string(v);
      if (is_signed(t) && chance(30)) return "(-" + lit + ")";
      return lit;
    }
  }
}

// A literal far from the type's limits: bounds of LIMIT, where overflow must not reorder them.
std::string Gen::small_literal(T t) {
  int v = pick(50);
  if (t == T::Time) return "T#" + std::to_string(v) + "ms";
  if (is_real(t)) return std::string(name(t)) + "#" + std::to_string(v) + ".0";
  return std::string(name(t)) + "#" + std::to_string(v);
}

std::string Gen::place_text(const Place& p, const Scope& s, int depth) {
  if (!p.indexed) return p.base;
  std::string i = depth > 0 ? expr(T::Dint, s, depth - 1) : literal(T::Dint);
  return p.base + "[LIMIT(DINT#" + std::to_string(p.lo) + ", " + i + ", DINT#" + std::to_string(p.hi) + ")]" + p.after;
}

// A place of type t (index constant), or "" when the scope has none.
std::string Gen::variable(T t, const Scope& s) {
  std::vector<const Place*> ok;
  for (const auto& p : s.places)
    if (p.t == t) ok.push_back(&p);
  if (ok.empty()) return "";
  return place_text(*ok[pick(static_cast<int>(ok.size()))], s, 0);
}

std::string Gen::leaf(T t, const Scope& s) {
  std::vector<const Place*> ok;
  for (const auto& p : s.places)
    if (p.t == t) ok.push_back(&p);
  if (ok.empty() || chance(25)) return literal(t);
  return place_text(*ok[pick(static_cast<int>(ok.size()))], s, 0);
}

std::string Gen::date_literal() {
  return "D#" + std::to_string(1970 + pick(130)) + "-" + two(1 + pick(12)) + "-" + two(1 + pick(28));
}
std::string Gen::tod_literal() {
  return "TOD#" + two(pick(24)) + ":" + two(pick(60)) + ":" + two(pick(60)) + "." + std::to_string(100 + pick(900));
}
std::string Gen::dt_literal() {
  std::string d = date_literal();
  return "DT#" + d.substr(2) + "-" + two(pick(24)) + ":" + two(pick(60)) + ":" + two(pick(60));
}

std::string Gen::call_text(const Callable& c, const Scope& s, int depth) {
  std::string callee = c.prefix;
  // `fbs[?].M0`: a method of an element of an array of instances, index computed here.
  if (auto at = callee.find("[?]"); at != std::string::npos)
    callee.replace(at, 3, "[LIMIT(DINT#1, " + expr(T::Dint, s, depth - 1) + ", DINT#2)]");
  if (c.is_property) return callee;
  std::string text = callee + "(";
  bool named = c.is_method || chance(60);
  for (size_t i = 0; i < c.params.size(); ++i) {
    if (i) text += ", ";
    if (named) text += c.params[i].first + " := ";
    if (i == 0 && c.itf_param) {
      static const char* kItf[] = {"ia", "ib", "id", "itf"};
      text += kItf[pick(4)];
      continue;
    }
    bool plain = c.is_method && opt_.avoid_method_args_with_calls;
    T pt = c.params[i].second;
    if (is_int(pt) && chance(15)) pt = narrower(pt, pick(8));  // widened by the call
    text += plain ? leaf(pt, s) : expr(pt, s, depth - 1);
  }
  return text + ")";
}

std::string Gen::expr(T t, const Scope& s, int depth) {
  if (depth <= 0 || chance(20)) return leaf(t, s);
  auto sub = [&](T u) { return expr(u, s, depth - 1); };
  // Two operands of an arithmetic operator, not both constant.
  auto operands = [&](T u) {
    std::pair<std::string, std::string> p{sub(u), sub(u)};
    if (is_const(p.first) && is_const(p.second)) {
      std::string v = variable(u, s);
      if (v.empty()) return std::pair<std::string, std::string>{};
      p.second = v;
    }
    return p;
  };
  auto arith = [&](T u, const std::string& op) {
    auto [a, b] = operands(u);
    if (a.empty()) return sub(u);
    return "(" + a + op + b + ")";
  };
  std::vector<std::function<std::string()>> alts;
  // Calls returning t: FUNCTIONs, methods, properties, interface methods.
  for (const auto& c : s.calls)
    if (c.ret == t) {
      alts.push_back([&, c] { return call_text(c, s, depth); });
      alts.push_back([&, c] { return call_text(c, s, depth); });
    }
  alts.push_back([&] { return "SEL(" + sub(T::Bool) + ", " + sub(t) + ", " + sub(t) + ")"; });
  if (t != T::Bool && t != T::Str) {
    alts.push_back([&] { return "MUX(LIMIT(DINT#0, " + sub(T::Dint) + ", DINT#2), " + sub(t) + ", " + sub(t) + ", " + sub(t) + ")"; });
  }
  if (is_int(t) || is_real(t) || t == T::Time) {
    alts.push_back([&] { return std::string(chance(50) ? "MIN(" : "MAX(") + sub(t) + ", " + sub(t) + ")"; });
    alts.push_back([&] {
      std::string a = small_literal(t);
      // Constant bounds in order: LIMIT with MN > MX is the implementation's business.
      return "LIMIT(" + a + ", " + sub(t) + ", " + a + " + " + (t == T::Time ? "T#100ms" : is_real(t) ? std::string(name(t)) + "#50.0" : std::string(name(t)) + "#50") + ")";
    });
    alts.push_back([&] { return arith(t, " + "); });
    alts.push_back([&] { return arith(t, " - "); });
  }
  if (is_int(t)) {
    std::string n = name(t);
    alts.push_back([&] { return arith(t, " * "); });
    // Mixed operands: the narrower one is widened implicitly.
    alts.push_back([&] {
      T u = narrower(t, pick(8));
      std::string a = sub(t), b = sub(u);
      if (is_const(a) && is_const(b)) a = variable(t, s);
      if (a.empty()) return sub(t);
      static const char* kOps[] = {" + ", " - ", " * "};
      return chance(50) ? "(" + a + kOps[pick(3)] + b + ")" : "(" + b + kOps[pick(3)] + a + ")";
    });
    alts.push_back([&, n] {
      auto [a, d] = operands(t);
      if (a.empty()) return sub(t);
      return "(" + a + (chance(50) ? " / " : " MOD ") + "SEL(" + d + " = " + n + "#0, " + d + ", " + n + "#7))";
    });
    if (is_signed(t)) {
      alts.push_back([&] { return "(-" + sub(t) + ")"; });
      alts.push_back([&] { return "ABS(" + sub(t) + ")"; });
    }
    alts.push_back([&] {
      T from = any_num();
      if (from == T::Lint && chance(50)) from = T::Bool;
      if (from == t) return sub(t);
      return std::string(name(from)) + "_TO_" + name(t) + "(" + sub(from) + ")";
    });
    if (t == T::Int) alts.push_back([&] { return "LEN(" + sub(T::Str) + ")"; });
    if (t == T::Dint || t == T::Udint || t == T::Lint) {
      // Dates as counts: DATE/DT seconds since 1970-01-01, TOD ms or s since midnight.
      std::string tn = name(t);
      alts.push_back([&, tn] { return "DATE_TO_" + tn + "(" + date_literal() + ")"; });
      alts.push_back([&, tn] { return "DT_TO_" + tn + "(" + dt_literal() + ")"; });
      alts.push_back([&, tn] { return "TOD_TO_" + tn + "(" + tod_literal() + ")"; });
      alts.push_back([&, tn] { return "DT_TO_" + tn + "(DINT_TO_DT(" + sub(T::Dint) + ") + " + sub(T::Time) + ")"; });
      alts.push_back([&, tn] { return "TOD_TO_" + tn + "(" + tod_literal() + " - " + sub(T::Time) + ")"; });
      alts.push_back([&, tn] { return "TIME_TO_" + tn + "(DINT_TO_TOD(" + sub(T::Dint) + ") - " + tod_literal() + ")"; });
      alts.push_back([&, tn] { return "TIME_TO_" + tn + "(" + date_literal() + " - UDINT_TO_DATE(" + sub(T::Udint) + "))"; });
    }
  }
  if (is_bits(t)) {
    alts.push_back([&] {
      static const char* kOps[] = {" AND ", " OR ", " XOR "};
      return "(" + sub(t) + kOps[pick(3)] + sub(t) + ")";
    });
    alts.push_back([&] { return "(NOT " + sub(t) + ")"; });
    alts.push_back([&] {
      static const char* kFns[] = {"SHL(", "SHR(", "ROL(", "ROR("};
      return kFns[pick(4)] + sub(t) + ", INT#" + std::to_string(pick(width(t) + 2)) + ")";
    });
    alts.push_back([&] {
      static const T kFrom[] = {T::Usint, T::Uint, T::Udint, T::Int, T::Dint};
      T from = kFrom[pick(5)];
      return std::string(name(from)) + "_TO_" + name(t) + "(" + sub(from) + ")";
    });
  }
  if (is_real(t)) {
    std::string n = name(t);
    // Factors limited to +-1000 and divisors of at least 1 in magnitude: no infinity, so
    // no NaN, whose MIN/MAX/LIMIT results would be the implementation's.
    alts.push_back([&, n] {
      return "(LIMIT(-" + n + "#1000.0, " + sub(t) + ", " + n + "#1000.0) * LIMIT(-" + n + "#1000.0, " + sub(t) + ", " + n +
             "#1000.0))";
    });
    alts.push_back([&, n] {
      std::string d = sub(t);
      return "(" + sub(t) + " / SEL(ABS(" + d + ") < " + n + "#1.0, " + d + ", " + n + "#1.0))";
    });
    alts.push_back([&] { return "(-" + sub(t) + ")"; });
    alts.push_back([&] { return "ABS(" + sub(t) + ")"; });
    alts.push_back([&] { return "SQRT(ABS(" + sub(t) + "))"; });
    alts.push_back([&] {
      T from = any_num();
      if (from == t) return sub(t);
      return std::string(name(from)) + "_TO_" + name(t) + "(" + sub(from) + ")";
    });
  }
  if (t == T::Time) {
    alts.push_back([&] {
      std::string a = sub(T::Time), d = sub(T::Dint);
      if (is_const(a) && is_const(d)) d = variable(T::Dint, s);
      if (d.empty()) return a;
      return chance(50) ? "(" + a + " * " + d + ")" : "(" + a + " / SEL(" + d + " = DINT#0, " + d + ", DINT#3))";
    });
    alts.push_back([&] { return "DINT_TO_TIME(" + sub(T::Dint) + ")"; });
  }
  if (t == T::Bool) {
    alts.push_back([&] {
      T u = any_scalar();
      static const char* kCmp[] = {" = ", " <> ", " < ", " > ", " <= ", " >= "};
      int k = u == T::Bool ? pick(2) : pick(6);  // strings are ordered byte by byte
      return "(" + sub(u) + kCmp[k] + sub(u) + ")";
    });
    alts.push_back([&] {
      static const char* kOps[] = {" AND ", " OR ", " XOR "};
      return "(" + sub(T::Bool) + kOps[pick(3)] + sub(T::Bool) + ")";
    });
    alts.push_back([&] { return "(NOT " + sub(T::Bool) + ")"; });
    alts.push_back([&] {
      static const T kFrom[] = {T::Int, T::Dint, T::Usint, T::Byte};
      T from = kFrom[pick(4)];
      return std::string(name(from)) + "_TO_BOOL(" + sub(from) + ")";
    });
  }
  if (t == T::Str) {
    alts.push_back([&] { return "CONCAT(" + sub(T::Str) + ", " + sub(T::Str) + ")"; });
    alts.push_back([&] { return std::string(chance(50) ? "LEFT(" : "RIGHT(") + sub(T::Str) + ", INT#" + std::to_string(pick(8)) + ")"; });
    alts.push_back([&] {
      return "MID(" + sub(T::Str) + ", INT#" + std::to_string(pick(6)) + ", INT#" + std::to_string(pick(7)) + ")";
    });
  }
  return alts[pick(static_cast<int>(alts.size()))]();
}

std::string Gen::assign(const Place& p, const Scope& s, int depth) {
  // Now and then a narrower integer, widened by the assignment.
  std::string rhs = is_int(p.t) && chance(15) ? expr(narrower(p.t, pick(8)), s, depth) : expr(p.t, s, depth);
  // Stored REALs stay within +-1e6, so that no chain of statements reaches infinity.
  if (is_real(p.t)) rhs = "LIMIT(-" + std::string(name(p.t)) + "#1000000.0, " + rhs + ", " + name(p.t) + "#1000000.0)";
  return place_text(p, s, 2) + " := " + rhs + ";";
}

std::string Gen::stmts(const Scope& s, int n, int depth, const std::string& sep) {
  std::string text;
  for (int i = 0; i < n; ++i) text += (i ? sep : "") + stmt(s, depth);
  return text;
}

std::string Gen::stmt(const Scope& s, int depth) {
  std::vector<const Place*> w;
  for (const auto& p : s.places)
    if (p.writable) w.push_back(&p);
  int r = pick(100);
  int ed = 3;  // expression depth
  if (depth > 0 && r < 10) {
    std::string t = "IF " + expr(T::Bool, s, ed) + " THEN " + stmts(s, 1 + pick(2), depth - 1);
    if (chance(40)) t += " ELSIF " + expr(T::Bool, s, ed) + " THEN " + stmts(s, 1, depth - 1);
    if (chance(60)) t += " ELSE " + stmts(s, 1 + pick(2), depth - 1);
    return t + " END_IF;";
  }
  if (depth > 0 && r < 16) {
    std::string t = "CASE " + expr(T::Dint, s, 2) + " OF";
    int base = pick(5);
    t += " DINT#" + std::to_string(base) + ": " + stmts(s, 1, depth - 1);
    t += " DINT#" + std::to_string(base + 1) + ", DINT#" + std::to_string(base + 3) + ": " + stmts(s, 1, depth - 1);
    t += " DINT#" + std::to_string(base + 4) + "..DINT#" + std::to_string(base + 40) + ": " + stmts(s, 1, depth - 1);
    if (chance(70)) t += " ELSE " + stmts(s, 1, depth - 1);
    return t + " END_CASE;";
  }
  if (depth > 0 && r < 22 && !loop_vars_.empty()) {
    std::string v = loop_vars_.back();
    loop_vars_.pop_back();
    Scope inner = s;
    Place p;
    p.base = v;
    p.t = T::Dint;
    p.writable = false;
    inner.places.push_back(p);
    int from = pick(6) - 2, to = from + pick(6);
    std::string by = chance(30) ? " BY DINT#2" : "";
    if (chance(20)) {
      std::swap(from, to);
      by = " BY (-DINT#1)";
    }
    auto bound = [](int b) { return b < 0 ? "(-DINT#" + std::to_string(-b) + ")" : "DINT#" + std::to_string(b); };
    std::string t = "FOR " + v + " := " + bound(from) + " TO " + bound(to) + by + " DO ";
    if (chance(20)) t += "IF " + expr(T::Bool, inner, 2) + " THEN CONTINUE; END_IF; ";
    t += stmts(inner, 1 + pick(2), depth - 1);
    if (chance(25)) t += " IF " + expr(T::Bool, inner, 2) + " THEN EXIT; END_IF;";
    return t + " END_FOR;";
  }
  if (depth > 0 && r < 26 && !while_vars_.empty()) {
    std::string v = while_vars_.back();
    while_vars_.pop_back();
    int n = 1 + pick(4);
    if (chance(50))
      return v + " := DINT#0; WHILE " + v + " < DINT#" + std::to_string(n) + " DO " + stmts(s, 1 + pick(2), depth - 1) + " " +
             v + " := " + v + " + DINT#1; END_WHILE;";
    return v + " := DINT#0; REPEAT " + stmts(s, 1 + pick(2), depth - 1) + " " + v + " := " + v + " + DINT#1; UNTIL " + v +
           " >= DINT#" + std::to_string(n) + " END_REPEAT;";
  }
  if (r < 45 && !s.insts.empty()) {
    auto [inst, k] = s.insts[static_cast<size_t>(pick(static_cast<int>(s.insts.size())))];
    const FbInfo& f = fbs_[static_cast<size_t>(k)];
    int q = pick(3);
    bool element = inst.find("[?]") != std::string::npos;
    if (q == 0 && (f.derived || element)) q = 1;
    if (element) inst.replace(inst.find("[?]"), 3, "[LIMIT(DINT#1, " + expr(T::Dint, s, 1) + ", DINT#2)]");
    if (q == 0) {
      // Whether an FB call's inputs are stored one by one as they are evaluated, or all
      // evaluated first, is the implementation's choice (plcfi stores them one by one): the
      // arguments must not read the instance being called.
      Scope args = s;
      // Calls that may read it: its own methods, and indirectly THIS^ methods (which read
      // an inner instance), interface calls and FUNCTIONs taking the interface.
      // (A named copy: clang 14 cannot capture a structured binding.)
      const std::string own = inst + ".";
      std::erase_if(args.calls, [&own](const Callable& c) {
        return c.prefix.rfind(own, 0) == 0 || c.prefix.rfind("THIS^.", 0) == 0 || c.prefix.rfind("itf.", 0) == 0 ||
               c.itf_param;
      });
      std::string t = inst + "(";
      bool first = true;
      for (const auto& [n, ty] : f.inputs) {
        if (!chance(70)) continue;
        t += (first ? "" : ", ") + n + " := " + expr(ty, args, ed);
        first = false;
      }
      for (const auto& [n, ty] : f.outputs) {
        std::vector<const Place*> dst;
        for (const auto* p : w)
          if (p->t == ty && !p->indexed) dst.push_back(p);
        if (dst.empty() || !chance(50)) continue;
        t += (first ? "" : ", ") + n + " => " + dst[pick(static_cast<int>(dst.size()))]->base;
        first = false;
      }
      return t + ");";
    }
    if (q == 1) {
      std::string t = inst + ".Step(";
      for (size_t i = 0; i < f.step_params.size(); ++i)
        t += (i ? ", " : "") + f.step_params[i].first + " := " +
             (opt_.avoid_method_args_with_calls ? leaf(f.step_params[i].second, s) : expr(f.step_params[i].second, s, ed));
      std::vector<const Place*> io;
      for (const auto* p : w)
        if (p->t == T::Dint && !p->bit) io.push_back(p);
      // Every scope that calls Step has a writable DINT (cnt in FBs, acc in programs).
      t += ", io := " + place_text(*io[static_cast<size_t>(pick(static_cast<int>(io.size())))], s,
                                   opt_.avoid_method_args_with_calls ? 0 : 1);
      std::vector<const Place*> dst;
      for (const auto* p : w)
        if (p->t == f.step_output && !p->indexed) dst.push_back(p);
      if (!dst.empty() && chance(60)) t += ", q => " + dst[pick(static_cast<int>(dst.size()))]->base;
      return t + ");";
    }
    const Callable& p = f.props[pick(static_cast<int>(f.props.size()))];
    std::string rhs = expr(p.ret, s, ed);
    if (is_real(p.ret)) rhs = "LIMIT(-" + std::string(name(p.ret)) + "#1000000.0, " + rhs + ", " + name(p.ret) + "#1000000.0)";
    return inst + "." + p.prefix + " := " + rhs + ";";
  }
  if (s.fb_statements && r < 49 && !refs_.empty()) {
    const auto& [n, ps] = refs_[static_cast<size_t>(pick(static_cast<int>(refs_.size())))];
    return n + " := REF(" + place_text(ps[static_cast<size_t>(pick(static_cast<int>(ps.size())))], s, 1) + ");";
  }
  if (s.fb_statements && r < 56) {
    std::vector<const Place*> io;
    for (const auto* p : w)
      if (p->t == fio_type_ && !p->bit) io.push_back(p);
    // The result goes to a place without an index: whether the index is computed before
    // or after FIO changes its VAR_IN_OUT is the implementation's choice.
    std::vector<const Place*> plain;
    for (const auto* p : io)
      if (!p->indexed) plain.push_back(p);
    if (io.size() >= 2 && !plain.empty()) {
      const Place* dst = plain[static_cast<size_t>(pick(static_cast<int>(plain.size())))];
      const Place* ref = io[static_cast<size_t>(pick(static_cast<int>(io.size())))];
      const Place* out = plain[static_cast<size_t>(pick(static_cast<int>(plain.size())))];
      std::map<std::string, std::string> arg{{"io", place_text(*ref, s, 1)}, {"a", expr(fio_type_, s, ed)}, {"o", place_text(*out, s, 1)}};
      std::string call = "FIO(";
      if (chance(50)) {  // non-formal: declaration order, a trailing output may be left out
        size_t n = fio_order_.back() == "o" && chance(50) ? 2 : 3;
        for (size_t i = 0; i < n; ++i) call += (i ? ", " : "") + arg[fio_order_[i]];
      } else {
        call += "io := " + arg["io"] + ", a := " + arg["a"];
        if (chance(50)) call += ", o => " + arg["o"];
      }
      return place_text(*dst, s, 1) + " := " + call + ");";
    }
  }
  if (s.fb_statements && r < 58) {
    // Whole structures copied in both directions.
    std::string i = "rs[LIMIT(DINT#1, " + expr(T::Dint, s, 1) + ", DINT#3)]";
    return chance(50) ? "r1 := " + i + ";" : i + " := r1;";
  }
  if (s.fb_statements && r < 61) {
    const char* kTargets[] = {"ia", "ib", "id"};
    return "IF " + expr(T::Bool, s, 2) + " THEN itf := " + kTargets[pick(3)] + "; ELSE itf := ib; END_IF;";
  }
  if (w.empty()) return ";";
  return assign(*w[pick(static_cast<int>(w.size()))], s, ed);
}

std::string Gen::pou_vars(const std::string& section, const std::vector<std::pair<std::string, T>>& v) {
  if (v.empty()) return "";
  std::string t = section + "\n";
  for (const auto& [n, ty] : v) t += "  " + n + " : " + type_text(ty) + ";\n";
  return t + "END_VAR\n";
}

void Gen::function(int k) {
  Callable c;
  c.prefix = "F" + std::to_string(k);
  c.ret = any_scalar();
  int n = 1 + pick(3);
  for (int i = 0; i < n; ++i) c.params.emplace_back("a" + std::to_string(i), any_scalar());
  Scope s;
  s.calls = functions_;
  for (const auto& [pn, pt] : c.params) s.places.push_back(Place{pn, "", pt, false});
  for (const auto& [gn, gt] : globals_) s.places.push_back(Place{gn, "", gt, false});
  std::vector<std::pair<std::string, T>> locals;
  for (int i = 0; i < 2; ++i) {
    locals.emplace_back("t" + std::to_string(i), any_scalar());
    s.places.push_back(Place{locals.back().first, "", locals.back().second, true});
  }
  out_ << "FUNCTION " << c.prefix << " : " << type_text(c.ret) << "\n" << pou_vars("VAR_INPUT", c.params);
  out_ << "VAR\n";
  for (const auto& [ln, lt] : locals) out_ << "  " << ln << " : " << type_text(lt) << " := " << literal(lt) << ";\n";
  out_ << "END_VAR\n";
  for (int i = 0; i < 2; ++i) out_ << stmt(s, 1) << "\n";
  if (chance(40))
    out_ << "IF " << expr(T::Bool, s, 2) << " THEN " << assign(Place{c.prefix, "", c.ret, true}, s, 2) << " RETURN; END_IF;\n";
  out_ << assign(Place{c.prefix, "", c.ret, true}, s, 3) << "\nEND_FUNCTION\n\n";
  functions_.push_back(c);
}

// inner >= 0: the FB holds an instance `inner` of FB number `inner`, which its methods read
// and its body and Step change.
void Gen::fb(int k, bool implements, int inner) {
  FbInfo f;
  f.type = "Fb" + std::to_string(k);
  for (int i = 0; i < 2; ++i) f.inputs.emplace_back("in" + std::to_string(i), any_scalar());
  for (int i = 0; i < 2; ++i) f.outputs.emplace_back("out" + std::to_string(i), any_scalar());
  std::vector<std::pair<std::string, T>> state;
  for (int i = 0; i < 4; ++i) state.emplace_back("s" + std::to_string(i), any_scalar());
  state.emplace_back("cnt", T::Dint);
  std::vector<std::pair<std::string, T>> props;
  for (int i = 0; i < 2; ++i) props.emplace_back("P" + std::to_string(i), state[static_cast<size_t>(pick(4))].second);

  out_ << "FUNCTION_BLOCK " << f.type << (implements ? " IMPLEMENTS IGen" : "") << "\n";
  out_ << pou_vars("VAR_INPUT", f.inputs) << pou_vars("VAR_OUTPUT", f.outputs);
  out_ << "VAR\n";
  for (const auto& [n, t] : state) out_ << "  " << n << " : " << type_text(t) << " := " << literal(t) << ";\n";
  std::vector<Callable> inner_calls;  // pure methods and getters of the inner instance
  std::vector<Place> inner_places;
  if (inner >= 0) {
    const FbInfo& in = fbs_[static_cast<size_t>(inner)];
    out_ << "  inner : " << in.type << ";\n";
    for (auto c : in.methods) {
      c.prefix = "inner." + c.prefix;
      inner_calls.push_back(c);
    }
    for (auto c : in.props) {
      c.prefix = "inner." + c.prefix;
      inner_calls.push_back(c);
    }
    for (const auto& [o, t] : in.outputs) inner_places.push_back(Place{"inner." + o, "", t, false});
  }
  std::string loop = "loop" + std::to_string(loops_++);
  out_ << "END_VAR\n";
  // Instance variables, read as `x` or `THIS^.x`.
  auto instance_places = [&](bool writable) {
    std::vector<Place> ps = inner_places;
    for (const auto& [gn, gt] : globals_) ps.push_back(Place{gn, "", gt, writable});
    for (const auto& v : f.inputs) ps.push_back(Place{chance(50) ? v.first : "THIS^." + v.first, "", v.second, false});
    for (const auto& v : f.outputs) ps.push_back(Place{v.first, "", v.second, writable});
    for (const auto& v : state) ps.push_back(Place{chance(50) ? v.first : "THIS^." + v.first, "", v.second, writable});
    return ps;
  };


  // Pure methods: they read the instance and write only their own variables, so that a
  // call inside an expression has no effect that an evaluation order could expose.
  std::vector<Callable> own;  // callable as THIS^.name inside the FB
  auto method = [&](const std::string& mname, T ret, std::vector<std::pair<std::string, T>> params) {
    Scope s;
    s.places = instance_places(false);
    s.calls = functions_;
    s.calls.insert(s.calls.end(), inner_calls.begin(), inner_calls.end());
    for (auto c : own) {
      c.prefix = "THIS^." + c.prefix;
      s.calls.push_back(c);
    }
    for (const auto& [pn, pt] : params) s.places.push_back(Place{pn, "", pt, false});
    out_ << "METHOD " << mname << " : " << type_text(ret) << "\n" << pou_vars("VAR_INPUT", params);
    out_ << "VAR\n  mv : " << type_text(ret) << " := " << literal(ret) << ";\nEND_VAR\n";
    s.places.push_back(Place{"mv", "", ret, true});
    out_ << stmt(s, 1) << "\n";
    if (chance(40))
      out_ << "IF " << expr(T::Bool, s, 2) << " THEN " << assign(Place{mname, "", ret, true}, s, 2) << " RETURN; END_IF;\n";
    out_ << assign(Place{mname, "", ret, true}, s, 3) << "\nEND_METHOD\n";
    Callable c;
    c.prefix = mname;
    c.ret = ret;
    c.params = std::move(params);
    c.is_method = true;
    own.push_back(c);
  };
  if (implements) {
    method("Calc", T::Dint, {{"k", T::Dint}});
    f.has_calc = true;
  }
  for (int i = 0; i < 2; ++i) {
    std::vector<std::pair<std::string, T>> params;
    int n = 1 + pick(2);
    for (int j = 0; j < n; ++j) params.emplace_back(std::string(1, static_cast<char>('a' + j)), any_scalar());
    method("M" + std::to_string(i), any_scalar(), params);
  }
  for (const auto& [pn, pt] : props) {
    Scope s;
    s.places = instance_places(false);
    s.calls = functions_;
    out_ << "PROPERTY " << pn << " : " << type_text(pt) << "\nGET\n";
    out_ << assign(Place{pn, "", pt, true}, s, 2) << "\nEND_GET\nSET\n";
    std::vector<std::string> same;
    for (const auto& v : state)
      if (v.second == pt) same.push_back(v.first);
    out_ << same[static_cast<size_t>(pick(static_cast<int>(same.size())))] << " := " << pn << ";\n";
    out_ << "cnt := cnt + DINT#1;\nEND_SET\nEND_PROPERTY\n";
    Callable c;
    c.prefix = pn;
    c.ret = pt;
    c.is_property = true;
    f.props.push_back(c);
  }
  // Step changes the instance; it is called only as a statement.
  f.step_params = {{"d", any_scalar()}};
  {
    Scope s;
    s.places = instance_places(true);
    s.calls = functions_;
    s.calls.insert(s.calls.end(), inner_calls.begin(), inner_calls.end());
    if (inner >= 0) s.insts.emplace_back("inner", inner);
    for (auto c : own) {
      c.prefix = "THIS^." + c.prefix;
      s.calls.push_back(c);
    }
    for (auto c : f.props) {
      c.prefix = "THIS^." + c.prefix;
      s.calls.push_back(c);
    }
    loop_vars_ = {loop};
    Scope step = s;
    step.places.push_back(Place{"d", "", f.step_params[0].second, false});
    f.step_output = any_scalar();
    // A FOR control variable must be local to the method.
    // io, a VAR_IN_OUT: the caller's DINT, changed through its address.
    out_ << "METHOD Step\n" << pou_vars("VAR_INPUT", f.step_params) << pou_vars("VAR_OUTPUT", {{"q", f.step_output}})
         << pou_vars("VAR_IN_OUT", {{"io", T::Dint}}) << "VAR\n  " << loop << " : DINT;\nEND_VAR\n";
    step.places.push_back(Place{"io", "", T::Dint, true});
    out_ << stmts(step, 2, 2, "\n") << "\n" << assign(Place{"q", "", f.step_output, true}, step, 2)
         << "\nio := io + " << expr(T::Dint, step, 2) << ";\ncnt := cnt + DINT#1;\nEND_METHOD\n";
    // The body.
    loop_vars_.clear();
    out_ << stmts(s, 3, 2, "\n") << "\nEND_FUNCTION_BLOCK\n\n";
    loop_vars_.clear();
  }
  f.methods = own;
  f.state = state;
  fbs_.push_back(f);
}

// An FB that EXTENDS `base`, overriding Calc and M0 (which call SUPER^ and never a method
// that could come back to them: the inherited M1 may call THIS^.M0, now the override).
void Gen::derived_fb(int k, const FbInfo& base) {
  FbInfo f = base;
  f.type = "Fb" + std::to_string(k);
  f.derived = true;
  std::vector<std::pair<std::string, T>> own{{"x0", any_scalar()}, {"x1", any_scalar()}};
  out_ << "FUNCTION_BLOCK " << f.type << " EXTENDS " << base.type << "\nVAR\n";
  for (const auto& [n, t] : own) out_ << "  " << n << " : " << type_text(t) << " := " << literal(t) << ";\n";
  out_ << "END_VAR\n";
  Scope s;
  for (const auto& v : base.inputs) s.places.push_back(Place{v.first, "", v.second, false});
  for (const auto& v : base.outputs) s.places.push_back(Place{"THIS^." + v.first, "", v.second, false});
  for (const auto& v : base.state) s.places.push_back(Place{v.first, "", v.second, false});
  for (const auto& v : own) s.places.push_back(Place{chance(50) ? v.first : "THIS^." + v.first, "", v.second, false});
  s.calls = functions_;
  for (auto c : base.props) {
    c.prefix = "THIS^." + c.prefix;
    s.calls.push_back(c);
  }
  auto override_method = [&](const Callable& m, bool may_call_calc) {
    Scope ms = s;
    Callable sup = m;
    sup.prefix = "SUPER^." + m.prefix;
    ms.calls.push_back(sup);
    if (may_call_calc) {
      Callable calc;
      calc.prefix = "THIS^.Calc";
      calc.ret = T::Dint;
      calc.params = {{"k", T::Dint}};
      calc.is_method = true;
      ms.calls.push_back(calc);
    }
    for (const auto& [pn, pt] : m.params) ms.places.push_back(Place{pn, "", pt, false});
    out_ << "METHOD " << m.prefix << " : " << type_text(m.ret) << "\n" << pou_vars("VAR_INPUT", m.params);
    out_ << "VAR\n  mv : " << type_text(m.ret) << " := " << literal(m.ret) << ";\nEND_VAR\n";
    ms.places.push_back(Place{"mv", "", m.ret, true});
    out_ << stmt(ms, 1) << "\n" << assign(Place{m.prefix, "", m.ret, true}, ms, 3) << "\nEND_METHOD\n";
  };
  for (const auto& m : base.methods) {
    if (m.prefix == "Calc") override_method(m, false);
    if (m.prefix == "M0") override_method(m, true);
  }
  out_ << "END_FUNCTION_BLOCK\n\n";
  fbs_.push_back(f);
}

std::string Gen::program() {
  str_len_ = 6 + pick(10);
  out_ << "(* generated by plcfi_oracle *)\n";
  // Rec holds a nested structure and an array: member offsets two levels deep.
  std::vector<std::pair<std::string, T>> inner_fields{{"h0", any_scalar()}, {"h1", any_scalar()}};
  out_ << "TYPE Sub :\nSTRUCT\n";
  for (const auto& [n, t] : inner_fields) out_ << "  " << n << " : " << type_text(t) << ";\n";
  out_ << "END_STRUCT;\nEND_TYPE\n\n";
  T elem = any_scalar();
  out_ << "TYPE Rec :\nSTRUCT\n";
  std::vector<std::pair<std::string, T>> fields;
  for (int i = 0; i < 3; ++i) fields.emplace_back("f" + std::to_string(i), any_scalar());
  for (const auto& [n, t] : fields) out_ << "  " << n << " : " << type_text(t) << ";\n";
  out_ << "  sub : Sub;\n  a : ARRAY[0..2] OF " << type_text(elem) << ";\n";
  out_ << "END_STRUCT;\nEND_TYPE\n\n";
  for (const auto& [n, t] : inner_fields) fields.emplace_back("sub." + n, t);
  out_ << "INTERFACE IGen\nMETHOD Calc : DINT\nVAR_INPUT\n  k : DINT;\nEND_VAR\nEND_METHOD\nEND_INTERFACE\n\n";
  for (int i = 0; i < 2; ++i) globals_.emplace_back("g" + std::to_string(i), any_scalar());
  out_ << pou_vars("VAR_GLOBAL", globals_) << "\n";

  int nf = 2 + pick(3);
  for (int i = 0; i < nf; ++i) function(i);
  // A FUNCTION with a VAR_IN_OUT, which it changes: called only as a statement's right side.
  {
    fio_type_ = any_scalar();
    std::string tt = type_text(fio_type_);
    // Its in-out, input and output in one of the six orders: a non-formal call binds in
    // declaration order, whatever the sections' order (and VAR_INPUT CONSTANT is an input
    // like any other to its callers).
    fio_order_ = {"io", "a", "o"};
    for (size_t i = fio_order_.size(); i > 1; --i) std::swap(fio_order_[i - 1], fio_order_[static_cast<size_t>(pick(static_cast<int>(i)))]);
    out_ << "FUNCTION FIO : " << tt << "\n";
    for (const auto& n : fio_order_)
      out_ << (n == "io" ? "VAR_IN_OUT" : n == "a" ? (chance(50) ? "VAR_INPUT CONSTANT" : "VAR_INPUT") : "VAR_OUTPUT") << "\n  " << n
           << " : " << tt << ";\nEND_VAR\n";
    Scope fs;
    fs.calls = functions_;
    fs.places = {Place{"io", "", fio_type_, true}, Place{"a", "", fio_type_, false}, Place{"o", "", fio_type_, true}};
    out_ << stmts(fs, 2, 1, "\n") << "\n" << assign(Place{"FIO", "", fio_type_, true}, fs, 2) << "\nEND_FUNCTION\n\n";
  }
  // A FUNCTION taking an interface: dispatch through a parameter.
  out_ << "FUNCTION FI : DINT\nVAR_INPUT\n  i : IGen;\n  k : DINT;\nEND_VAR\nFI := i.Calc(k := k) - k;\nEND_FUNCTION\n\n";
  fb(0, false, -1);
  fb(1, true, 0);
  fb(2, true, -1);
  derived_fb(3, fbs_[1]);

  Scope s;
  s.fb_statements = true;
  s.calls = functions_;
  out_ << "PROGRAM Main\nVAR\n";
  for (int i = 0; i < 14; ++i) {
    T t = any_scalar();
    std::string n = "v" + std::to_string(i);
    out_ << "  " << n << " : " << type_text(t);
    if (chance(40)) out_ << " := " << literal(t);
    out_ << ";\n";
    s.places.push_back(Place{n, "", t, true});
    if (is_bits(t)) {
      s.places.push_back(Place{n + "." + std::to_string(pick(width(t))), "", T::Bool, true});  // one bit
      s.places.back().bit = true;
    }
  }
  for (int i = 0; i < 2; ++i) {
    T t = any_scalar();
    int lo = pick(3) - 1, hi = lo + 2 + pick(4);
    std::string n = "arr" + std::to_string(i);
    out_ << "  " << n << " : ARRAY[" << lo << ".." << hi << "] OF " << type_text(t) << ";\n";
    Place p{n, "", t, true, true, lo, hi};
    s.places.push_back(p);
  }
  out_ << "  r1 : Rec;\n  rs : ARRAY[1..3] OF Rec;\n  acc : DINT;\n";
  s.places.push_back(Place{"acc", "", T::Dint, true});
  for (const auto& [n, t] : fields) {
    s.places.push_back(Place{"r1." + n, "", t, true});
    s.places.push_back(Place{"rs", "." + n, t, true, true, 1, 3});
  }
  s.places.push_back(Place{"r1.a", "", elem, true, true, 0, 2});
  for (const auto& [n, t] : globals_) s.places.push_back(Place{n, "", t, true});
  // Instances: ia (Fb1, holding an Fb0) and ib (Fb2) implement IGen, ic is an Fb0, ia2 a
  // second Fb1, id an Fb3 EXTENDS Fb1 (so it implements IGen too).
  const std::pair<std::string, int> insts[] = {{"ia", 1}, {"ib", 2}, {"ic", 0}, {"ia2", 1}, {"id", 3}};
  for (const auto& [inst, k] : insts) {
    out_ << "  " << inst << " : " << fbs_[static_cast<size_t>(k)].type << ";\n";
    s.insts.emplace_back(inst, k);
    const FbInfo& f = fbs_[static_cast<size_t>(k)];
    for (const auto& [o, t] : f.outputs) s.places.push_back(Place{inst + "." + o, "", t, false});
    for (auto c : f.methods) {
      c.prefix = inst + "." + c.prefix;
      s.calls.push_back(c);
    }
    for (auto c : f.props) {
      c.prefix = inst + "." + c.prefix;
      s.calls.push_back(c);
    }
  }
  // The interface refers to an instance before any statement can call through it.
  std::string first = "IF " + expr(T::Bool, s, 2) + " THEN itf := ia; ELSE itf := ib; END_IF;\n";
  // Two references, each to a type with at least two variables to point at; they point at
  // one before any statement reads through them, and statements retarget them.
  {
    std::map<T, std::vector<Place>> targets;
    for (const auto& p : s.places)
      if (p.writable && !p.bit) targets[p.t].push_back(p);
    std::vector<T> ok;
    for (const auto& [t, ps] : targets)
      if (ps.size() >= 2) ok.push_back(t);
    for (int i = 0; i < 2 && !ok.empty(); ++i) {
      T t = ok[static_cast<size_t>(pick(static_cast<int>(ok.size())))];
      std::string n = "p" + std::to_string(i);
      out_ << "  " << n << " : REF_TO " << type_text(t) << ";\n";
      const auto& ps = targets[t];
      first += n + " := REF(" + place_text(ps[static_cast<size_t>(pick(static_cast<int>(ps.size())))], s, 0) + ");\n";
      refs_.emplace_back(n, ps);
    }
    for (const auto& [n, ps] : refs_) s.places.push_back(Place{n + "^", "", ps[0].t, true});
  }
  // An array of instances of Fb0: methods, properties and outputs of an indexed element.
  out_ << "  fbs : ARRAY[1..2] OF " << fbs_[0].type << ";\n";
  s.insts.emplace_back("fbs[?]", 0);
  for (const auto& [o, t] : fbs_[0].outputs) s.places.push_back(Place{"fbs", "." + o, t, false, true, 1, 2});
  for (auto c : fbs_[0].methods) {
    c.prefix = "fbs[?]." + c.prefix;
    s.calls.push_back(c);
  }
  for (auto c : fbs_[0].props) {
    c.prefix = "fbs[?]." + c.prefix;
    s.calls.push_back(c);
  }
  Callable fi;
  fi.prefix = "FI";
  fi.params = {{"i", T::Dint}, {"k", T::Dint}};  // i: the interface, written by call_text
  fi.itf_param = true;
  s.calls.push_back(fi);
  Callable calc;
  calc.prefix = "itf.Calc";
  calc.ret = T::Dint;
  calc.params = {{"k", T::Dint}};
  calc.is_method = true;
  s.calls.push_back(calc);
  out_ << "  itf : IGen;\n";
  for (int i = 0; i < 3; ++i) {
    loop_vars_.push_back("loop" + std::to_string(loops_++));
    out_ << "  " << loop_vars_.back() << " : DINT;\n";
  }
  for (int i = 0; i < 2; ++i) {
    while_vars_.push_back("w" + std::to_string(i));
    out_ << "  " << while_vars_.back() << " : DINT;\n";
  }
  out_ << "END_VAR\n";
  out_ << first;
  int n = 12 + pick(10);
  for (int i = 0; i < n; ++i) out_ << stmt(s, 2) << "\n";
  out_ << "END_PROGRAM\n\n";

  // A second PROGRAM, run after Main in each scan: it sees what Main left in the globals.
  Scope a;
  a.calls = functions_;
  out_ << "PROGRAM Aux\nVAR\n";
  for (int i = 0; i < 5; ++i) {
    T t = any_scalar();
    std::string nm = "x" + std::to_string(i);
    out_ << "  " << nm << " : " << type_text(t) << " := " << literal(t) << ";\n";
    a.places.push_back(Place{nm, "", t, true});
  }
  for (const auto& [gn, gt] : globals_) a.places.push_back(Place{gn, "", gt, true});
  const FbInfo& ax = fbs_[2];
  out_ << "  ax : " << ax.type << ";\n  acc : DINT;\n  loopA : DINT;\n  wa : DINT;\nEND_VAR\n";
  a.places.push_back(Place{"acc", "", T::Dint, true});
  a.insts.emplace_back("ax", 2);
  for (const auto& [o, t] : ax.outputs) a.places.push_back(Place{"ax." + o, "", t, false});
  for (auto c : ax.methods) {
    c.prefix = "ax." + c.prefix;
    a.calls.push_back(c);
  }
  for (auto c : ax.props) {
    c.prefix = "ax." + c.prefix;
    a.calls.push_back(c);
  }
  loop_vars_ = {"loopA"};
  while_vars_ = {"wa"};
  for (int i = 0; i < 4 + pick(4); ++i) out_ << stmt(a, 2) << "\n";
  out_ << "END_PROGRAM\n";
  return out_.str();
}

// IEC names and keywords are case-insensitive: some identifiers and keywords are written in
// another case (never inside string literals, comments or numbers).
std::string scramble_case(const std::string& text, uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x5eedca5eULL);
  std::string out = text;
  size_t i = 0;
  auto ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  while (i < out.size()) {
    char c = out[i];
    if (c == '\'') {
      size_t j = out.find('\'', i + 1);
      i = j == std::string::npos ? out.size() : j + 1;
    } else if (c == '(' && i + 1 < out.size() && out[i + 1] == '*') {
      size_t j = out.find("*)", i + 2);
      i = j == std::string::npos ? out.size() : j + 2;
    } else if (std::isdigit(static_cast<unsigned char>(c))) {
      while (i < out.size() && (ident(out[i]) || out[i] == '.')) ++i;
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      size_t j = i;
      while (j < out.size() && ident(out[j])) ++j;
      if (rng() % 100 < 12) {
        int how = static_cast<int>(rng() % 3);
        for (size_t k = i; k < j; ++k) {
          auto u = static_cast<unsigned char>(out[k]);
          bool up = how == 0 ? false : how == 1 ? true : (rng() & 1) != 0;
          out[k] = static_cast<char>(up ? std::toupper(u) : std::tolower(u));
        }
      }
      i = j;
    } else {
      ++i;
    }
  }
  return out;
}

}  // namespace

std::string generate_program(uint64_t seed, const GenOptions& opt) {
  Gen g(seed, opt);
  return scramble_case(g.program(), seed);
}

}  // namespace plcfi::oracle
