// Rule 26: an IF on a test of bits whose arms assign one variable values that only read
// variables and cannot fail is one select instruction (select_if, CompileOptions::
// if_selects; only without coverage). The programs here are checked against the same
// computation done in C++, scan by scan, with the selects and without, in both tiers; the
// IFs that must keep their jump (a call, a division by a variable, an index nobody
// checked, a comparison of magnitudes, ...) are checked for it and for IEC's evaluation.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::occurrences;
using vmtest::VmRun;

CompileOptions selects(bool on) {
  CompileOptions o;
  o.coverage = false;  // selects leave the arms nothing to mark
  o.if_selects = on;
  return o;
}

// Every form of bit test the rule takes, on every width, one-armed and two-armed, with
// values of every size: a 32-bit LCG draws the data each scan.
const char* const kBits = R"(
PROGRAM P
  VAR
    seed : UDINT := 12345;
    r : UDINT;
    b : BYTE; w : WORD; d : DWORD; l : LWORD;
    n : DINT; s : INT; q : LINT;
    flags : ARRAY [0..7] OF BOOL;
    k : DINT;
    f : BOOL;
    crc : WORD := 16#FFFF;
    lfsr : WORD := 16#ACE1;
    odd : DINT := 0;
    packed : WORD := 0;
    steps : DINT := 0;
    x : REAL := 1.5;
    y : LREAL := 0.25;
    t : TIME := T#1s;
    g : BOOL := FALSE;
    m : DINT := 0;
    e : DINT := 0;
    sum : LINT := 0;
  END_VAR
  seed := seed * 1103515245 + 12345;
  r := SHR(seed, 8);
  b := UDINT_TO_BYTE(r);
  w := UDINT_TO_WORD(r);
  d := UDINT_TO_DWORD(r);
  l := SHL(DWORD_TO_LWORD(d), 17) OR DWORD_TO_LWORD(d);
  n := UDINT_TO_DINT(r) - 8000000;
  s := DINT_TO_INT(n);
  q := DINT_TO_LINT(n) * 4099;
  FOR k := 0 TO 7 DO
    flags[k] := (SHR(r, k * 3) AND 1) <> 0;
  END_FOR;
  f := (r AND 16#100) = 0;

  (* CRC and LFSR steps: two-armed, (x AND K) <> 0 *)
  crc := crc XOR SHL(BYTE_TO_WORD(b), 8);
  FOR k := 0 TO 7 DO
    IF (crc AND 16#8000) <> 16#0000 THEN
      crc := SHL(crc, 1) XOR 16#1021;
    ELSE
      crc := SHL(crc, 1);
    END_IF;
  END_FOR;
  IF (lfsr AND 16#0001) <> 16#0000 THEN
    lfsr := SHR(lfsr, 1) XOR 16#B400;
  ELSE
    lfsr := SHR(lfsr, 1);
  END_IF;

  (* one-armed: a counter, bits packed from a BOOL array *)
  IF (d AND 16#40) <> 0 THEN odd := odd + 1; END_IF;
  IF (b AND 16#01) = 0 THEN odd := odd + 10; END_IF;
  packed := 0;
  FOR k := 0 TO 7 DO
    IF flags[k] THEN
      packed := packed OR SHL(WORD#1, k);
    END_IF;
  END_FOR;

  (* parity by MOD 2, on DINT and INT, and an even test *)
  IF n MOD 2 = 0 THEN steps := steps + n / 2; ELSE steps := steps - (3 * n + 1) / 4; END_IF;
  IF s MOD 2 <> 0 THEN steps := steps + 7; END_IF;
  IF n MOD 8 = 0 THEN steps := steps + 1000; END_IF;

  (* bits of LWORD and LINT, the top bit of a DWORD, a bit access, NOT of a BOOL *)
  IF (l AND 16#8000000000000000) <> 0 THEN sum := sum + 3; ELSE sum := sum - 1; END_IF;
  IF (q AND 16#0000000100000000) = 0 THEN sum := sum + DINT_TO_LINT(n); END_IF;
  IF (d AND 16#80000000) <> 0 THEN m := m + 1; END_IF;
  IF w.5 THEN m := m + 100; END_IF;
  IF NOT f THEN m := m + 10000; ELSE m := m - 3; END_IF;
  IF NOT NOT flags[2] THEN e := e + 1; END_IF;

  (* values of other types: REAL, LREAL, TIME, BOOL *)
  IF flags[0] THEN x := x * 1.25; ELSE x := x - 0.5; END_IF;
  IF flags[1] THEN y := y + 0.125; END_IF;
  IF (b AND 16#04) <> 0 THEN t := t + T#10ms; ELSE t := t - T#3ms; END_IF;
  IF (b AND 16#08) <> 0 THEN g := NOT g; END_IF;
END_PROGRAM
)";

struct Expected {
  uint16_t crc = 0xFFFF, lfsr = 0xACE1, packed = 0;
  int32_t odd = 0, steps = 0, m = 0, e = 0;
  int64_t sum = 0, t = 1000000000;  // ns
  float x = 1.5f;
  double y = 0.25;
  bool g = false;
};

Expected expected_bits(int scans) {
  Expected ex;
  uint32_t seed = 12345;
  for (int sc = 0; sc < scans; ++sc) {
    seed = seed * 1103515245u + 12345u;
    const uint32_t r = seed >> 8;
    const uint8_t b = static_cast<uint8_t>(r);
    const uint16_t w = static_cast<uint16_t>(r);
    const uint32_t d = r;
    const uint64_t l = (uint64_t{d} << 17) | d;
    const int32_t n = static_cast<int32_t>(r) - 8000000;
    const int16_t s = static_cast<int16_t>(n);
    const int64_t q = int64_t{n} * 4099;
    bool flags[8];
    for (int k = 0; k < 8; ++k) flags[k] = ((r >> (k * 3)) & 1) != 0;
    const bool f = (r & 0x100) == 0;
    ex.crc = static_cast<uint16_t>(ex.crc ^ (b << 8));
    for (int k = 0; k < 8; ++k)
      ex.crc = static_cast<uint16_t>((ex.crc & 0x8000) ? (ex.crc << 1) ^ 0x1021 : ex.crc << 1);
    ex.lfsr = static_cast<uint16_t>((ex.lfsr & 1) ? (ex.lfsr >> 1) ^ 0xB400 : ex.lfsr >> 1);
    if (d & 0x40) ex.odd += 1;
    if ((b & 1) == 0) ex.odd += 10;
    ex.packed = 0;
    for (int k = 0; k < 8; ++k)
      if (flags[k]) ex.packed = static_cast<uint16_t>(ex.packed | (1u << k));
    if (n % 2 == 0) ex.steps += n / 2;
    else ex.steps -= static_cast<int32_t>((3 * int64_t{n} + 1) / 4);
    if (s % 2 != 0) ex.steps += 7;
    if (n % 8 == 0) ex.steps += 1000;
    if (l & 0x8000000000000000ull) ex.sum += 3;
    else ex.sum -= 1;
    if ((q & 0x100000000ll) == 0) ex.sum += n;
    if (d & 0x80000000u) ex.m += 1;
    if (w & (1u << 5)) ex.m += 100;
    if (!f) ex.m += 10000;
    else ex.m -= 3;
    if (flags[2]) ex.e += 1;
    ex.x = flags[0] ? ex.x * 1.25f : ex.x - 0.5f;
    if (flags[1]) ex.y += 0.125;
    ex.t += (b & 4) ? 10000000 : -3000000;
    if (b & 8) ex.g = !ex.g;
  }
  return ex;
}

TEST(VmSelects, BitTestsSelectWhatTheJumpsChose) {
  constexpr int kScans = 200;
  const Expected ex = expected_bits(kScans);
  for (bool on : {true, false}) {
    VmRun p(kBits, selects(on), "bits.st");
    ASSERT_TRUE(p.ok());
    for (int s = 0; s < kScans; ++s) ASSERT_TRUE(p.scan()) << p.m->trap().message;
    SCOPED_TRACE(on ? "selects" : "jumps");
    EXPECT_EQ(p.get("P.crc"), ex.crc);
    EXPECT_EQ(p.get("P.lfsr"), ex.lfsr);
    EXPECT_EQ(p.get("P.packed"), ex.packed);
    EXPECT_EQ(p.get("P.odd"), ex.odd);
    EXPECT_EQ(p.get("P.steps"), ex.steps);
    EXPECT_EQ(p.get("P.sum"), ex.sum);
    EXPECT_EQ(p.get("P.m"), ex.m);
    EXPECT_EQ(p.get("P.e"), ex.e);
    EXPECT_EQ(p.get("P.t"), ex.t);
    EXPECT_EQ(p.get("P.g"), ex.g ? 1 : 0);
    EXPECT_EQ(static_cast<float>(p.real("P.x")), ex.x);
    EXPECT_EQ(p.real("P.y"), ex.y);
  }
  same_in_both_tiers("bits.st", kBits, 50, 0, nullptr, selects(true));
}

TEST(VmSelects, TheIfsOnBitsHaveNoJumpLeft) {
  VmRun on(kBits, selects(true), "bits.st");
  VmRun off(kBits, selects(false), "bits.st");
  CompileOptions covered = selects(true);
  covered.coverage = true;
  VmRun cov(kBits, covered, "bits.st");
  ASSERT_TRUE(on.ok() && off.ok() && cov.ok());
  EXPECT_TRUE(on.b->app->if_selects);
  EXPECT_FALSE(off.b->app->if_selects);
  EXPECT_FALSE(cov.b->app->if_selects);
  const std::string with = on.disasm();
  auto sels = [](const std::string& text) {
    return occurrences(text, " SEL1 ") + occurrences(text, " SEL2 ") + occurrences(text, " SEL4 ") +
           occurrences(text, " SEL8 ");
  };
  // 17 of the 18 IFs (`n MOD 8 = 0` from the comparison's value, the others from one
  // bit); `IF NOT f` tests a BOOL variable, a status, and keeps its jump.
  EXPECT_EQ(sels(with), 17u) << with;
  EXPECT_EQ(sels(off.disasm()), 0u);
  EXPECT_EQ(sels(cov.disasm()), 0u);
  // The parities are bit reads, not divisions.
  EXPECT_EQ(occurrences(with, "MODK_I32"), 1u) << with;  // n MOD 8
  EXPECT_EQ(occurrences(off.disasm(), "MODK_I32"), 2u);
  EXPECT_NE(with.find("SEL2 "), std::string::npos);
  EXPECT_NE(with.find("SEL8 "), std::string::npos);
  EXPECT_NE(with.find("SEL1 "), std::string::npos);
}

// One scan of src compiled with selects: the trap message ("" if none), P.calls in *calls
// and whether any IF became a select.
std::string trap_of(const std::string& src, int64_t* calls = nullptr, bool* selected = nullptr) {
  VmRun p(src, selects(true), "keep.st");
  if (!p.ok()) return "no build";
  const bool ok = p.scan();
  if (calls) *calls = p.get("P.calls");
  if (selected) *selected = p.b->app->if_selects;
  return ok ? "" : p.m->trap().message;
}

TEST(VmSelects, ArmsThatCouldBeSeenKeepTheirJump) {
  // The arm not taken would call a function, divide by zero, read outside an array.
  const char* call = R"(
FUNCTION Bump : DINT
  VAR_INPUT k : DINT; END_VAR
  VAR_IN_OUT n : DINT; END_VAR
  n := n + 1;
  Bump := k + 1;
END_FUNCTION
PROGRAM P
  VAR w : WORD := 16#0002; x : DINT := 0; calls : DINT := 0; END_VAR
  IF (w AND 1) <> 0 THEN x := Bump(x, calls); END_IF;
END_PROGRAM
)";
  int64_t calls = -1;
  bool selected = true;
  EXPECT_EQ(trap_of(call, &calls, &selected), "");
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(selected);

  // One program each: its declarations, its IF, the trap one scan ends with ("" none)
  // and whether the IF is a select.
  struct Case {
    const char* vars;
    const char* stmt;
    const char* trap;
    bool select;
  };
  const Case cases[] = {
      // a division by a variable that is zero, in the arm not taken
      {"w : WORD := 16#0002; x : DINT := 10; z : DINT := 0;",
       "IF (w AND 1) <> 0 THEN x := x / z; ELSE x := x MOD 7; END_IF;", "", false},
      // an index nobody checked (9), in the arm not taken
      {"flags : ARRAY [0..3] OF BOOL; v : ARRAY [0..3] OF DINT; j : DINT := 9; x : DINT;",
       "IF flags[1] THEN x := v[j]; END_IF;", "", false},
      // the element the condition read (and checked) read again by an arm
      {"flags : ARRAY [0..3] OF BOOL := [FALSE, TRUE]; j : DINT := 1; x : DINT;",
       "IF flags[j] THEN x := BOOL_TO_DINT(flags[j]) + 4; END_IF;", "", true},
      // a condition that traps traps as before
      {"flags : ARRAY [0..3] OF BOOL; j : DINT := 4; x : DINT;", "IF flags[j] THEN x := x + 1; END_IF;",
       "index 4 outside 0..3", true},
  };
  for (const Case& c : cases) {
    const std::string src = std::string("PROGRAM P\n  VAR ") + c.vars + " calls : DINT; END_VAR\n  " + c.stmt + "\nEND_PROGRAM\n";
    VmRun p(src, selects(true), "keep.st");
    ASSERT_TRUE(p.ok()) << c.stmt;
    const bool ok = p.scan();
    const std::string trap = ok ? "" : p.m->trap().message;
    if (*c.trap) {
      EXPECT_NE(trap.find(c.trap), std::string::npos) << c.stmt << ": " << trap;
    } else {
      EXPECT_EQ(trap, "") << c.stmt;
    }
    // A condition that traps ends the scan before the select: the listing tells.
    EXPECT_EQ(occurrences(p.disasm(), " SEL4 ") == 1, c.select) << c.stmt;
  }
}

TEST(VmSelects, OtherIfsKeepTheirJump) {
  // Comparisons of magnitudes, ELSIF, two statements, two variables, an element, a
  // subrange, a STRING, x := x: no select.
  const char* const kept[] = {
      "IF n > 3 THEN x := x + 1; END_IF;",
      "IF n = 0 THEN x := 1; ELSE x := 2; END_IF;",
      "IF (w AND 1) <> 0 THEN x := 1; ELSIF (w AND 2) <> 0 THEN x := 2; END_IF;",
      "IF (w AND 1) <> 0 THEN x := 1; n := 2; END_IF;",
      "IF (w AND 1) <> 0 THEN x := 1; ELSE n := 2; END_IF;",
      "IF (w AND 1) <> 0 THEN v[1] := 1; END_IF;",
      "IF (w AND 1) <> 0 THEN small := 3; END_IF;",
      "IF (w AND 1) <> 0 THEN txt := 'a'; END_IF;",
      "IF (w AND 1) <> 0 THEN x := x; END_IF;",
      "IF (w AND 1) = 1 THEN x := 1; END_IF;",
      "IF (w AND 3) <> 2 THEN x := 1; END_IF;",
      "IF n MOD 3 = 0 THEN x := 1; END_IF;",
      "IF a AND b THEN x := 1; END_IF;",
      "IF a THEN x := x + 1; END_IF;",
      "IF (5 AND 1) <> 0 THEN x := 1; ELSE x := 2; END_IF;",
      "IF NOT a THEN x := 1; ELSE x := 2; END_IF;",
  };
  for (const char* body : kept) {
    const std::string src = std::string("PROGRAM P\n  VAR w : WORD := 5; n : DINT := 4; x : DINT; v : ARRAY [0..3] OF DINT;\n"
                                        "    small : INT(0..10); txt : STRING; a, b : BOOL; END_VAR\n  ") +
                            body + "\nEND_PROGRAM\n";
    VmRun p(src, selects(true), "kept.st");
    ASSERT_TRUE(p.ok()) << body;
    EXPECT_FALSE(p.b->app->if_selects) << body;
    ASSERT_TRUE(p.scan()) << body;
    // A constant condition is still folded and warned about, as with jumps.
    if (std::string(body).find("(5 AND 1)") != std::string::npos) {
      EXPECT_NE(p.b->diags.render_all().find("ST404"), std::string::npos) << p.b->diags.render_all();
    }
  }
}

TEST(VmSelects, ATestOfBitsIsTypeCheckedAsWithJumps) {
  // 16#8000 does not fit INT, 16#80 not SINT: an error either way, never a select of bit
  // 15 or 7 that `plcfi run` would accept and `plcfi check` refuse.
  const char* src = R"(
PROGRAM P
  VAR s : INT := -5; n : SINT := -3; x : DINT; END_VAR
  IF (s AND 16#8000) <> 0 THEN x := 1; ELSE x := 2; END_IF;
  IF (n AND 16#80) = 0 THEN x := x + 10; END_IF;
END_PROGRAM
)";
  for (bool on : {true, false}) {
    auto b = build_sources({{"typed.st", src}}, selects(on));
    EXPECT_FALSE(b->ok());
    const std::string d = b->diags.render_all();
    EXPECT_NE(d.find("constant 32768 does not fit INT"), std::string::npos) << d;
    EXPECT_NE(d.find("constant 128 does not fit SINT"), std::string::npos) << d;
  }
}

TEST(VmSelects, ASubrangeTargetKeepsItsJump) {
  // `(w AND 1) <> 0` holds: x gets lim - 2. `(w AND 2) <> 0` does not: lim, a subrange
  // variable, keeps its jump and is not assigned 99 (which would trap).
  const char* src = R"(
PROGRAM P
  VAR w : WORD := 1; x : DINT := 0; lim : INT(0..10) := 5; big : INT := 99; calls : DINT; END_VAR
  IF (w AND 1) <> 0 THEN x := lim - 2; ELSE x := 99; END_IF;
  IF (w AND 2) <> 0 THEN lim := big; END_IF;
END_PROGRAM
)";
  VmRun p(src, selects(true), "range.st");
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(p.get("P.x"), 3);
  EXPECT_EQ(p.get("P.lim"), 5);
}

TEST(VmSelects, SelOfValuesIsOneSelect) {
  // The standard function SEL on values of 1, 2, 4 and 8 bytes: one select each, both
  // inputs evaluated as IEC says; on a STRING, the copy of the one chosen.
  const char* src = R"(
PROGRAM P
  VAR
    g : BOOL;
    k : DINT := 0;
    b : BYTE; i : INT; r : REAL; t : LTIME; txt : STRING[8];
  END_VAR
  g := (k MOD 3) = 1;
  b := SEL(g, BYTE#16#11, BYTE#16#22);
  i := SEL(g, -5, 7);
  r := SEL(NOT g, 2.5, -0.75);
  t := SEL(g, LTIME#1s, LTIME#2ms);
  txt := SEL(g, 'no', 'yes');
  k := k + 1;
END_PROGRAM
)";
  VmRun p(src, selects(true), "sel.st");
  ASSERT_TRUE(p.ok());
  const std::string listing = p.disasm();
  EXPECT_EQ(occurrences(listing, " SEL1 ") + occurrences(listing, " SEL2 ") + occurrences(listing, " SEL4 ") +
                occurrences(listing, " SEL8 "),
            4u)
      << listing;
  for (int s = 0; s < 6; ++s) {
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    const bool g = s % 3 == 1;
    EXPECT_EQ(p.get("P.b"), g ? 0x22 : 0x11);
    EXPECT_EQ(p.get("P.i"), g ? 7 : -5);
    EXPECT_EQ(p.real("P.r"), g ? 2.5 : -0.75);
    EXPECT_EQ(p.get("P.t"), g ? 2000000 : 1000000000);
  }
  same_in_both_tiers("sel.st", src, 6, 0, nullptr, selects(true));
}

}  // namespace
}  // namespace plcfi::st
