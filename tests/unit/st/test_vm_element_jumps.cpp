// Rule 20: a conditional jump on an array element (IF f[i] THEN, IF r[j - 1].key > x THEN,
// WHILE a[k] <> 0 DO) runs as one handler in the interpreter: the element load and the
// jump that reads what it loaded. Each case runs the interpreter against the native tier,
// which has no superinstructions (memory, coverage and traps after every scan), checks
// values by hand, and that the fused handlers were really used.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

// The names of the superinstructions the interpreter runs on `src` (after one scan).
std::set<std::string> fused_names(const std::string& src) {
  vmtest::VmRun p(src, {}, "ejump.st");
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
    fill += "    a_" + T + "[i] := TO_" + T + "(DINT_TO_BYTE((i * 37 + scan * 11) MOD 256));\n";
    fill += "    s_" + T + "[i].v := TO_" + T + "(DINT_TO_BYTE((i * 53 + scan * 7) MOD 256));\n";
    fill += "  END_FOR;\n";
    fill += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO m_" + T + "[i, j] := " + to +
            "(i * 29 + j * 61 + scan * 13) MOD 256 - 128); END_FOR; END_FOR;\n";
    fill += "  x_" + T + " := " + to + "(scan * 41 + 100) MOD 256 - 128);\n";
    for (const char* op : ops) {
      for (int order = 0; order < 2; ++order) {
        auto cond = [&](const std::string& e) {
          return order == 0 ? e + " " + op + " x_" + T : "x_" + T + " " + op + " " + e;
        };
        const std::string w = std::to_string(weight);
        body += "  IF " + cond("a_" + T + "[k]") + " THEN hits := hits + " + w + "; END_IF;\n";
        body += "  FOR i := 0 TO 7 DO IF " + cond("a_" + T + "[i]") + " THEN hits := hits + " + w + "; END_IF; END_FOR;\n";
        body += "  IF " + cond("s_" + T + "[k].v") + " THEN hits := hits + " + w + "; END_IF;\n";
        body += "  FOR i := 0 TO 7 DO IF " + cond("s_" + T + "[i].v") + " THEN hits := hits + " + w + "; END_IF; END_FOR;\n";
        body += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO IF " + cond("m_" + T + "[i, j]") + " THEN hits := hits + " + w +
                "; END_IF; END_FOR; END_FOR;\n";
        weight = weight * 3 % 1000 + 1;
      }
    }
    // Tests of bits: (e AND m) <> 0 and (e AND m) = 0 (JTZ, JTNZ).
    for (const char* rel : {"<> 0", "= 0"}) {
      for (int order = 0; order < 2; ++order) {
        auto cond = [&](const std::string& e) {
          return std::string("(") + (order == 0 ? e + " AND x_" + T : "x_" + T + " AND " + e) + ") " + rel;
        };
        const std::string w = std::to_string(weight);
        body += "  IF " + cond("a_" + T + "[k]") + " THEN hits := hits + " + w + "; END_IF;\n";
        body += "  FOR i := 0 TO 7 DO IF " + cond("a_" + T + "[i]") + " THEN hits := hits + " + w + "; END_IF; END_FOR;\n";
        body += "  IF " + cond("s_" + T + "[k].v") + " THEN hits := hits + " + w + "; END_IF;\n";
        body += "  FOR i := 0 TO 7 DO IF " + cond("s_" + T + "[i].v") + " THEN hits := hits + " + w + "; END_IF; END_FOR;\n";
        body += "  FOR i := 1 TO 2 DO FOR j := 0 TO 3 DO IF " + cond("m_" + T + "[i, j]") + " THEN hits := hits + " + w +
                "; END_IF; END_FOR; END_FOR;\n";
        weight = weight * 3 % 1000 + 1;
      }
    }
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
                  {}, "ejump.st");
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

// The fused handler applies only when the jump reads the slot the load wrote: a jump on
// another value after an element load stays two instructions and means the same.
TEST(VmElementJumps, OnlyWhenTheJumpReadsTheElement) {
  const std::string src = R"(
PROGRAM P
VAR a : ARRAY [0..3] OF INT := [3, 1, 4, 1]; i : DINT; b : BOOL; n : DINT; t : INT; END_VAR
FOR i := 0 TO 3 DO
  t := a[i];
  IF b THEN n := n + 1; END_IF;
  b := NOT b;
END_FOR;
END_PROGRAM
)";
  same_in_both_tiers("ejump.st", src, 3);
  for (const auto& name : fused_names(src)) EXPECT_EQ(name.find("LDXN2+J"), std::string::npos) << name;
}

}  // namespace
}  // namespace plcfi::st
