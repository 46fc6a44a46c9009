// Rules 20 and 22: an array element loaded for the instruction after it, a conditional
// jump (IF f[i] THEN, IF r[j - 1].key > x THEN, WHILE a[k] <> 0 DO) or a widening
// conversion (INT_TO_DINT(a[i])), runs as one handler in the interpreter with that
// instruction. Each case runs the interpreter against the native tier, which has no
// superinstructions (memory, coverage and traps after every scan; with coverage marks
// and without), checks values by hand, and that the fused handlers were really used.
#include <gtest/gtest.h>

#include <functional>
#include <set>
#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

// Compiled as `plcfi run` compiles without --coverage: no COV after a jump (a jump and
// the COV after it are a superinstruction of their own, to which these rules yield); the
// IFs on BOOL elements and on bits keep their jumps (rule 26 would make them selects).
CompileOptions no_coverage() {
  CompileOptions o;
  o.coverage = false;
  o.if_selects = false;
  return o;
}

// Both tiers, scan by scan, compiled with coverage marks and without.
void same_in_both_tiers(const std::string& file, const std::string& src, int scans, uint64_t budget = 0) {
  plcfi::st::same_in_both_tiers(file, src, scans, budget);
  plcfi::st::same_in_both_tiers(file, src, scans, budget, nullptr, no_coverage());
}

// The names of the superinstructions the interpreter runs on `src` (after one scan),
// compiled without coverage marks.
std::set<std::string> fused_names(const std::string& src) {
  vmtest::VmRun p(src, no_coverage(), "ejump.st");
  if (!p.ok()) return {};
  p.scan();
  std::set<std::string> out;
  for (const auto& [pc, name] : p.m->superinstructions()) out.insert(name);
  return out;
}

// Every comparison of an element with a variable and every test of its bits, in both
// orders, for each integer type
// up to 32 bits, with the element reached in each access form: a checked index (LDX), a
// FOR counter proven in range (LDXN), a field of a structure element (LDXS, LDXSN) and a
// row of a rank-2 array in a FOR loop (LDXR). Each condition that holds adds its own
// weight to `hits`, so a jump that goes the wrong way changes the sum.
std::string comparisons_program() {
  const char* types[] = {"SINT", "USINT", "INT", "UINT", "DINT", "UDINT", "WORD", "BYTE", "DWORD"};
  const char* ops[] = {"=", "<>", "<", ">", "<=", ">="};
  std::string tdecl;
  std::string vars;
  std::string body;
  std::string fill;
  int weight = 1;
  tdecl += "TYPE\n";
  for (const char* t : types) {
    const std::string T = t;
    // A DINT from -128 to 127 as T (wrapping into the unsigned types).
    const std::string to = T == "DINT" ? "(" : "DINT_TO_" + T + "(";
    tdecl += "  S_" + T + " : STRUCT pad : BYTE; v : " + T + "; END_STRUCT;\n";
    vars += "  a_" + T + " : ARRAY [0..7] OF " + T + ";\n";
    vars += "  s_" + T + " : ARRAY [0..7] OF S_" + T + ";\n";
    vars += "  m_" + T + " : ARRAY [1..2, 0..3] OF " + T + ";\n";
    vars += "  x_" + T + " : " + T + ";\n";
    // Fill with values around x (the bit patterns cover the sign of the signed types).
    fill += "  FOR i := 0 TO 7 DO\n";
    fill += "    a_" + T + "[i] := " + to + "(i * 37 + scan * 11) MOD 256 - 128);\n";
    fill += "    s_" + T + "[i].v := " + to + "(i * 53 + scan * 7) MOD 256 - 128);\n";
    fill += "  END_FOR;\n";
    fill += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO m_" + T + "[i, j] := " + to +
            "(i * 29 + j * 61 + scan * 13) MOD 256 - 128); END_FOR; END_FOR;\n";
    fill += "  x_" + T + " := " + to + "(scan * 41 + 100) MOD 256 - 128);\n";
    // One condition on an element of each access form, each adding weight w when it holds.
    auto add_conditions = [&](const std::function<std::string(const std::string&)>& cond) {
      const std::string w = std::to_string(weight);
      const std::string then = " THEN hits := hits + " + w + "; END_IF;";
      body += "  IF " + cond("a_" + T + "[k]") + then + "\n";
      body += "  FOR i := 0 TO 7 DO IF " + cond("a_" + T + "[i]") + then + " END_FOR;\n";
      body += "  IF " + cond("s_" + T + "[k].v") + then + "\n";
      body += "  FOR i := 0 TO 7 DO IF " + cond("s_" + T + "[i].v") + then + " END_FOR;\n";
      body += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO IF " + cond("m_" + T + "[i, j]") + then + " END_FOR; END_FOR;\n";
      weight = weight * 3 % 1000 + 1;
    };
    for (const char* op : ops)
      for (int order = 0; order < 2; ++order)
        add_conditions([&](const std::string& e) { return order == 0 ? e + " " + op + " x_" + T : "x_" + T + " " + op + " " + e; });
    // Tests of bits: (e AND m) <> 0 and (e AND m) = 0 (JTZ, JTNZ).
    for (const char* rel : {"<> 0", "= 0"})
      for (int order = 0; order < 2; ++order)
        add_conditions([&](const std::string& e) {
          return std::string("(") + (order == 0 ? e + " AND x_" + T : "x_" + T + " AND " + e) + ") " + rel;
        });
  }
  tdecl += "  S_BOOL : STRUCT pad : BYTE; v : BOOL; END_STRUCT;\nEND_TYPE\n";
  vars += "  f : ARRAY [0..7] OF BOOL;\n  sf : ARRAY [0..7] OF S_BOOL;\n  mf : ARRAY [1..2, 0..3] OF BOOL;\n";
  fill += "  FOR i := 0 TO 7 DO f[i] := ((i + scan) MOD 3) = 0; sf[i].v := ((i * 5 + scan) MOD 4) = 1; END_FOR;\n";
  fill += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO mf[i, j] := ((i + j + scan) MOD 2) = 0; END_FOR; END_FOR;\n";
  for (int neg = 0; neg < 2; ++neg) {
    const std::string n = neg ? "NOT " : "";
    const std::string w = std::to_string(1000 + neg);
    body += "  IF " + n + "f[k] THEN hits := hits + " + w + "; END_IF;\n";
    body += "  FOR i := 0 TO 7 DO IF " + n + "f[i] THEN hits := hits + " + w + "; END_IF; END_FOR;\n";
    body += "  IF " + n + "sf[k].v THEN hits := hits + " + w + "; END_IF;\n";
    body += "  FOR i := 0 TO 7 DO IF " + n + "sf[i].v THEN hits := hits + " + w + "; END_IF; END_FOR;\n";
    body += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO IF " + n + "mf[i, j] THEN hits := hits + " + w +
            "; END_IF; END_FOR; END_FOR;\n";
  }
  return tdecl + "PROGRAM P\nVAR\n" + vars +
         "  i : DINT; j : DINT; k : DINT; scan : DINT; hits : DINT;\nEND_VAR\n" + fill +
         "  k := scan MOD 8;\n  hits := 0;\n" + body + "  scan := scan + 1;\nEND_PROGRAM\n";
}

TEST(VmElementJumps, EveryComparisonOfAnElementAgreesWithTheNativeTier) {
  const std::string src = comparisons_program();
  same_in_both_tiers("ejump.st", src, 12);
  // The class is fused in every access form, each width and signedness, either operand.
  const auto names = fused_names(src);
  for (const char* form : {"LDX", "LDXN", "LDXS", "LDXSN", "LDXR"}) {
    for (const char* jump : {"JMPF", "JMPT"})
      EXPECT_EQ(names.count(std::string(form) + "1+" + jump), 1u) << form << " " << jump;
    for (const char* t : {"I8", "U8", "I16", "U16", "I32", "U32"}) {
      const std::string n = std::string(t).substr(1) == "8" ? "1" : std::string(t).substr(1) == "16" ? "2" : "4";
      for (const char* j : {"JEQ_", "JNE_", "JLT_", "JGE_", "JTZ_", "JTNZ_"})
        EXPECT_EQ(names.count(std::string(form) + n + "+" + j + t), 1u) << form << n << " " << j << t;
    }
  }
}

TEST(VmElementJumps, ValuesByHand) {
  // flags 0..7: TRUE at 1, 2, 6; keys compared in both orders; a WHILE on an element.
  vmtest::VmRun p(R"(
TYPE It : STRUCT id : DINT; key : INT; END_STRUCT; END_TYPE
PROGRAM P
VAR
  f : ARRAY [0..7] OF BOOL := [FALSE, TRUE, TRUE, FALSE, FALSE, FALSE, TRUE, FALSE];
  it : ARRAY [0..4] OF It := [(id := 1, key := -3), (id := 2, key := 5), (id := 3, key := 40), (id := 4, key := -300), (id := 5, key := 7)];
  z : ARRAY [0..9] OF UINT := [4, 9, 65535, 2, 0, 8, 8, 8, 8, 8];
  i : DINT; k : DINT := 0; x : INT := 5;
  set : DINT; over : DINT; under : DINT; len : DINT; clear : DINT;
END_VAR
FOR i := 0 TO 7 DO
  IF f[i] THEN set := set * 10 + i; END_IF;
  IF NOT f[i] THEN clear := clear + 1; END_IF;
END_FOR;
FOR i := 0 TO 4 DO
  IF it[i].key > x THEN over := over * 10 + it[i].id; END_IF;
  IF x > it[i].key THEN under := under * 10 + it[i].id; END_IF;
END_FOR;
WHILE z[k] <> 0 DO
  k := k + 1;
END_WHILE;
len := k;
END_PROGRAM
)",
                  no_coverage(), "ejump.st");
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan());
  EXPECT_EQ(p.get("P.set"), 126);
  EXPECT_EQ(p.get("P.clear"), 5);
  EXPECT_EQ(p.get("P.over"), 35);
  EXPECT_EQ(p.get("P.under"), 14);
  EXPECT_EQ(p.get("P.len"), 4);
  auto used = [&](const std::string& name) {
    for (const auto& [pc, n] : p.m->superinstructions())
      if (n == name) return true;
    return false;
  };
  EXPECT_TRUE(used("LDXN1+JMPF"));
  EXPECT_TRUE(used("LDXN1+JMPT"));
  EXPECT_TRUE(used("LDXSN2+JGE_I16"));
  EXPECT_TRUE(used("LDX2+JNE_U16") || used("LDX2+JEQ_U16"));
}

// A checked index out of range traps at the load, with its message and location, in the
// fused handler as in the plain one; a WHILE on an element that never ends is stopped by
// the watchdog at the same point in both tiers.
TEST(VmElementJumps, RefusedIndexAndWatchdogAsPlain) {
  // k = 10 on the fifth scan: first f[k] (a BOOL, LDX1), then, with f larger, it[k - 1].key
  // (a field, LDXS2) refuses the index.
  for (const char* f_bounds : {"0..9", "0..20"}) {
    const std::string trap_src = std::string(R"(
TYPE It : STRUCT id : DINT; key : INT; END_STRUCT; END_TYPE
PROGRAM P
VAR
  f : ARRAY [)") + f_bounds + R"(] OF BOOL; it : ARRAY [0..8] OF It;
  k : DINT := 6; n : DINT; m : DINT;
END_VAR
f[3] := TRUE;
it[2].key := 9;
IF f[k] THEN n := n + 1; END_IF;
IF it[k - 1].key > 4 THEN m := m + 1; END_IF;
k := k + 1;
END_PROGRAM
)";
    same_in_both_tiers("ejump.st", trap_src, 6);
    vmtest::VmRun p(trap_src, {}, "ejump.st");
    ASSERT_TRUE(p.ok());
    for (int s = 0; s < 4; ++s) ASSERT_TRUE(p.scan()) << s;
    EXPECT_FALSE(p.scan());  // k = 10
    EXPECT_EQ(p.m->trap().kind, TrapKind::IndexOutOfRange);
    EXPECT_EQ(p.m->trap().loc.line, f_bounds == std::string("0..9") ? 10u : 11u);
    EXPECT_EQ(p.get("P.n"), 0);  // f[6..9] are FALSE
    EXPECT_EQ(p.get("P.m"), 0);  // it[5..8].key are 0
  }

  const std::string loop_src = R"(
PROGRAM P
VAR a : ARRAY [0..3] OF DINT := [1, 1, 1, 1]; k : DINT; n : DINT; END_VAR
k := 0;
WHILE a[k] <> 0 DO
  n := n + 1;
END_WHILE;
END_PROGRAM
)";
  for (uint64_t budget : {1u, 2u, 7u, 1000u}) same_in_both_tiers("ejump.st", loop_src, 2, budget);
  vmtest::VmRun q(loop_src, {}, "ejump.st");
  ASSERT_TRUE(q.ok());
  q.m->set_budget(7);
  EXPECT_FALSE(q.scan());
  EXPECT_EQ(q.m->trap().kind, TrapKind::Watchdog);
  EXPECT_EQ(q.get("P.n"), 8);
}

// The pair is fused whichever operands the jump reads: after an element load, a jump on
// another value of the element's width means what it meant.
TEST(VmElementJumps, AJumpOnAnotherValueMeansTheSame) {
  const std::string src = R"(
PROGRAM P
VAR a : ARRAY [0..3] OF BYTE := [3, 1, 4, 1]; i : DINT; b : BOOL; n : DINT; t : BYTE; END_VAR
FOR i := 0 TO 3 DO
  t := a[i];
  IF b THEN n := n + 1; END_IF;
  b := NOT b;
END_FOR;
END_PROGRAM
)";
  same_in_both_tiers("ejump.st", src, 3);
  EXPECT_EQ(fused_names(src).count("LDXN1+JMPF"), 1u);
}

// Rule 22: an element loaded for a widening conversion. Each expression reads an element
// (every access form) for a conversion, an arithmetic or a bitwise operation; the results
// are folded into `acc`, compared with the native tier's.
std::string uses_program() {
  struct Use {
    const char* type;   // the element's type
    const char* expr;   // @: the element
    const char* into;   // the variable it is assigned to
  };
  const Use uses[] = {
      {"BOOL", "@ AND fb", "xb"},         {"BOOL", "@ OR fb", "xb"},          {"BOOL", "@ XOR fb", "xb"},
      {"BYTE", "@ AND yb", "xy"},         {"BYTE", "@ OR yb", "xy"},          {"BYTE", "@ XOR yb", "xy"},
      {"BYTE", "BYTE_TO_WORD(@)", "xw"},  {"BYTE", "BYTE_TO_DWORD(@)", "xd"}, {"USINT", "USINT_TO_INT(@)", "xi"},
      {"USINT", "USINT_TO_DINT(@)", "xj"}, {"SINT", "SINT_TO_INT(@)", "xi"},  {"SINT", "SINT_TO_DINT(@)", "xj"},
      {"INT", "@ + yi", "xi"},            {"INT", "@ - yi", "xi"},            {"INT", "@ * yi", "xi"},
      {"WORD", "@ AND yw", "xw"},         {"WORD", "@ OR yw", "xw"},          {"WORD", "@ XOR yw", "xw"},
      {"INT", "INT_TO_DINT(@)", "xj"},    {"WORD", "WORD_TO_DWORD(@)", "xd"}, {"UINT", "UINT_TO_DINT(@)", "xj"},
      {"DINT", "@ + yj", "xj"},           {"DINT", "@ - yj", "xj"},           {"DINT", "@ * yj", "xj"},
      {"DINT", "@ * yj + zj", "xj"},      {"DWORD", "@ AND yd", "xd"},        {"DWORD", "@ OR yd", "xd"},
      {"DWORD", "@ XOR yd", "xd"},        {"REAL", "@ + yr", "xr"},           {"REAL", "@ - yr", "xr"},
      {"REAL", "@ * yr", "xr"},           {"DINT", "DINT_TO_REAL(@)", "xr"},
  };
  std::string vars, fill, body;
  std::set<std::string> declared;
  int u = 0;
  for (const Use& use : uses) {
    const std::string T = use.type, n = std::to_string(u++);
    if (declared.insert(T).second) {
      vars += "  a_" + T + " : ARRAY [0..7] OF " + T + ";\n  s_" + T + " : ARRAY [0..7] OF S_" + T + ";\n";
      vars += "  l_" + T + " : ARRAY [0..15] OF " + T + ";\n  m_" + T + " : ARRAY [1..2, 0..3] OF " + T + ";\n";
      const std::string conv = T == "BOOL"   ? "((v MOD 3) = 0)"
                               : T == "REAL" ? "DINT_TO_REAL(v - 100) * 0.37"
                               : T == "DINT" ? "(v - 100) * 40000"
                                             : "DINT_TO_" + T + "(v - 100)";
      fill += "  FOR i := 0 TO 7 DO v := (i * 37 + scan * 11) MOD 256; a_" + T + "[i] := " + conv + "; v := v + 5; s_" + T +
              "[i].v := " + conv + "; END_FOR;\n";
      fill += "  FOR i := 0 TO 15 DO v := (i * 53 + scan * 7) MOD 256; l_" + T + "[i] := " + conv + "; END_FOR;\n";
      fill += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO v := (i * 29 + j * 61 + scan * 13) MOD 256; m_" + T + "[i, j] := " +
              conv + "; END_FOR; END_FOR;\n";
    }
    auto stmt = [&](const std::string& elem) {
      std::string e = use.expr;
      e.replace(e.find('@'), 1, elem);
      return std::string(use.into) + " := " + e + "; fold(" + use.into + ", " + n + ");";
    };
    body += "  " + stmt("a_" + T + "[k]") + "\n";
    body += "  FOR i := 0 TO 7 DO " + stmt("a_" + T + "[i]") + " END_FOR;\n";
    body += "  " + stmt("s_" + T + "[k].v") + "\n";
    body += "  FOR i := 0 TO 7 DO " + stmt("s_" + T + "[i].v") + " END_FOR;\n";
    body += "  FOR i := 0 TO 3 DO FOR j := 0 TO hi DO " + stmt("l_" + T + "[i * 4 + j]") + " END_FOR; END_FOR;\n";
    body += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO " + stmt("m_" + T + "[i, j]") + " END_FOR; END_FOR;\n";
  }
  // fold(x, n): a statement that keeps every use apart (no reduction loop) and sums it.
  std::string folded;
  for (const char* x : {"xb", "xy", "xw", "xd", "xi", "xj", "xr"}) {
    const std::string X = x;
    const std::string as_dint = X == "xb"   ? "BOOL_TO_DINT(xb)"
                                : X == "xr" ? "REAL_TO_DINT(xr * 8.0)"
                                : X == "xj" ? "xj"
                                : X == "xy" ? "BYTE_TO_DINT(xy)"
                                : X == "xw" ? "WORD_TO_DINT(xw)"
                                : X == "xd" ? "DWORD_TO_DINT(xd)"
                                            : "INT_TO_DINT(xi)";
    folded += X + ":" + as_dint + ";";
  }
  // Replace each fold(x, n) by an accumulation in DINT with a per-use weight.
  std::string out;
  for (size_t at = 0;;) {
    const size_t f = body.find("fold(", at);
    if (f == std::string::npos) {
      out += body.substr(at);
      break;
    }
    const size_t comma = body.find(", ", f), close = body.find(')', comma);
    const std::string x = body.substr(f + 5, comma - f - 5), w = body.substr(comma + 2, close - comma - 2);
    const size_t def = folded.find(x + ":");
    const std::string as_dint = folded.substr(def + x.size() + 1, folded.find(';', def) - def - x.size() - 1);
    out += body.substr(at, f - at) + "acc := acc * 3 + " + as_dint + " + " + w;
    at = close + 1;
  }
  std::string types = "TYPE\n";
  for (const auto& T : declared) types += "  S_" + T + " : STRUCT pad : BYTE; v : " + T + "; END_STRUCT;\n";
  types += "END_TYPE\n";
  return types + "PROGRAM P\nVAR\n" + vars +
         "  i : DINT; j : DINT; k : DINT; v : DINT; hi : DINT := 3; scan : DINT; acc : DINT;\n"
         "  fb : BOOL; yb : BYTE := 16#5A; yw : WORD := 16#0FF0; yd : DWORD := 16#00FF00FF; yi : INT := -7;\n"
         "  yj : DINT := 12345; zj : DINT := -99; yr : REAL := 1.5;\n"
         "  xb : BOOL; xy : BYTE; xw : WORD; xd : DWORD; xi : INT; xj : DINT; xr : REAL;\nEND_VAR\n" +
         fill + "  k := scan MOD 8;\n  fb := (scan MOD 2) = 0;\n" + out + "  scan := scan + 1;\nEND_PROGRAM\n";
}

TEST(VmElementUses, ConversionsAndArithmeticOnElementsAgreeWithTheNativeTier) {
  const std::string src = uses_program();
  same_in_both_tiers("euse.st", src, 6);
  const auto names = fused_names(src);
  // Widening conversions of an element, in every access form.
  for (const char* form : {"LDX", "LDXN", "LDXS", "LDXSN", "LDXL", "LDXR"}) {
    const std::string f = form;
    for (const std::string& name : {f + "1+CVT_U8_U16", f + "1+CVT_U8_U32", f + "1+CVT_U8_I16", f + "1+CVT_U8_I32",
                                    f + "1+CVT_I8_I16", f + "1+CVT_I8_I32", f + "2+CVT_I16_I32", f + "2+CVT_U16_U32",
                                    f + "2+CVT_U16_I32"})
      EXPECT_EQ(names.count(name), 1u) << name;
    // Arithmetic, bitwise operations and REAL conversions are left as they are (the rule's
    // list leaves them out).
    for (const std::string& name : {f + "1+BXOR", f + "2+MUL_I16", f + "4+XOR_U32", f + "4+ADD_F32", f + "4+CVT_I32_F32"})
      EXPECT_EQ(names.count(name), 0u) << name;
  }
}

// The rule yields: an element loaded for a CVT_I16_I32 that heads a superinstruction of
// its own (CVT_I16_I32+MADD_I32, INT_TO_DINT(a[i]) * k + s) is left to that one.
TEST(VmElementUses, YieldsToTheNextInstructionsOwnSuperinstruction) {
  const std::string src = R"(
PROGRAM P
VAR a : ARRAY [0..7] OF INT := [1, -2, 3, -4, 5, -6, 7, -8]; i : DINT; k : DINT := 31; s : DINT; t : DINT; u : DINT; END_VAR
FOR i := 0 TO 7 DO
  s := INT_TO_DINT(a[i]) * k + s;
  t := t + 1;
  u := INT_TO_DINT(a[i]) + u;
END_FOR;
END_PROGRAM
)";
  same_in_both_tiers("euse.st", src, 3);
  const auto names = fused_names(src);
  EXPECT_EQ(names.count("CVT_I16_I32+MADD_I32"), 1u);
  EXPECT_EQ(names.count("LDXN2+CVT_I16_I32"), 1u);  // the second: INT_TO_DINT(a[i]) + u
  vmtest::VmRun p(src, no_coverage(), "euse.st");
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan());
  EXPECT_EQ(p.get("P.s"), 31 * (1 - 2 + 3 - 4 + 5 - 6 + 7 - 8));
  EXPECT_EQ(p.get("P.u"), -4);
  size_t fused_cvt = 0;
  for (const auto& [pc, name] : p.m->superinstructions()) fused_cvt += name == "LDXN2+CVT_I16_I32";
  EXPECT_EQ(fused_cvt, 1u);
}

}  // namespace
}  // namespace plcfi::st
