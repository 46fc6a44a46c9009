// An IF, WHILE or REPEAT condition that is an AND or OR chain becomes a chain of jumps when
// leaving out its later terms cannot be seen (cond_branch, CompileOptions::condition_jumps).
// The program checks itself: each condition is also computed as a value (an assignment,
// which evaluates every operand) and compared with where the jumps went. Both tiers, with
// the chains and without; the cases that must keep IEC's evaluation of every operand (a
// call, an index not yet checked, a division by a variable) are checked for it.
#include <gtest/gtest.h>

#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::occurrences;
using vmtest::VmRun;

CompileOptions with_chains(bool on) {
  CompileOptions o;
  o.condition_jumps = on;
  return o;
}

// Conditions over the four bits of `scan` (a, b, c, d) and over elements of an array of
// structures, in IF, ELSIF, WHILE and REPEAT; `bad` counts a jump that went another way
// than the value, `hits` sums a weight per condition that held.
const char* const kConditions = R"(
TYPE Tag : STRUCT zone : INT; alarm : BOOL; END_STRUCT; END_TYPE
PROGRAM P
  VAR
    scan : DINT := 0;
    a, b, c, d, v : BOOL;
    x, y, n : DINT;
    i : DINT;
    z : INT;
    tags : ARRAY [0..7] OF Tag;
    bad : DINT := 0;
    hits : DINT := 0;
  END_VAR
  a := (scan AND 1) <> 0;
  b := (scan AND 2) <> 0;
  c := (scan AND 4) <> 0;
  d := (scan AND 8) <> 0;
  x := scan MOD 5;
  y := scan MOD 3;

  v := a AND b;
  IF a AND b THEN hits := hits + 1; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := a OR b;
  IF a OR b THEN hits := hits + 2; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := a AND b AND c;
  IF a AND b AND c THEN hits := hits + 4; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := a OR b OR c OR d;
  IF a OR b OR c OR d THEN hits := hits + 8; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := (a AND b) OR (c AND d);
  IF (a AND b) OR (c AND d) THEN hits := hits + 16; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := (a OR b) AND NOT (c OR d);
  IF (a OR b) AND NOT (c OR d) THEN hits := hits + 32; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := a AND (b OR c) AND d;
  IF a AND (b OR c) AND d THEN hits := hits + 64; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := NOT a OR b AND c;
  IF NOT a OR b AND c THEN hits := hits + 128; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  v := x > 2 AND y < 2 OR x = 0;
  IF x > 2 AND y < 2 OR x = 0 THEN hits := hits + 256; IF NOT v THEN bad := bad + 1; END_IF;
  ELSIF v THEN bad := bad + 1; END_IF;

  (* an ELSIF chain: the first arm that holds *)
  IF a AND b AND c AND d THEN hits := hits + 512;
  ELSIF c OR d THEN hits := hits + 1024;
  ELSIF a AND NOT b THEN hits := hits + 2048;
  ELSE hits := hits + 4096;
  END_IF;

  (* loops: the test on entry and at the bottom *)
  n := 0;
  WHILE (a OR b) AND n < 3 DO n := n + 1; END_WHILE;
  IF (a OR b) <> (n = 3) OR (n <> 0 AND n <> 3) THEN bad := bad + 1; END_IF;
  n := 0;
  REPEAT n := n + 1; UNTIL (a AND b) OR n >= 3 END_REPEAT;
  IF (a AND b) <> (n = 1) THEN bad := bad + 1; END_IF;
  n := 0;
  WHILE n < 5 AND NOT (c AND n >= 2) DO n := n + 1; END_WHILE;
  IF n <> SEL(c, 5, 2) THEN bad := bad + 1; END_IF;

  (* elements: the second term's index was checked by the first *)
  FOR i := 0 TO 7 DO
    tags[i].zone := DINT_TO_INT((i + scan) MOD 3);
    tags[i].alarm := ((i * 7 + scan) MOD 4) = 0;
  END_FOR;
  z := DINT_TO_INT(scan MOD 3);
  i := 0;
  n := -1;
  WHILE i < 8 DO
    v := tags[i].zone = z AND tags[i].alarm;
    IF tags[i].zone = z AND tags[i].alarm THEN
      IF NOT v THEN bad := bad + 1; END_IF;
      n := i;
      i := 8;
    ELSE
      IF v THEN bad := bad + 1; END_IF;
      i := i + 1;
    END_IF;
  END_WHILE;
  hits := hits + 8192 * (n + 1);
  scan := scan + 1;
END_PROGRAM
)";

// The same sums computed here, scan by scan.
int64_t expected_hits(int scans) {
  int64_t hits = 0;
  for (int s = 0; s < scans; ++s) {
    const bool a = s & 1, b = s & 2, c = s & 4, d = s & 8;
    const int x = s % 5, y = s % 3;
    if (a && b) hits += 1;
    if (a || b) hits += 2;
    if (a && b && c) hits += 4;
    if (a || b || c || d) hits += 8;
    if ((a && b) || (c && d)) hits += 16;
    if ((a || b) && !(c || d)) hits += 32;
    if (a && (b || c) && d) hits += 64;
    if (!a || (b && c)) hits += 128;
    if ((x > 2 && y < 2) || x == 0) hits += 256;
    if (a && b && c && d) hits += 512;
    else if (c || d) hits += 1024;
    else if (a && !b) hits += 2048;
    else hits += 4096;
    int n = -1;
    for (int i = 0; i < 8; ++i)
      if ((i + s) % 3 == s % 3 && (i * 7 + s) % 4 == 0) {
        n = i;
        break;
      }
    hits += 8192 * (n + 1);
  }
  return hits;
}

TEST(VmConditionJumps, ChainsJumpAsTheValueSays) {
  for (bool chains : {true, false}) {
    VmRun p(kConditions, with_chains(chains), "cond.st");
    ASSERT_TRUE(p.ok());
    for (int s = 0; s < 32; ++s) ASSERT_TRUE(p.scan()) << p.m->trap().message;
    EXPECT_EQ(p.get("P.bad"), 0) << "chains " << chains;
    EXPECT_EQ(p.get("P.hits"), expected_hits(32)) << "chains " << chains;
  }
  same_in_both_tiers("cond.st", kConditions, 32, 0, nullptr, with_chains(true));
}

TEST(VmConditionJumps, TheConditionsAreChainsOfJumps) {
  // Each `v := ...` keeps its BAND or BOR (an assignment evaluates every operand); the
  // IF, WHILE and REPEAT conditions have none left.
  VmRun on(kConditions, with_chains(true), "cond.st");
  VmRun off(kConditions, with_chains(false), "cond.st");
  ASSERT_TRUE(on.ok() && off.ok());
  EXPECT_TRUE(on.b->app->condition_chains);
  EXPECT_FALSE(off.b->app->condition_chains);
  const std::string with = on.disasm(), without = off.disasm();
  const size_t assigned = occurrences(with, " BAND ") + occurrences(with, " BOR ");
  EXPECT_EQ(assigned, 23u) << with;
  EXPECT_GT(occurrences(without, " BAND ") + occurrences(without, " BOR "), assigned + 20) << without;
  // The element condition: two element loads, each followed by its jump.
  EXPECT_NE(with.find("LDXS2"), std::string::npos);
  EXPECT_NE(with.find("JNE_I16"), std::string::npos) << with;
}

// Runs one scan of src (compiled with chains) and returns the trap message ("" if none),
// with the value of P.calls in *calls.
std::string trap_of(const std::string& src, int64_t* calls = nullptr) {
  VmRun p(src, with_chains(true), "keep.st");
  if (!p.ok()) return "no build";
  const bool ok = p.scan();
  if (calls) *calls = p.get("P.calls");
  return ok ? "" : p.m->trap().message;
}

TEST(VmConditionJumps, OperandsThatCanBeSeenAreAllEvaluated) {
  // A call in a later term: its side effect happens whatever the first term says.
  const char* call = R"(
FUNCTION Bump : BOOL
  VAR_IN_OUT k : DINT; END_VAR
  k := k + 1;
  Bump := TRUE;
END_FUNCTION
PROGRAM P
  VAR off : BOOL := FALSE; on : BOOL := TRUE; calls : DINT := 0; r : DINT := 0; END_VAR
  IF off AND Bump(calls) THEN r := 1; END_IF;
  IF on OR Bump(calls) THEN r := r + 2; END_IF;
  WHILE off AND Bump(calls) DO r := 100; END_WHILE;
END_PROGRAM
)";
  int64_t calls = 0;
  EXPECT_EQ(trap_of(call, &calls), "");
  EXPECT_EQ(calls, 3);
  // An index the first term did not check, and a division by a variable, still fail.
  const char* index = R"(
PROGRAM P
  VAR off : BOOL := FALSE; a : ARRAY [0..7] OF DINT; i : DINT := 9; calls : DINT; END_VAR
  IF off AND a[i] > 0 THEN calls := 1; END_IF;
END_PROGRAM
)";
  EXPECT_NE(trap_of(index).find("index 9 outside 0..7"), std::string::npos) << trap_of(index);
  const char* other = R"(
PROGRAM P
  VAR off : BOOL := FALSE; a : ARRAY [0..7] OF DINT; b : ARRAY [0..9] OF DINT; i : DINT := 9; calls : DINT; END_VAR
  IF b[i] = 0 AND a[i] > 0 THEN calls := 1; END_IF;
END_PROGRAM
)";
  EXPECT_NE(trap_of(other).find("index 9 outside 0..7"), std::string::npos) << trap_of(other);
  const char* divide = R"(
PROGRAM P
  VAR off : BOOL := FALSE; k : DINT := 0; calls : DINT; END_VAR
  IF off AND 10 / k > 1 THEN calls := 1; END_IF;
END_PROGRAM
)";
  EXPECT_NE(trap_of(divide).find("division by zero"), std::string::npos) << trap_of(divide);
  // The same access in both terms: the first one fails, where the value would have.
  const char* same = R"(
PROGRAM P
  VAR a : ARRAY [0..7] OF DINT; i : DINT := 12; calls : DINT; END_VAR
  IF a[i] = 0 AND a[i] < 5 THEN calls := 1; END_IF;
END_PROGRAM
)";
  EXPECT_NE(trap_of(same).find("index 12 outside 0..7"), std::string::npos) << trap_of(same);
  // CODESYS: a property's getter is a call (here it counts its reads), a REFERENCE TO is
  // read through its address (here unbound: a null reference).
  CompileOptions codesys = with_chains(true);
  codesys.dialect = Dialect::Codesys;
  const char* property = R"(
FUNCTION_BLOCK Counted
  VAR_OUTPUT reads : DINT; END_VAR
  VAR v : BOOL := TRUE; END_VAR
PROPERTY Value : BOOL
GET
  reads := reads + 1;
  Value := v;
END_GET
END_PROPERTY
END_FUNCTION_BLOCK
PROGRAM P
  VAR off : BOOL := FALSE; c : Counted; calls : DINT; END_VAR
  IF off AND c.Value THEN calls := 100; END_IF;
  calls := calls + c.reads;
END_PROGRAM
)";
  {
    VmRun p(property, codesys, "keep.st");
    ASSERT_TRUE(p.ok());
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    EXPECT_EQ(p.get("P.calls"), 1);
  }
  const char* reference = R"(
PROGRAM P
  VAR off : BOOL := FALSE; r : REFERENCE TO DINT; calls : DINT; END_VAR
  IF off AND r > 0 THEN calls := 1; END_IF;
END_PROGRAM
)";
  {
    VmRun p(reference, codesys, "keep.st");
    ASSERT_TRUE(p.ok());
    EXPECT_FALSE(p.scan());
    EXPECT_EQ(p.m->trap().kind, TrapKind::NullReference) << p.m->trap().message;
  }
  // Those that can be seen stay values: their AND or OR is in the listing.
  for (const char* src : {call, index, other, divide}) {
    VmRun p(src, with_chains(true), "keep.st");
    ASSERT_TRUE(p.ok());
    const std::string dis = p.disasm();
    EXPECT_GT(occurrences(dis, " BAND ") + occurrences(dis, " BOR "), 0u) << dis;
  }
}

TEST(VmConditionJumps, TheWatchdogCountsOneBackEdgePerPass) {
  // A loop that never ends: the watchdog stops it after as many passes with the chain as
  // without (one jump back taken per pass, whichever term decides).
  const char* src = R"(
PROGRAM P
  VAR a : BOOL := TRUE; b : BOOL := FALSE; k : DINT := 0; calls : DINT; END_VAR
  k := 0;
  WHILE (a OR b) AND k >= 0 DO k := k + 1; END_WHILE;
END_PROGRAM
)";
  const char* repeat = R"(
PROGRAM P
  VAR a : BOOL := TRUE; b : BOOL := FALSE; k : DINT := 0; calls : DINT; END_VAR
  k := 0;
  REPEAT k := k + 1; UNTIL (b AND a) OR k < 0 END_REPEAT;
END_PROGRAM
)";
  for (const char* s : {src, repeat}) {
    for (uint64_t budget : {1u, 2u, 7u, 1000u}) {
      int64_t passes[2] = {0, 0};
      for (bool chains : {true, false}) {
        VmRun p(s, with_chains(chains), "dog.st");
        ASSERT_TRUE(p.ok());
        p.m->set_budget(budget);
        EXPECT_FALSE(p.scan());
        EXPECT_EQ(p.m->trap().kind, TrapKind::Watchdog);
        passes[chains] = p.get("P.k");
      }
      EXPECT_EQ(passes[0], passes[1]) << "budget " << budget;
      EXPECT_GT(passes[1], 0);
    }
    same_in_both_tiers("dog.st", s, 2, 50, nullptr, with_chains(true));
  }
}

// Long and deep conditions: a chain of 20,000 terms (one left spine), 120 levels of
// parentheses alternating AND and OR, NOT of NOT 100 times, 5,000 element terms proven by
// the first. They compile (no recursion along the spine) and compute what the values do.
TEST(VmConditionJumps, LongAndDeepConditions) {
  std::string chain = "a0";
  for (int i = 1; i < 20000; ++i) chain += " AND a" + std::to_string(i % 4);
  std::string deep = "a0";
  for (int i = 0; i < 120; ++i) deep = "(" + deep + (i % 2 ? " AND a" : " OR a") + std::to_string(i % 4) + ")";
  std::string nots;
  for (int i = 0; i < 101; ++i) nots += "NOT ";
  std::string elements = "t[i]";
  for (int i = 1; i < 5000; ++i) elements += " OR t[" + (i % 3 ? std::to_string(i % 8) : std::string("i")) + "]";
  const std::string src = "PROGRAM P\nVAR a0, a1, a2, a3 : BOOL; n, i : DINT; t : ARRAY [0..7] OF BOOL; END_VAR\n"
                          "n := 0;\nIF " + chain + " THEN n := n + 1; END_IF;\n"
                          "WHILE " + deep + " DO n := n + 10; a0 := NOT a0; a2 := FALSE; END_WHILE;\n"
                          "IF " + nots + "(a0 OR a1) THEN n := n + 100; END_IF;\n"
                          "IF " + elements + " THEN n := n + 1000; END_IF;\nEND_PROGRAM\n";
  VmRun on(src, with_chains(true), "deep.st"), off(src, with_chains(false), "deep.st");
  ASSERT_TRUE(on.ok() && off.ok());
  EXPECT_TRUE(on.b->app->condition_chains);
  for (int s = 0; s < 16; ++s) {
    for (VmRun* p : {&on, &off}) {
      for (int k = 0; k < 4; ++k) p->set("P.a" + std::to_string(k), (s >> k) & 1);
      p->set("P.i", s % 8);
      p->set("P.t[" + std::to_string((s * 3) % 8) + "]", s % 5 == 0);
      ASSERT_TRUE(p->scan()) << p->m->trap().message;
    }
    EXPECT_EQ(on.get("P.n"), off.get("P.n")) << "scan " << s;
  }
}

}  // namespace
}  // namespace plcfi::st
