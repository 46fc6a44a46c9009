// Rule 27: the array elements an IF or ELSIF condition compared stay in the temporaries
// they were loaded into, for the code the condition's jump leads to (the next ELSIF's
// condition, the ELSE's first assignment) and falls into (the arm's first assignment),
// instead of being loaded again (compared_elements, CompileOptions::elsif_reuse). The
// programs here run with and without the rule, and in both tiers, and must agree scan by
// scan; the listings show which loads are gone and which must stay.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::occurrences;
using vmtest::VmRun;

CompileOptions reuse(bool on) {
  CompileOptions o;
  o.elsif_reuse = on;
  return o;
}

// Three-way compares, binary search, running extremes, ELSIF chains on one element,
// compares of two elements, ELSE arms that read the element; arms that write the element
// or its index before reading it again; elements of every size, fields of structures, a
// rank-2 array. An LCG draws the data each scan.
const char* const kHeld = R"(
TYPE Rec : STRUCT tag : DINT; zone : INT; level : REAL; on : BOOL; END_STRUCT; END_TYPE
PROGRAM P
  VAR
    seed : UDINT := 2463534;
    r : UDINT;
    k : DINT; i : DINT; lo : DINT; hi : DINT; mid : DINT; want : DINT;
    a : ARRAY [0..31] OF DINT;
    s : ARRAY [1..16] OF INT;
    bt : ARRAY [0..15] OF BYTE;
    lr : ARRAY [0..7] OF LREAL;
    f : ARRAY [0..15] OF BOOL;
    recs : ARRAY [0..15] OF Rec;
    m2 : ARRAY [0..3, 0..3] OF DINT;
    top : DINT := 0; low : DINT := 0; hits : DINT := 0; pos : DINT := 0;
    stop : INT := 0; bucket : DINT := 0; bsum : DINT := 0;
    lmax : LREAL := 0.0; peak : REAL := 0.0; ons : DINT := 0;
    sw : DINT := 0; cell : DINT := 0; z : INT := 3; x : INT := 0;
    n1 : DINT := 0; n2 : DINT := 0; n3 : DINT := 0;
    sum : LINT := 0;
  END_VAR
  FOR k := 0 TO 31 DO
    seed := seed * 1664525 + 1013904223;
    r := SHR(seed, 9);
    a[k] := UDINT_TO_DINT(r MOD 2000) - 1000;
  END_FOR;
  FOR k := 1 TO 16 DO
    seed := seed * 1664525 + 1013904223;
    s[k] := UDINT_TO_INT(SHR(seed, 13) MOD 600) - 300;
    bt[k - 1] := UDINT_TO_BYTE(SHR(seed, 5));
    f[k - 1] := (seed AND 16#400) <> 0;
    recs[k - 1].tag := k * 7;
    recs[k - 1].zone := UDINT_TO_INT(SHR(seed, 3) MOD 5);
    recs[k - 1].level := UDINT_TO_REAL(SHR(seed, 11) MOD 1000) * 0.125;
    recs[k - 1].on := (seed AND 16#80) <> 0;
  END_FOR;
  FOR k := 0 TO 7 DO
    seed := seed * 1664525 + 1013904223;
    lr[k] := UDINT_TO_LREAL(SHR(seed, 7) MOD 100000) / 7.0;
    m2[k MOD 4, k / 2] := UDINT_TO_DINT(SHR(seed, 4) MOD 50);
  END_FOR;

  (* running extremes: the arm's first assignment reads the compared element *)
  FOR k := 0 TO 31 DO
    IF a[k] > top THEN
      top := a[k];
    ELSIF a[k] < low THEN
      low := a[k];
    END_IF;
  END_FOR;
  FOR k := 0 TO 7 DO
    IF lr[k] >= lmax THEN lmax := lr[k] * 0.5 + lmax * 0.5; END_IF;
  END_FOR;

  (* binary search over recs' tags, three-way compare on a field *)
  FOR k := 0 TO 7 DO
    seed := seed * 1664525 + 1013904223;
    want := UDINT_TO_DINT(SHR(seed, 10) MOD 120);
    lo := 0; hi := 15;
    WHILE lo <= hi DO
      mid := (lo + hi) / 2;
      IF recs[mid].tag = want THEN
        hits := hits + 1; pos := pos + mid; lo := hi + 1;
      ELSIF recs[mid].tag < want THEN
        lo := mid + 1;
      ELSE
        hi := mid - 1;
      END_IF;
    END_WHILE;
  END_FOR;

  (* an ELSIF chain on one INT element, an ELSE that assigns it on *)
  FOR i := 1 TO 16 DO
    IF s[i] < -200 THEN
      bucket := bucket + 1;
    ELSIF s[i] < -50 THEN
      bucket := bucket + 10;
    ELSIF s[i] <= 50 AND s[i] <> 0 THEN
      bucket := bucket + 100;
    ELSIF s[i] > 250 THEN
      stop := s[i];
    ELSE
      x := s[i] / 2;
      bsum := bsum + x;
    END_IF;
  END_FOR;

  (* two elements compared: both held, for the arm and for the ELSIF *)
  FOR k := 0 TO 14 DO
    IF recs[k].level > recs[k + 1].level THEN
      peak := recs[k].level - recs[k + 1].level + peak * 0.25;
    ELSIF recs[k].level = recs[k + 1].level THEN
      sw := sw + 1;
    END_IF;
  END_FOR;

  (* the arm writes the element (or moves the index) before it reads it again *)
  FOR k := 0 TO 15 DO
    IF bt[k] > 16#80 THEN
      bt[k] := bt[k] - 16#40;
      sum := sum + BYTE_TO_LINT(bt[k]);
    ELSIF bt[k] < 16#10 THEN
      i := k;
      bt[k] := bt[i] + 1;
    END_IF;
  END_FOR;
  i := 0;
  WHILE i < 31 DO
    IF a[i] > a[i + 1] THEN
      a[i] := a[i + 1];
      i := i + 2;
    ELSE
      i := i + 1;
    END_IF;
  END_WHILE;

  (* the condition or the assignment computes a value of its own before it reads the element *)
  FOR k := 0 TO 31 DO
    IF a[k] > 500 THEN
      n1 := n1 + 1;
    ELSIF k * 40 - 700 > a[k] THEN
      n2 := n2 + a[k];
    ELSE
      n3 := n3 + (k + 1) * 2 + a[k];
    END_IF;
  END_FOR;

  (* BOOL elements, a structure field compared with a variable, a rank-2 element *)
  FOR k := 0 TO 15 DO
    IF f[k] = recs[k].on THEN
      ons := ons + 1;
    ELSIF recs[k].zone = z THEN
      ons := ons + 100;
    END_IF;
  END_FOR;
  FOR k := 0 TO 3 DO
    IF m2[k, 3 - k] > 25 THEN
      cell := cell + m2[k, 3 - k];
    ELSIF m2[k, 3 - k] = 0 THEN
      cell := cell - 1;
    END_IF;
  END_FOR;

  sum := sum + n1 + n2 * 3 + n3 * 11 + top * 3 + low * 5 + hits * 7 + pos + stop + bucket + bsum + sw + ons + cell
         + LREAL_TO_LINT(lmax) + REAL_TO_LINT(peak * 16.0);
END_PROGRAM
)";

TEST(VmHeld, HeldElementsGiveWhatLoadsGive) {
  VmRun on(kHeld, reuse(true), "held.st");
  VmRun off(kHeld, reuse(false), "held.st");
  ASSERT_TRUE(on.ok() && off.ok());
  EXPECT_TRUE(on.b->app->elsif_reuse);
  EXPECT_FALSE(off.b->app->elsif_reuse);
  for (int s = 0; s < 300; ++s) {
    ASSERT_TRUE(on.scan()) << on.m->trap().message;
    ASSERT_TRUE(off.scan()) << off.m->trap().message;
    SCOPED_TRACE("scan " + std::to_string(s));
    for (const char* v : {"P.sum", "P.n1", "P.n2", "P.n3", "P.top", "P.low", "P.hits", "P.pos", "P.stop", "P.bucket", "P.bsum", "P.sw",
                          "P.ons", "P.cell", "P.x"})
      ASSERT_EQ(on.get(v), off.get(v)) << v;
    ASSERT_EQ(on.real("P.lmax"), off.real("P.lmax"));
    ASSERT_EQ(on.real("P.peak"), off.real("P.peak"));
    for (int k = 0; k < 16; ++k) ASSERT_EQ(on.get("P.bt[" + std::to_string(k) + "]"), off.get("P.bt[" + std::to_string(k) + "]"));
    for (int k = 0; k < 32; ++k) ASSERT_EQ(on.get("P.a[" + std::to_string(k) + "]"), off.get("P.a[" + std::to_string(k) + "]"));
  }
  // Every kind of IF above was taken both ways.
  EXPECT_GT(on.get("P.hits"), 0);
  EXPECT_GT(on.get("P.sw"), 0);
  EXPECT_NE(on.get("P.stop"), 0);
  EXPECT_GT(on.get("P.bsum"), 0);
  EXPECT_GT(on.get("P.n1"), 0);
  EXPECT_NE(on.get("P.n2"), 0);
  EXPECT_NE(on.get("P.n3"), 0);
  same_in_both_tiers("held.st", kHeld, 60, 0, nullptr, reuse(true));
}

TEST(VmHeld, TheLoadsThatAreGoneAndThoseThatStay) {
  const char* src = R"(
TYPE Rec : STRUCT tag : DINT; level : REAL; END_STRUCT; END_TYPE
PROGRAM P
  VAR
    recs : ARRAY [0..15] OF Rec;
    a : ARRAY [0..15] OF DINT;
    s : ARRAY [0..15] OF INT;
    i : DINT; want : DINT; lo : DINT; hi : DINT; top : DINT; n : DINT; big : DINT := 100000;
    peak : REAL;
  END_VAR
  (* gone: the ELSIF's tag, the arm's a[i] and level, the ELSE's a[i] *)
  IF recs[i].tag = want THEN lo := 1; ELSIF recs[i].tag < want THEN lo := 2; ELSE hi := 3; END_IF;
  IF a[i] > top THEN top := a[i]; ELSE n := a[i]; END_IF;
  IF recs[i].level > peak THEN peak := recs[i].level; END_IF;
  (* stay: a second statement, a converted element, an AND *)
  IF a[i] > top THEN top := 0; n := a[i]; END_IF;
  IF s[i] > big THEN n := s[i]; END_IF;
  IF a[i] > 0 AND a[i] < 9 THEN n := 1; ELSIF a[i] > 100 THEN n := 2; END_IF;
END_PROGRAM
)";
  VmRun on(src, reuse(true), "loads.st");
  VmRun off(src, reuse(false), "loads.st");
  ASSERT_TRUE(on.ok() && off.ok());
  const std::string with = on.disasm(), without = off.disasm();
  // DINT fields and elements (LDXS4: tag and level; LDX4: a[i]); INT elements (LDX2).
  EXPECT_EQ(occurrences(without, "LDXS4 "), 4u) << without;
  EXPECT_EQ(occurrences(with, "LDXS4 "), 2u) << with;  // the ELSIF's tag and the arm's level
  EXPECT_EQ(occurrences(without, "LDX4 "), 8u) << without;
  EXPECT_EQ(occurrences(with, "LDX4 "), 6u) << with;  // the arm's and the ELSE's a[i] gone
  EXPECT_EQ(occurrences(with, "LDX2 "), occurrences(without, "LDX2 ")) << with;
}

TEST(VmHeld, ALoadThatTrapsTrapsWhereItDid) {
  const char* src = R"(
PROGRAM P
  VAR a : ARRAY [0..3] OF DINT; i : DINT := 4; n : DINT; END_VAR
  IF a[i] > 0 THEN n := 1; ELSIF a[i] < 0 THEN n := 2; ELSE n := a[i]; END_IF;
END_PROGRAM
)";
  VmRun on(src, reuse(true), "trap.st");
  VmRun off(src, reuse(false), "trap.st");
  ASSERT_TRUE(on.ok() && off.ok());
  EXPECT_FALSE(on.scan());
  EXPECT_FALSE(off.scan());
  EXPECT_EQ(describe_trap(*on.b->app, on.m->trap()), describe_trap(*off.b->app, off.m->trap()));
  EXPECT_NE(describe_trap(*on.b->app, on.m->trap()).find("trap.st:4"), std::string::npos)
      << describe_trap(*on.b->app, on.m->trap());
}

TEST(VmHeld, ConditionsWithCallsLoadAgain) {
  // Bump changes a[0] through its VAR_IN_OUT: the ELSIF must read the new value.
  const char* src = R"(
FUNCTION Bump : BOOL
  VAR_IN_OUT v : DINT; END_VAR
  v := v + 10;
  Bump := TRUE;
END_FUNCTION
PROGRAM P
  VAR a : ARRAY [0..3] OF DINT := [5, 0, 0, 0]; i : DINT := 0; n : DINT := 0; END_VAR
  IF a[i] > 100 THEN
    n := 1;
  ELSIF Bump(a[i]) AND a[i] > 12 THEN
    n := a[i];
  END_IF;
END_PROGRAM
)";
  for (bool on : {true, false}) {
    VmRun p(src, reuse(on), "calls.st");
    ASSERT_TRUE(p.ok());
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    EXPECT_EQ(p.get("P.n"), 15);
  }
}

}  // namespace
}  // namespace plcfi::st
