// Rule 30: a CASE whose selector is narrower than DINT (INT, UINT, SINT, USINT, BYTE, WORD,
// an enumerated type) compiles to a conversion into a DINT temporary and a jump table on
// it; the interpreter runs the two as one handler that jumps on the converted value. The
// selectors run through every label, below and above the table (ELSE), negative values
// and the type's extremes, in the interpreter and the native tier (which has no such
// handler), against values worked out by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::VmRun;

// Each CASE adds its arm's weight to a sum of its own; the selectors step through their
// ranges from scan to scan.
const char* const kCases = R"(
TYPE Mode : (M_OFF, M_RUN, M_HOLD, M_FAULT, M_SPARE); END_TYPE
PROGRAM P
  VAR
    n : DINT := 0;
    si : INT; su : UINT; ss : SINT; sb : BYTE; sw : WORD; su8 : USINT; m : Mode;
    ti : DINT := 0; tu : DINT := 0; ts : DINT := 0; tb : DINT := 0; tw : DINT := 0; tu8 : DINT := 0; tm : DINT := 0;
  END_VAR
  si := DINT_TO_INT(n MOD 13 - 6);            (* -6 .. 6 *)
  su := DINT_TO_UINT(n MOD 9) * 8191;        (* 0, 8191, .. 65528 *)
  ss := DINT_TO_SINT(n MOD 256 - 128);      (* -128 .. 127 *)
  sb := DINT_TO_BYTE(n MOD 256);
  sw := DINT_TO_WORD(n MOD 11 + 65530);      (* wraps past 65535 *)
  su8 := DINT_TO_USINT(n MOD 7 + 250);       (* 250 .. 255, 0 *)
  m := M_OFF;
  IF n MOD 5 = 1 THEN m := M_RUN; ELSIF n MOD 5 = 2 THEN m := M_HOLD; ELSIF n MOD 5 = 3 THEN m := M_FAULT;
  ELSIF n MOD 5 = 4 THEN m := M_SPARE; END_IF;
  CASE si OF
    -3: ti := ti + 1;
    -2, -1: ti := ti + 10;
    0: ti := ti + 100;
    1..2: ti := ti + 1000;
    3: ti := ti + 10000;
  ELSE
    ti := ti + 100000;
  END_CASE;
  CASE su OF
    0: tu := tu + 1;
    1, 2, 3: tu := tu + 10;
    4: tu := tu + 100;
  ELSE
    tu := tu + 1000;
  END_CASE;
  CASE ss OF
    -2: ts := ts + 1;
    -1..0: ts := ts + 10;
    1: ts := ts + 100;
    2..3: ts := ts + 1000;
  ELSE
    ts := ts + 10000;
  END_CASE;
  CASE sb OF
    0: tb := tb + 1;
    1..4: tb := tb + 10;
    5: tb := tb + 100;
    6, 7: tb := tb + 1000;
  ELSE
    tb := tb + 10000;
  END_CASE;
  CASE sw OF
    65530: tw := tw + 1;
    65531, 65532: tw := tw + 10;
    65533..65535: tw := tw + 100;
  ELSE
    tw := tw + 1000;
  END_CASE;
  CASE su8 OF
    250: tu8 := tu8 + 1;
    251..253: tu8 := tu8 + 10;
    254: tu8 := tu8 + 100;
  ELSE
    tu8 := tu8 + 1000;
  END_CASE;
  CASE m OF
    M_OFF: tm := tm + 1;
    M_RUN: tm := tm + 10;
    M_HOLD, M_FAULT: tm := tm + 100;
  ELSE
    tm := tm + 1000;
  END_CASE;
  n := n + 1;
END_PROGRAM
)";

// The same sums worked out in C++ for `scans` scans.
struct Sums {
  int64_t ti = 0, tu = 0, ts = 0, tb = 0, tw = 0, tu8 = 0, tm = 0;
};
Sums by_hand(int scans) {
  Sums s;
  for (int64_t n = 0; n < scans; ++n) {
    const int64_t si = n % 13 - 6;
    s.ti += si == -3 ? 1 : (si == -2 || si == -1) ? 10 : si == 0 ? 100 : (si == 1 || si == 2) ? 1000 : si == 3 ? 10000 : 100000;
    const int64_t su = static_cast<uint16_t>((n % 9) * 8191);
    s.tu += su == 0 ? 1 : (su >= 1 && su <= 3) ? 10 : su == 4 ? 100 : 1000;
    const int64_t ss = static_cast<int8_t>(n % 256 - 128);
    s.ts += ss == -2 ? 1 : (ss == -1 || ss == 0) ? 10 : ss == 1 ? 100 : (ss == 2 || ss == 3) ? 1000 : 10000;
    const int64_t sb = n % 256;
    s.tb += sb == 0 ? 1 : sb <= 4 ? 10 : sb == 5 ? 100 : sb <= 7 ? 1000 : 10000;
    const int64_t sw = static_cast<uint16_t>(n % 11 + 65530);
    s.tw += sw == 65530 ? 1 : (sw == 65531 || sw == 65532) ? 10 : sw >= 65533 ? 100 : 1000;
    const int64_t su8 = static_cast<uint8_t>(n % 7 + 250);
    s.tu8 += su8 == 250 ? 1 : (su8 >= 251 && su8 <= 253) ? 10 : su8 == 254 ? 100 : 1000;
    const int64_t m = n % 5;
    s.tm += m == 0 ? 1 : m == 1 ? 10 : (m == 2 || m == 3) ? 100 : 1000;
  }
  return s;
}

TEST(VmCaseSelectors, NarrowSelectorsJumpAsTheirValuesSay) {
  CompileOptions o;
  o.coverage = false;
  VmRun p(kCases, o, "cases.st");
  ASSERT_TRUE(p.ok());
  constexpr int kScans = 600;  // past every selector's range
  for (int k = 0; k < kScans; ++k) ASSERT_TRUE(p.scan()) << p.m->trap().message;
  const Sums want = by_hand(kScans);
  EXPECT_EQ(p.get("P.ti"), want.ti);
  EXPECT_EQ(p.get("P.tu"), want.tu);
  EXPECT_EQ(p.get("P.ts"), want.ts);
  EXPECT_EQ(p.get("P.tb"), want.tb);
  EXPECT_EQ(p.get("P.tw"), want.tw);
  EXPECT_EQ(p.get("P.tu8"), want.tu8);
  EXPECT_EQ(p.get("P.tm"), want.tm);
  // Each of the seven CASEs is one handler with its conversion (all their labels are
  // dense: one jump table each).
  size_t fused = 0;
  for (const auto& [pc, name] : p.m->superinstructions()) fused += name.ends_with("+JTAB");
  EXPECT_EQ(fused, 7u);
  same_in_both_tiers("cases.st", kCases, 300, 0, nullptr, o);
  // With coverage, each arm's bit is set where the table lands.
  VmRun c(kCases, {}, "cases.st");
  ASSERT_TRUE(c.ok());
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(c.scan());
  EXPECT_EQ(c.get("P.tm"), by_hand(20).tm);
}

}  // namespace
}  // namespace plcfi::st
