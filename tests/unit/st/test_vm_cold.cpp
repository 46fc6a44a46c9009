// Rule 29: in the IF that ends a loop body, an arm that leaves the loop (EXIT, RETURN, or
// a literal assigned to a variable the WHILE or UNTIL condition reads) is placed after
// the other arms, its condition jumping there when it holds; an AND's later terms are
// tested there, with a copy of a short ELSE where they fail. The passes that stay in the
// loop run without a taken jump before the loop's own. The programs run with and without
// the rule and in both tiers and must agree scan by scan; the watchdog counts as many
// passes either way; a failing index traps at the same line.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::occurrences;
using vmtest::VmRun;

// As `plcfi run` compiles without --coverage (the rule is off with coverage).
CompileOptions cold(bool on) {
  CompileOptions o;
  o.coverage = false;
  o.cold_arms = on;
  return o;
}

// Search loops of every form the rule reorders, and two it leaves: an LCG draws the data
// each scan.
const char* const kCold = R"(
TYPE Tag : STRUCT v : DINT; on : BOOL; END_STRUCT; END_TYPE
FUNCTION Find : INT
  VAR_INPUT x : DINT; END_VAR
  VAR_IN_OUT arr : ARRAY [0..23] OF DINT; END_VAR
  VAR j : INT; END_VAR
  Find := -1;
  FOR j := 0 TO 23 DO
    IF arr[j] = x THEN
      Find := j;
      RETURN;
    END_IF;
  END_FOR;
END_FUNCTION
PROGRAM P
  VAR
    seed : UDINT := 2463534242;
    a : ARRAY [0..23] OF DINT;
    b : ARRAY [0..23] OF BOOL;
    tags : ARRAY [0..23] OF Tag;
    srt : ARRAY [0..23] OF DINT;
    lo : DINT; hi : DINT; mid : DINT; bs : DINT; want2 : DINT;
    i : DINT; k : DINT; j : DINT; n : DINT;
    want : DINT; pos : DINT; hit : DINT; first : DINT; low : DINT; cnt : DINT;
    big : DINT; small : DINT; steps : DINT; where : INT;
    found : BOOL; done : BOOL; moving : BOOL; go : BOOL;
    r : REAL; lim : REAL := 100.0; zero : REAL := 0.0; q : REAL;
    sum : LINT := 0;
  END_VAR
  FOR i := 0 TO 23 DO
    seed := seed XOR SHL(seed, 13);
    seed := seed XOR SHR(seed, 17);
    seed := seed XOR SHL(seed, 5);
    a[i] := UDINT_TO_DINT(seed MOD 1000);
    b[i] := (seed AND 16#100) <> 0;
    tags[i].v := a[i];
    tags[i].on := b[i];
    srt[i] := i * 41 + 3;
  END_FOR;
  want := a[UDINT_TO_DINT(seed MOD 32) MOD 24] + UDINT_TO_DINT(seed MOD 2);

  (* a sentinel: the found arm sets the counter past the bound *)
  pos := -1;
  i := 0;
  WHILE i < 24 DO
    IF a[i] = want THEN
      pos := i;
      i := 24;
    ELSE
      i := i + 1;
    END_IF;
  END_WHILE;

  (* a flag in an AND condition, the IF followed by a short statement, no ELSE *)
  found := FALSE;
  hit := -1;
  i := 0;
  WHILE NOT found AND i < 24 DO
    IF tags[i].v > 500 AND tags[i].on THEN
      found := TRUE;
      hit := i;
    END_IF;
    i := i + 1;
  END_WHILE;

  (* an AND with a short ELSE: its copy runs where the second term fails *)
  first := -1;
  cnt := 0;
  i := 0;
  WHILE i < 24 DO
    IF tags[i].v > 300 AND NOT tags[i].on AND tags[i].v < 900 THEN
      first := i;
      i := 99;
    ELSE
      i := i + 1;
      cnt := cnt + 1;
    END_IF;
  END_WHILE;

  (* a binary search: the found arm makes lo pass hi; the ELSIF reads the element the IF
     loaded (rule 27) *)
  want2 := UDINT_TO_DINT(seed MOD 24) * 41 + 3 + UDINT_TO_DINT(SHR(seed, 5) MOD 2);
  lo := 0;
  hi := 23;
  bs := -1;
  WHILE lo <= hi DO
    mid := (lo + hi) / 2;
    IF srt[mid] = want2 THEN
      bs := mid;
      lo := hi + 1;
    ELSIF srt[mid] < want2 THEN
      lo := mid + 1;
    ELSE
      hi := mid - 1;
    END_IF;
  END_WHILE;

  (* EXIT, in the first arm and in a middle one *)
  low := -1;
  FOR i := 0 TO 23 DO
    IF a[i] < 100 THEN
      low := i;
      EXIT;
    END_IF;
    cnt := cnt + a[i] MOD 3;
  END_FOR;
  FOR i := 0 TO 23 DO
    IF a[i] > 900 THEN
      big := big + 1;
    ELSIF a[i] < 20 THEN
      EXIT;
    ELSE
      small := small + 1;
    END_IF;
  END_FOR;

  (* REPEAT with its flag, a nested IF inside the arm that stays *)
  k := 0;
  done := FALSE;
  REPEAT
    IF a[k] MOD 7 = 0 THEN
      done := TRUE;
    ELSE
      k := k + 1;
      IF k >= 24 THEN
        k := -1;
        done := TRUE;
      END_IF;
    END_IF;
  UNTIL done
  END_REPEAT;

  (* a flag loop (rule 28): the leaving arm first, the jump back through the opposite
     of its test; a REAL test, and a NaN that fails both < and >= *)
  moving := TRUE;
  j := UDINT_TO_DINT(seed MOD 9);
  WHILE moving DO
    IF j = 0 THEN
      moving := FALSE;
    ELSE
      j := j - 1;
      steps := steps + 1;
    END_IF;
  END_WHILE;
  go := TRUE;
  r := UDINT_TO_REAL(seed MOD 50);
  WHILE go DO
    IF r >= lim THEN
      go := FALSE;
    ELSE
      r := r * 1.5 + 1.0;
      steps := steps + 1;
    END_IF;
  END_WHILE;
  go := TRUE;
  q := zero / zero;
  n := 0;
  WHILE go DO
    IF q < zero THEN
      go := FALSE;
    ELSE
      n := n + 1;
      IF n > UDINT_TO_DINT(seed MOD 20) THEN q := -1.0; END_IF;
    END_IF;
  END_WHILE;

  (* left as written: an ELSE that leaves too (it would jump instead) *)
  moving := TRUE;
  j := 23;
  WHILE moving DO
    IF j = 0 THEN
      moving := FALSE;
    ELSIF a[j] > a[j - 1] THEN
      j := j - 1;
    ELSE
      moving := FALSE;
    END_IF;
  END_WHILE;

  where := Find(x := want, arr := a);
  sum := sum * 7 + pos * 3 + hit * 5 + first * 11 + low * 13 + cnt + big * 17 + small * 19 + k * 23 + steps
         + n * 29 + j * 31 + where * 37 + REAL_TO_LINT(r) + bs * 41;
END_PROGRAM
)";

TEST(VmColdArms, ArmsThatLeaveTheLoopPlacedLastComputeTheSame) {
  VmRun on(kCold, cold(true), "cold.st");
  VmRun off(kCold, cold(false), "cold.st");
  ASSERT_TRUE(on.ok() && off.ok());
  EXPECT_TRUE(on.b->app->cold_arms);
  EXPECT_FALSE(off.b->app->cold_arms);
  vmtest::same_scan_by_scan(kCold, cold(true), cold(false), 300,
                            {"P.sum", "P.pos", "P.hit", "P.first", "P.low", "P.cnt", "P.big", "P.small", "P.k", "P.steps",
                             "P.n", "P.j", "P.where", "P.i", "P.bs", "P.lo", "P.hi"});
  same_in_both_tiers("cold.st", kCold, 60, 0, nullptr, cold(true));
}

TEST(VmColdArms, TheListingShowsTheStayingArmFirst) {
  const char* src = R"(
PROGRAM P
  VAR a : ARRAY [0..9] OF DINT; b : ARRAY [0..9] OF BOOL; i : DINT; pos : DINT; want : DINT; END_VAR
  i := 0;
  WHILE i < 10 DO
    IF a[i] = want THEN
      pos := i;
      i := 10;
    ELSE
      i := i + 1;
    END_IF;
  END_WHILE;
  i := 0;
  WHILE i < 10 DO
    IF a[i] = want AND a[i] < 500 THEN
      pos := i;
      i := 10;
    ELSE
      i := i + 2;
    END_IF;
  END_WHILE;
END_PROGRAM
)";
  VmRun on(src, cold(true), "layout.st");
  VmRun off(src, cold(false), "layout.st");
  ASSERT_TRUE(on.ok() && off.ok());
  const std::string with = on.disasm(), without = off.disasm();
  // Without: each IF jumps over its found arm when the element differs (JNE). With: it
  // jumps to the found arm when it is equal (JEQ), and i := i + 1 comes before pos := i.
  EXPECT_EQ(occurrences(without, " JNE_I32 "), 2u) << without;
  EXPECT_EQ(occurrences(with, " JNE_I32 "), 0u) << with;
  EXPECT_EQ(occurrences(with, " JEQ_I32 "), 2u) << with;
  const auto first_loop = with.substr(0, with.find("i := 0;", with.find("i := 0;") + 1));
  EXPECT_LT(first_loop.find("ADD_I32"), first_loop.find("pos := i")) << with;
  // The AND (its second term reads the element the first proved): a[i] < 500 is tested
  // at the found arm (JGE to the copy of the ELSE), and i := i + 2 is there twice.
  EXPECT_EQ(occurrences(without, " JGE_I32 "), occurrences(with, " JGE_I32 ")) << with;
  EXPECT_EQ(occurrences(with, " ADD_I32 "), occurrences(without, " ADD_I32 ") + 1) << with;
}

TEST(VmColdArms, TheWatchdogAndTrapsSeeTheSamePasses) {
  // Never found: the loop runs until the watchdog stops it, after as many passes.
  const char* forever = R"(
PROGRAM P
  VAR a : ARRAY [0..3] OF DINT; i : DINT := 0; k : DINT := 0; END_VAR
  WHILE i < 4 DO
    IF a[k MOD 4] = 99 THEN
      i := 4;
    ELSE
      k := k + 1;
    END_IF;
  END_WHILE;
END_PROGRAM
)";
  vmtest::traps_after_as_many_passes(forever, cold(true), cold(false), 3000, "P.k", 3001);
  // The search runs past the array: the element's index check traps at the IF's line,
  // with the same passes done.
  const char* past = R"(
PROGRAM P
  VAR a : ARRAY [0..9] OF DINT; b : ARRAY [0..19] OF BOOL; i : DINT := 0; n : DINT := 0; END_VAR
  WHILE i < 20 DO
    IF a[i] = 5 AND b[i] THEN
      i := 20;
    ELSE
      i := i + 1;
      n := n + 1;
    END_IF;
  END_WHILE;
END_PROGRAM
)";
  std::string where[2];
  for (bool on : {true, false}) {
    VmRun p(past, cold(on), "past.st");
    ASSERT_TRUE(p.ok());
    EXPECT_FALSE(p.scan());
    EXPECT_EQ(p.get("P.n"), 10) << (on ? "with the rule" : "without");
    where[on] = p.m->trap().message + " @" + std::to_string(p.m->trap().loc.line);
    EXPECT_EQ(p.m->trap().loc.line, 5u) << where[on];
  }
  EXPECT_EQ(where[0], where[1]);
}


// Searches nested `depth` deep, each loop ended by an IF whose found arm sets its counter
// past the bound; the innermost condition an AND of `terms` comparisons of one element.
std::string nested_searches(int depth, int terms) {
  std::string src = "PROGRAM P\nVAR\n  a : ARRAY [0..3] OF DINT := [1, 2, 3, 4];\n  k : DINT := 0;\n";
  for (int i = 0; i < depth; ++i) src += "  i" + std::to_string(i) + " : DINT;\n";
  src += "END_VAR\n";
  for (int i = 0; i < depth; ++i) src += "i" + std::to_string(i) + " := 0;\nWHILE i" + std::to_string(i) + " < 2 DO\n";
  std::string cond = "a[k MOD 4] > 0";
  for (int t = 1; t < terms; ++t) cond += " AND a[k MOD 4] <> " + std::to_string(100 + t);
  src += "k := k + 1;\nIF " + cond + " AND k > 1000000 THEN i" + std::to_string(depth - 1) + " := 2; ELSE i" +
         std::to_string(depth - 1) + " := i" + std::to_string(depth - 1) + " + 1; END_IF;\nEND_WHILE;\n";
  for (int i = depth - 2; i >= 0; --i)
    src += "IF k < 0 THEN i" + std::to_string(i) + " := 2; ELSE i" + std::to_string(i) + " := i" + std::to_string(i) +
           " + 1; END_IF;\nEND_WHILE;\n";
  return src + "END_PROGRAM\n";
}

TEST(VmColdArms, DeepNestsAndLongConditionsRunOrEndInTheNestingError) {
  // 2 passes per level: k counts the innermost body's passes, 2^12.
  const std::string deep = nested_searches(12, 200);
  vmtest::same_scan_by_scan(deep, cold(true), cold(false), 2, {"P.k"});
  VmRun p(deep, cold(true), "deep.st");
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(p.get("P.k"), 4096);
  same_in_both_tiers("deep.st", deep, 1, 0, nullptr, cold(true));
  // A nest deeper than the parser takes: its error, not a crash.
  auto b = build_sources({{"deeper.st", nested_searches(200, 2)}}, cold(true));
  EXPECT_FALSE(b->ok());
  EXPECT_NE(b->diags.render_all().find("ST117"), std::string::npos) << b->diags.render_all();
}

}  // namespace
}  // namespace plcfi::st
