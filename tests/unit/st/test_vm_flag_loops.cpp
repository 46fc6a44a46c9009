// Rule 28: an arm that ends the body of `WHILE flag DO` on a path that cannot have
// written the flag jumps back without testing it (the flag is TRUE where the body
// starts), through a copy of the body's first jump when that is a conditional jump on
// variables (CompileOptions::flag_loops, with loop_tails). A path that stores the flag,
// calls anything or stores through a pointer keeps the test. The programs run with and
// without the rule and in both tiers and must agree scan by scan; a loop that never ends
// traps on the watchdog after as many passes either way.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::occurrences;
using vmtest::VmRun;

CompileOptions flags(bool on) {
  CompileOptions o;
  o.flag_loops = on;
  return o;
}

// Flag loops of every kind the rule looks at, and the writes it must see: a store of the
// flag (a constant, a comparison retargeted to it), a function clearing it through its
// VAR_IN_OUT, a store through a reference, an inner loop clearing the outer flag, CASE
// arms. An LCG draws the data each scan.
const char* const kFlags = R"(
FUNCTION Nudge : DINT
  VAR_IN_OUT f : BOOL; END_VAR
  VAR_INPUT k : DINT; END_VAR
  IF k MOD 7 = 6 THEN f := FALSE; END_IF;
  Nudge := k + 1;
END_FUNCTION
PROGRAM P
  VAR
    seed : UDINT := 88172645;
    a : ARRAY [0..23] OF DINT;
    i : DINT; j : DINT; t : DINT; k : DINT; n : DINT;
    moving : BOOL; go : BOOL; outer : BOOL; inner : BOOL;
    pf : REF_TO BOOL;
    moves : DINT := 0; steps : DINT := 0; found : DINT := 0; rounds : DINT := 0;
    state : INT := 0; sum : LINT := 0;
  END_VAR
  FOR i := 0 TO 23 DO
    seed := seed * 1664525 + 1013904223;
    a[i] := UDINT_TO_DINT(SHR(seed, 12) MOD 1000);
  END_FOR;

  (* insertion sort: the shifting arm jumps back through a copy of IF j = 0 *)
  FOR i := 1 TO 23 DO
    t := a[i];
    j := i;
    moving := TRUE;
    WHILE moving DO
      IF j = 0 THEN
        moving := FALSE;
      ELSIF a[j - 1] > t THEN
        a[j] := a[j - 1];
        j := j - 1;
        moves := moves + 1;
      ELSE
        moving := FALSE;
      END_IF;
    END_WHILE;
    a[j] := t;
  END_FOR;

  (* the flag cleared by a call, through a reference, by a comparison stored into it *)
  go := TRUE; k := UDINT_TO_DINT(seed MOD 5);
  WHILE go DO
    IF k > 40 THEN
      go := FALSE;
    ELSE
      k := Nudge(f := go, k := k);
    END_IF;
  END_WHILE;
  steps := steps + k;
  pf := REF(go);
  go := TRUE; k := UDINT_TO_DINT(seed MOD 9);
  WHILE go DO
    IF k > 1000 THEN
      go := FALSE;
    ELSE
      pf^ := k < 30;
      k := k + 3;
    END_IF;
  END_WHILE;
  steps := steps + k * 10;
  go := TRUE; k := 0;
  WHILE go DO
    IF k > 1000 THEN
      go := FALSE;
    ELSE
      k := k + 1;
      go := a[k MOD 24] < 900;
    END_IF;
  END_WHILE;
  found := found + k;

  (* nested: the inner loop clears the outer flag on some passes *)
  outer := TRUE; n := 0;
  WHILE outer DO
    inner := TRUE; k := 0;
    WHILE inner DO
      IF k >= 5 THEN
        inner := FALSE;
      ELSIF a[n * 3 + k] > 700 THEN
        outer := FALSE;
        k := k + 1;
      ELSE
        k := k + 1;
      END_IF;
    END_WHILE;
    IF n >= 5 THEN
      outer := FALSE;
    ELSE
      n := n + 1;
      rounds := rounds + k;
    END_IF;
  END_WHILE;
  rounds := rounds + n * 100;

  (* CASE arms, one of them clearing the flag *)
  go := TRUE; k := 0;
  WHILE go DO
    CASE state OF
      0: state := 1; k := k + 1;
      1: IF a[k] > 500 THEN state := 2; END_IF; k := k + 2;
      2: go := k < 10; state := 0;
    ELSE
      state := 0;
    END_CASE;
  END_WHILE;
  found := found + k * 1000 + state;

  FOR i := 0 TO 23 DO sum := sum * 3 + a[i]; END_FOR;
  sum := sum + moves + steps + found + rounds;
END_PROGRAM
)";

TEST(VmFlagLoops, JumpingBackWithoutTheTestComputesTheSame) {
  vmtest::same_scan_by_scan(kFlags, flags(true), flags(false), 200,
                            {"P.sum", "P.moves", "P.steps", "P.found", "P.rounds", "P.state", "P.n"});
  VmRun on(kFlags, flags(true), "flags.st");
  ASSERT_TRUE(on.ok());
  for (int s = 0; s < 200; ++s) ASSERT_TRUE(on.scan()) << on.m->trap().message;
  for (int k = 0; k < 23; ++k)
    EXPECT_LE(on.get("P.a[" + std::to_string(k) + "]"), on.get("P.a[" + std::to_string(k + 1) + "]")) << k;
  same_in_both_tiers("flags.st", kFlags, 40, 0, nullptr, flags(true));
}

TEST(VmFlagLoops, OnlyThePathsThatCannotWriteTheFlagLoseTheTest) {
  VmRun on(kFlags, flags(true), "flags.st");
  VmRun off(kFlags, flags(false), "flags.st");
  ASSERT_TRUE(on.ok() && off.ok());
  const std::string with = on.disasm(), without = off.disasm();
  // Without: a JMPT per arm that ends a loop body and per loop bottom. With, six jump
  // back: the sort's shifting arm; the inner loop's ELSIF arm (it stores outer, not
  // inner) and its ELSE (at the bottom); the CASE loop's arms 0, 1 and ELSE. Five keep
  // their test: the loops whose arms call Nudge, store through pf or store a comparison
  // into go; the outer loop's ELSE (the inner loop before it may have stored outer); the
  // CASE's arm 2.
  EXPECT_EQ(occurrences(without, " JMPB "), 0u) << without;
  EXPECT_EQ(occurrences(with, " JMPB "), 6u) << with;
  EXPECT_EQ(occurrences(with, " JMPT "), 5u) << with;
  EXPECT_EQ(occurrences(without, " JMPT "), 11u) << without;
  // The sort's arm: the copy of `IF j = 0` (JNE) goes back to the ELSIF's test; the
  // inner loop's arms: copies of `IF k >= 5` (JLT).
  EXPECT_EQ(occurrences(with, " JNE_I32 "), occurrences(without, " JNE_I32 ") + 1) << with;
  EXPECT_EQ(occurrences(with, " JLT_I32 "), occurrences(without, " JLT_I32 ") + 2) << with;
}

TEST(VmFlagLoops, ALoopThatNeverEndsTrapsAfterAsManyPasses) {
  const char* src = R"(
PROGRAM P
  VAR go : BOOL := TRUE; k : DINT := 0; n : DINT := 0; END_VAR
  WHILE go DO
    IF k < 0 THEN
      go := FALSE;
    ELSE
      k := k + 1;
    END_IF;
  END_WHILE;
END_PROGRAM
)";
  vmtest::traps_after_as_many_passes(src, flags(true), flags(false), 5000, "P.k", 5001);
}

// Flag loops nested `depth` deep, each ended by an IF in its own body: the innermost
// counts k, loop i stops once k > i.
std::string nested_flags(int depth) {
  std::string src = "PROGRAM P\nVAR\n";
  for (int i = 0; i < depth; ++i) src += "  f" + std::to_string(i) + " : BOOL := TRUE;\n";
  src += "  k : DINT := 0;\nEND_VAR\n";
  for (int i = 0; i < depth; ++i) src += "WHILE f" + std::to_string(i) + " DO\n";
  src += "k := k + 1;\n";
  for (int i = depth - 1; i >= 0; --i)
    src += "IF k > " + std::to_string(i) + " THEN f" + std::to_string(i) + " := FALSE; END_IF;\nEND_WHILE;\n";
  return src + "END_PROGRAM\n";
}

TEST(VmFlagLoops, DeepNestsRunOrEndInTheNestingError) {
  const std::string deep = nested_flags(120);
  for (bool on : {true, false}) {
    VmRun p(deep, flags(on), "deep.st");
    ASSERT_TRUE(p.ok());
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    EXPECT_EQ(p.get("P.k"), 120) << (on ? "with the rule" : "without");
  }
  same_in_both_tiers("deep.st", deep, 2, 0, nullptr, flags(true));
  auto b = build_sources({{"deeper.st", nested_flags(200)}}, flags(true));
  EXPECT_FALSE(b->ok());
  EXPECT_NE(b->diags.render_all().find("ST117"), std::string::npos) << b->diags.render_all();
}


// A flag loop that ends: the watchdog's count of its passes is the plain loop's, to the
// pass. The shortest budget that lets a scan finish is the same with and without the
// rule, and one less traps. (The THEN arm's jump back copies `IF k < n`, whose jump leads
// forward to the ELSE: a copy of it taken there once skipped the count of a pass.)
TEST(VmFlagLoops, AFiniteLoopNeedsTheSameBudgetToTheLastPass) {
  const char* src = R"(
PROGRAM P
  VAR go : BOOL; k : DINT; n : DINT := 37; m : DINT; END_VAR
  go := TRUE;
  k := 0;
  WHILE go DO
    IF k < n THEN
      k := k + 1;
    ELSE
      go := FALSE;
    END_IF;
  END_WHILE;
  go := TRUE;
  WHILE go DO
    IF m >= 5 THEN
      go := FALSE;
    ELSIF k > 0 THEN
      k := k - 2;
    ELSE
      m := m + 1;
    END_IF;
  END_WHILE;
  m := 0;
END_PROGRAM
)";
  auto least = [&](const CompileOptions& o) {
    for (int64_t b = 1; b < 1000; ++b) {
      VmRun p(src, o, "ends.st");
      if (!p.ok()) return int64_t{-1};
      p.m->set_budget(b);
      if (p.scan()) return b;
    }
    return int64_t{-1};
  };
  auto opts = [](bool flag_loops, bool cold_arms) {
    CompileOptions o = flags(flag_loops);
    o.coverage = false;  // as `plcfi run` compiles (rule 29 is off with coverage)
    o.cold_arms = cold_arms;
    return o;
  };
  const int64_t plain = least(opts(false, false));
  ASSERT_GT(plain, 40);
  EXPECT_EQ(least(opts(true, false)), plain);
  EXPECT_EQ(least(opts(true, true)), plain);
  EXPECT_EQ(least(flags(true)), least(flags(false)));
}

}  // namespace
}  // namespace plcfi::st
