// Loop tails: an IF or CASE that ends a loop body ends its arms with a copy of the loop's
// bottom (LOOPUP/LOOPDN, the WHILE or UNTIL test, then a jump to the exit) instead of a
// jump to the bottom. The program must compute what it computes with the jumps, in every
// loop form, with arms nested in arms, EXIT, conditions that call functions, and in both
// tiers; the watchdog must count the copied back edges as it counts the original.
#include <gtest/gtest.h>

#include <cctype>
#include <sstream>
#include <string>
#include <vector>

#include "engine.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

struct Prog : vmtest::VmRun {
  Prog(const std::string& src, bool tails) : VmRun(src, options(tails), "tails.st") {}
  static CompileOptions options(bool tails) {
    CompileOptions o;
    o.loop_tails = tails;
    o.flag_loops = false;  // the copies of the WHILE tests are the subject here (rule 28: test_vm_flag_loops.cpp)
    return o;
  }
};

using vmtest::occurrences;

const char* kTails = R"(FUNCTION Probe : BOOL
VAR_INPUT x : DINT; END_VAR
VAR_IN_OUT calls : DINT; END_VAR
calls := calls + 1;
Probe := x > 0;
END_FUNCTION

PROGRAM P
VAR
  crc : WORD := 16#FFFF;
  data : ARRAY [0..15] OF BYTE;
  i, j, n, state, calls, seed, s, t : DINT;
  moving : BOOL;
  a : ARRAY [0..19] OF DINT;
END_VAR
seed := (seed * 1103 + 12345) MOD 65521;
FOR i := 0 TO 15 DO
  data[i] := DINT_TO_BYTE(seed + i * 37);
END_FOR;
(* FOR up: IF/ELSE ending the body *)
FOR i := 0 TO 15 DO
  crc := crc XOR SHL(BYTE_TO_WORD(data[i]), 8);
  FOR j := 0 TO 7 DO
    IF (crc AND 16#8000) <> 16#0000 THEN
      crc := SHL(crc, 1) XOR 16#1021;
    ELSE
      crc := SHL(crc, 1);
    END_IF;
  END_FOR;
END_FOR;
(* FOR down by 2, IF/ELSIF/ELSE with a nested IF ending an arm, EXIT in an arm *)
s := 0;
FOR i := 19 TO 0 BY -2 DO
  IF i MOD 3 = 0 THEN
    s := s + i;
  ELSIF i MOD 3 = 1 THEN
    IF s > 40 THEN
      s := s - 1;
    ELSE
      s := s + 2;
    END_IF;
  ELSIF i = 5 AND seed MOD 2 = 0 THEN
    EXIT;
  ELSE
    s := s * 2;
  END_IF;
END_FOR;
(* WHILE with a flag: an insertion sort, the body an IF/ELSIF/ELSE *)
FOR i := 0 TO 19 DO
  a[i] := (seed * (i + 3)) MOD 97;
END_FOR;
FOR i := 1 TO 19 DO
  t := a[i];
  j := i;
  moving := TRUE;
  WHILE moving DO
    IF j = 0 THEN
      moving := FALSE;
    ELSIF a[j - 1] > t THEN
      a[j] := a[j - 1];
      j := j - 1;
    ELSE
      moving := FALSE;
    END_IF;
  END_WHILE;
  a[j] := t;
END_FOR;
(* WHILE whose condition calls a function: evaluated once per pass, as before *)
n := seed MOD 23 + 5;
WHILE Probe(n, calls) DO
  IF n MOD 2 = 0 THEN
    n := n / 2 - 1;
  ELSE
    n := n - 3;
  END_IF;
END_WHILE;
(* REPEAT with a CASE ending the body *)
state := 0;
t := 0;
REPEAT
  t := t + 1;
  CASE state OF
    0: state := 1;
    1: state := 2;
       s := s + t;
    2: state := 0;
  ELSE
    state := 0;
  END_CASE;
UNTIL t >= 10 + seed MOD 5
END_REPEAT;
END_PROGRAM
)";

TEST(VmTails, ArmsEndingALoopBodyRunTheLoopsBottomAndComputeTheSame) {
  Prog on(kTails, true), off(kTails, false);
  ASSERT_TRUE(on.ok());
  ASSERT_TRUE(off.ok());
  const std::string dis = on.disasm(), plain = off.disasm();
  // Copies: the CRC loop's LOOPUP (its THEN arm); the LOOPDN: the IF and both ELSIF
  // arms (the one with EXIT as well), and the THEN arm of the IF that ends the first
  // ELSIF arm; the WHILE tests (JMPT): the sort's ELSIF arm and the THEN arm of the loop
  // whose condition calls Probe; the UNTIL test: the three CASE arms (the ELSE falls to
  // the bottom). The sort's IF and ELSE arms end with `moving := FALSE`: there the test
  // of moving, which could not be taken, is left out (rule 23), in the IF arm's copy and
  // at the bottom, which only the ELSE arm reaches.
  EXPECT_EQ(occurrences(plain, " LOOPUP_I32") + 1, occurrences(dis, " LOOPUP_I32")) << dis;
  EXPECT_EQ(occurrences(plain, " LOOPDN_I32") + 4, occurrences(dis, " LOOPDN_I32")) << dis;
  EXPECT_EQ(occurrences(plain, " JMPT ") + 1, occurrences(dis, " JMPT ")) << dis;
  EXPECT_EQ(occurrences(plain, " CALL ") + 1, occurrences(dis, " CALL ")) << dis;  // Probe, in the copy of the test
  EXPECT_GT(occurrences(plain, " JMP "), 0u);
  for (int scan = 0; scan < 8; ++scan) {
    on.set("P.seed", scan * 7919);
    off.set("P.seed", scan * 7919);
    ASSERT_TRUE(on.scan()) << on.m->trap().message;
    ASSERT_TRUE(off.scan()) << off.m->trap().message;
    for (const char* v : {"P.crc", "P.s", "P.t", "P.n", "P.state", "P.calls", "P.a[0]", "P.a[7]", "P.a[19]"})
      EXPECT_EQ(off.get(v), on.get(v)) << v << " after scan " << scan;
  }
  // Sorted, by hand: every element no greater than the next.
  for (int k = 0; k < 19; ++k)
    EXPECT_LE(on.get("P.a[" + std::to_string(k) + "]"), on.get("P.a[" + std::to_string(k + 1) + "]")) << k;
}

TEST(VmTails, TheNativeTierComputesTheSame) {
  same_in_both_tiers("tails.st", kTails, 6, 0, [](Machine& m, int scan) {
    std::string err;
    auto h = resolve(m.app(), "P.seed", &err);
    ASSERT_TRUE(h.has_value()) << err;
    write_int(m, *h, scan * 7919);
  });
}

// A loop that never ends through its copied back edge traps on the watchdog, as the
// original does, after the same number of iterations.
TEST(VmTails, TheWatchdogCountsTheCopiedBackEdges) {
  const char* src = R"(PROGRAM P
VAR n, k : DINT; END_VAR
n := 0;
WHILE n >= 0 DO
  IF n MOD 2 = 0 THEN
    n := n + 2;
  ELSE
    n := n + 1;
  END_IF;
  k := k + 1;
  IF k < 1000000000 THEN
    n := n - 2;
  ELSE
    k := 0;
  END_IF;
END_WHILE;
END_PROGRAM
)";
  Prog on(src, true), off(src, false);
  ASSERT_TRUE(on.ok());
  ASSERT_TRUE(off.ok());
  on.m->set_budget(5000);
  off.m->set_budget(5000);
  EXPECT_FALSE(on.scan());
  EXPECT_FALSE(off.scan());
  EXPECT_EQ(TrapKind::Watchdog, on.m->trap().kind);
  EXPECT_EQ(off.m->trap().kind, on.m->trap().kind);
  EXPECT_EQ(off.get("P.k"), on.get("P.k"));
}

// An IF or CASE that one or two short assignments follow at the end of a loop body: its
// arms end with a copy of them and of the loop's bottom. Each assignment adds its own
// weight, so a copy that is missing, doubled or in the wrong arm changes the sums.
const char* kRest = R"(PROGRAM P
VAR
  n, steps, i, s, t, u, seed, state, k : DINT;
  w : WORD;
  odd : DINT;
  frame : ARRAY [0..31] OF BYTE;
END_VAR
(* WHILE: an IF/ELSE, then one assignment (Collatz) *)
n := seed MOD 1000 + 27;
steps := 0;
WHILE n <> 1 DO
  IF n MOD 2 = 0 THEN
    n := n / 2;
  ELSE
    n := 3 * n + 1;
  END_IF;
  steps := steps + 1;
END_WHILE;
(* FOR: an IF/ELSIF/ELSE, then two assignments, one to an element *)
w := 16#ACE1;
s := 0;
FOR i := 0 TO 31 DO
  IF (w AND 16#0001) <> 16#0000 THEN
    w := SHR(w, 1) XOR 16#B400;
  ELSIF (w AND 16#0002) <> 16#0000 THEN
    w := SHR(w, 1) XOR 16#0013;
  ELSE
    w := SHR(w, 1);
  END_IF;
  frame[(i * 5 + seed) MOD 32] := WORD_TO_BYTE(w XOR SHR(w, 5));
  s := s + WORD_TO_DINT(w AND 16#00FF) * (i + 1);
END_FOR;
(* REPEAT: a CASE, then one assignment, and the UNTIL test *)
state := 0;
t := 0;
u := 0;
REPEAT
  CASE state OF
    0: state := 1;
    1: state := 2; u := u + 100;
  ELSE
    state := 0;
  END_CASE;
  t := t + 1;
UNTIL t >= 10 + seed MOD 4
END_REPEAT;
(* an IF without ELSE: nothing to copy into (its arm falls through) *)
odd := 0;
FOR i := 0 TO 31 DO
  IF (BYTE_TO_DINT(frame[i]) MOD 3) = 0 THEN
    odd := odd + 1;
  END_IF;
  k := k + i;
END_FOR;
(* three statements after the IF: not copied *)
FOR i := 0 TO 3 DO
  IF i = 2 THEN k := k + 7; ELSE k := k - 1; END_IF;
  k := k + 1;
  k := k * 3;
  k := k MOD 100003;
END_FOR;
END_PROGRAM
)";

// The same sums computed here.
struct RestSums {
  int64_t steps = 0, s = 0, t = 0, u = 0, odd = 0, state = 0;
};
RestSums rest_by_hand(int64_t seed) {
  RestSums r;
  int64_t n = seed % 1000 + 27;
  while (n != 1) {
    n = n % 2 == 0 ? n / 2 : 3 * n + 1;
    ++r.steps;
  }
  uint16_t w = 0xACE1;
  uint8_t frame[32] = {};
  for (int i = 0; i < 32; ++i) {
    if (w & 1) w = static_cast<uint16_t>((w >> 1) ^ 0xB400);
    else if (w & 2) w = static_cast<uint16_t>((w >> 1) ^ 0x0013);
    else w = static_cast<uint16_t>(w >> 1);
    frame[(i * 5 + seed) % 32] = static_cast<uint8_t>(w ^ (w >> 5));
    r.s += (w & 0xFF) * (i + 1);
  }
  int64_t state = 0;
  do {
    if (state == 0) state = 1;
    else if (state == 1) { state = 2; r.u += 100; }
    else state = 0;
    ++r.t;
  } while (!(r.t >= 10 + seed % 4));
  r.state = state;
  for (uint8_t b : frame) r.odd += b % 3 == 0;
  return r;
}

TEST(VmTails, AssignmentsAfterTheLastIfAreCopiedIntoItsArms) {
  Prog on(kRest, true), off(kRest, false);
  ASSERT_TRUE(on.ok() && off.ok());
  EXPECT_TRUE(on.b->app->copied_statements);
  EXPECT_FALSE(off.b->app->copied_statements);
  const std::string dis = on.disasm(), plain = off.disasm();
  // steps := steps + 1 in the THEN arm; the element store and the sum in the THEN and
  // ELSIF arms; t := t + 1 in the two CASE arms before the ELSE. The IF without ELSE and
  // the IF that three statements follow keep one copy of what follows them.
  EXPECT_EQ(occurrences(plain, " STXN1 ") + occurrences(plain, " STX1 ") + 2,
            occurrences(dis, " STXN1 ") + occurrences(dis, " STX1 "))
      << dis;
  // The element's index i * 5 + seed and the sum's product, each in the two arms.
  EXPECT_EQ(occurrences(plain, " MUL_I32 ") + occurrences(plain, " MADD_I32 ") + 4,
            occurrences(dis, " MUL_I32 ") + occurrences(dis, " MADD_I32 "))
      << dis;
  EXPECT_EQ(occurrences(plain, "steps := steps + 1") + 1, occurrences(dis, "steps := steps + 1")) << dis;
  EXPECT_EQ(occurrences(plain, "t := t + 1") + 2, occurrences(dis, "t := t + 1")) << dis;
  EXPECT_EQ(occurrences(plain, "k := k + i"), occurrences(dis, "k := k + i")) << dis;
  EXPECT_EQ(occurrences(plain, "k := k MOD 100003"), occurrences(dis, "k := k MOD 100003")) << dis;
  for (int64_t seed : {0, 1, 7, 4242, 99991}) {
    on.set("P.seed", seed);
    off.set("P.seed", seed);
    ASSERT_TRUE(on.scan()) << on.m->trap().message;
    ASSERT_TRUE(off.scan()) << off.m->trap().message;
    const RestSums r = rest_by_hand(seed);
    for (Prog* p : {&on, &off}) {
      EXPECT_EQ(p->get("P.steps"), r.steps) << seed;
      EXPECT_EQ(p->get("P.s"), r.s) << seed;
      EXPECT_EQ(p->get("P.t"), r.t) << seed;
      EXPECT_EQ(p->get("P.u"), r.u) << seed;
      EXPECT_EQ(p->get("P.state"), r.state) << seed;
      EXPECT_EQ(p->get("P.odd"), r.odd) << seed;
    }
    for (const char* v : {"P.k", "P.w", "P.frame[0]", "P.frame[17]", "P.frame[31]"}) EXPECT_EQ(off.get(v), on.get(v)) << v;
  }
  same_in_both_tiers("tails.st", kRest, 3);
}

// Rule 23: a conditional jump on a BOOL variable that the instruction just before set to
// a constant, with no jump target between, is left out when it cannot be taken (the
// insertion sort of kTails: see the count of WHILE test copies above). Where the flag is
// set TRUE, where CONTINUE reaches the loop's test, and where an IF's other arms jump to
// its end, the test stays; every loop computes what it did.
const char* kFlags = R"(PROGRAM P
VAR
  k, n, m, seed : DINT;
  moving, done, again : BOOL;
END_VAR
(* a flag set TRUE at the end of a pass: the jump back stays *)
k := 0;
again := TRUE;
WHILE again DO
  k := k + 1;
  IF k >= 5 THEN again := FALSE; ELSE again := TRUE; END_IF;
END_WHILE;
(* CONTINUE reaches the test with the flag as it was *)
moving := TRUE;
n := 0;
WHILE moving DO
  n := n + 1;
  IF n < 3 THEN CONTINUE; END_IF;
  moving := FALSE;
END_WHILE;
(* an IF whose THEN arm jumps to its end, the ELSE arm clearing the flag before the test *)
done := FALSE;
m := 0;
REPEAT
  m := m + 1;
  IF m MOD 2 = 0 THEN
    done := m >= 6;
  ELSE
    done := FALSE;
  END_IF;
  seed := seed + 1;
UNTIL done
END_REPEAT;
END_PROGRAM
)";

TEST(VmTails, AJumpOnAFlagJustClearedIsLeftOut) {
  same_in_both_tiers("tails.st", kFlags, 3);
  // kTails's insertion sort, its two `moving := FALSE` arms without the test after them.
  Prog sorted(kTails, true);
  ASSERT_TRUE(sorted.ok());
  for (int scan = 0; scan < 3; ++scan) {
    sorted.set("P.seed", scan * 7919 + 1);
    ASSERT_TRUE(sorted.scan()) << sorted.m->trap().message;
    for (int i = 1; i < 20; ++i)
      EXPECT_LE(sorted.get("P.a[" + std::to_string(i - 1) + "]"), sorted.get("P.a[" + std::to_string(i) + "]")) << scan;
  }
  for (bool tails : {true, false}) {
    Prog p(kFlags, tails);
    ASSERT_TRUE(p.ok());
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    EXPECT_EQ(p.get("P.k"), 5);
    EXPECT_EQ(p.get("P.n"), 3);
    EXPECT_EQ(p.get("P.m"), 6);
  }
  // With loop tails, the loops here keep their jumps after the flag is set.
  Prog p(kFlags, true);
  ASSERT_TRUE(p.ok());
  const std::string dis = p.disasm();
  // The listing's instructions, each as its words (address, name, operands).
  std::vector<std::vector<std::string>> ins;
  std::istringstream lines(dis);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string x; words >> x;) w.push_back(x);
    if (w.size() >= 2 && std::isdigit(static_cast<unsigned char>(w[0][0]))) ins.push_back(w);
  }
  size_t cleared_then_tested = 0;  // MOV1 v, K followed by JMPT target, v
  for (size_t i = 0; i + 1 < ins.size(); ++i)
    if (ins[i][1] == "MOV1" && ins[i + 1][1] == "JMPT" && ins[i].size() == 4 && ins[i + 1].size() == 4 &&
        ins[i][2] == ins[i + 1][3])
      ++cleared_then_tested;
  // The two left: again := TRUE (taken) and moving := FALSE before the test CONTINUE
  // also reaches.
  EXPECT_EQ(cleared_then_tested, 2u) << dis;
}

}  // namespace
}  // namespace plcfi::st
