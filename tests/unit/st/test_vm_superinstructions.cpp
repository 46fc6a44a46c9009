// Superinstructions keep the language's meaning: the interpreter runs some adjacent
// instructions in one handler (pairs, triples, and a summing loop as a whole), handing
// values from one to the next in registers. Each case checks what the source says, that
// the superinstruction was really used, and the interpreter against the native tier, which
// has none (memory, coverage and traps after every scan, watchdog included).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

#include "engine.hpp"
#include "native/native.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

struct Prog : vmtest::VmRun {
  explicit Prog(const std::string& src) : VmRun(src, {}, "fused.st") {}
  // How many superinstructions of this name the interpreter runs (after a first call).
  size_t uses(const std::string& name) const {
    auto all = m->superinstructions();
    return static_cast<size_t>(std::count_if(all.begin(), all.end(), [&](const auto& p) { return p.second == name; }));
  }
  std::string all_names() const {
    std::string s;
    for (const auto& [pc, name] : m->superinstructions()) s += std::to_string(pc) + " " + name + "\n";
    return s;
  }
};

// Both tiers, scan by scan, with `inputs` written into both machines before each scan;
// and the interpreter runs superinstructions on this source.
void same_in_both_tiers(const std::string& src, int scans, const std::function<void(Machine&, int)>& inputs,
                        uint64_t budget = 100'000'000) {
  plcfi::st::same_in_both_tiers("fused.st", src, scans, budget, inputs);
  Prog p(src);
  ASSERT_TRUE(p.ok());
  inputs(*p.m, 0);
  p.scan();  // the first call threads the code (a trap here is the tiers' comparison's business)
  EXPECT_FALSE(p.m->superinstructions().empty());
}

void set(Machine& m, const char* path, int64_t v) {
  std::string err;
  auto h = resolve(m.app(), path, &err);
  ASSERT_TRUE(h) << err;
  write_int(m, *h, v);
}

// ------------------------------------------------------------------ the summing loop

const char* kSum = R"(PROGRAM P
VAR
  a : ARRAY [1..10] OF DINT;
  i : INT; j : INT := 3; hi : INT := 10; big : BOOL;
  s : DINT; s2 : DINT; s3 : DINT; k : DINT; w : DINT;
END_VAR
FOR i := 1 TO 10 DO
  a[i] := INT_TO_DINT(i) * 1000;
  IF big THEN a[i] := 2147483600; END_IF;
END_FOR;
s := 0;
FOR i := 1 TO hi DO
  s := s + a[i];
END_FOR;
s2 := 5;
FOR i := 1 TO 10 BY 3 DO
  s2 := a[i] + s2;
END_FOR;
s3 := 0;
FOR i := 1 TO 10 DO
  k := k + 1;
  s3 := s3 + a[i];
END_FOR;
w := 0;
FOR i := 1 TO 10 DO
  w := w + a[j];
END_FOR;
END_PROGRAM
)";

TEST(VmSuperinstructions, TheSummingLoopAddsEveryElementAndLeavesTheCounterPastTheEnd) {
  Prog p(kSum);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  // The first two loops are reduction loops, run in one handler (test_vm_reductions.cpp);
  // the third's body has another statement and the fourth's index is not the counter:
  // those run as a pair and a plain loop instruction, with the same result.
  EXPECT_EQ(2u, p.uses("LDXH4+ADD_I32+LOOPUP_I16")) << p.all_names();
  EXPECT_EQ(2u, p.uses("LDXH4+ADD_I32")) << p.all_names();
  EXPECT_EQ(55000, p.get("P.s"));
  EXPECT_EQ(5 + 1000 + 4000 + 7000 + 10000, p.get("P.s2"));
  EXPECT_EQ(55000, p.get("P.s3"));
  EXPECT_EQ(10, p.get("P.k"));
  EXPECT_EQ(30000, p.get("P.w"));
  EXPECT_EQ(11, p.get("P.i"));
  // An empty loop leaves the sum alone.
  p.set("P.hi", 0);
  ASSERT_TRUE(p.scan());
  EXPECT_EQ(0, p.get("P.s"));
  // DINT addition wraps around, as everywhere else in the interpreter.
  p.set("P.hi", 10);
  p.set("P.big", 1);
  ASSERT_TRUE(p.scan());
  EXPECT_EQ(static_cast<int32_t>(static_cast<uint32_t>(2147483600u) * 10u), p.get("P.s"));
}

TEST(VmSuperinstructions, AnIndexOutsideTheArrayStopsTheSummingLoopWhereThePlainLoopStops) {
  Prog p(kSum);
  ASSERT_TRUE(p.ok());
  p.set("P.hi", 12);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, p.m->trap().kind);
  EXPECT_EQ("index 11 outside 1..10", p.m->trap().message);
  EXPECT_EQ(13u, p.m->trap().loc.line);
  EXPECT_EQ(55000, p.get("P.s"));  // every element added before the bad index
  EXPECT_EQ(11, p.get("P.i"));
}

TEST(VmSuperinstructions, TheSummingLoopBehavesTheSameInTheNativeTierTrapsIncluded) {
  same_in_both_tiers(kSum, 6, [](Machine& m, int s) {
    set(m, "P.hi", s == 2 ? 12 : s == 3 ? 0 : 10);
    set(m, "P.big", s == 4 ? 1 : 0);
  });
}

TEST(VmSuperinstructions, TheWatchdogStopsTheSummingLoopAtTheSameIterationAsThePlainLoop) {
  // The first loop jumps back 9 times; the summing loop's fifth jump back is one too many.
  same_in_both_tiers(kSum, 2, [](Machine& m, int) { set(m, "P.hi", 10); }, 13);
  Prog p(kSum);
  ASSERT_TRUE(p.ok());
  p.m->set_budget(13);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::Watchdog, p.m->trap().kind);
  EXPECT_EQ(13u, p.m->trap().loc.line);  // the loop step is located at the body's last statement
  EXPECT_EQ(1000 + 2000 + 3000 + 4000 + 5000, p.get("P.s"));
  EXPECT_EQ(6, p.get("P.i"));
}

// ------------------------------------------------------------------ chains and pairs

// Expressions whose intermediate results feed the next instruction (handed on in a
// register), calls with their argument moves, REAL comparisons with NaN, boolean chains.
const char* kChains = R"(FUNCTION SC : DINT
VAR_INPUT x : DINT; gain : DINT; lo : DINT; hi : DINT; END_VAR
VAR t : DINT; END_VAR
t := (x * gain) / 16;
IF t < lo THEN
  t := lo;
ELSIF t > hi THEN
  t := hi;
END_IF;
SC := t;
END_FUNCTION

FUNCTION_BLOCK PI
VAR_INPUT sp : REAL; pv : REAL; kp : REAL := 0.5; ki : REAL := 0.125; lo : REAL := 0.0; hi : REAL := 100.0; END_VAR
VAR_OUTPUT out : REAL; sat : BOOL; END_VAR
VAR integ : REAL; err : REAL; raw : REAL; END_VAR
err := sp - pv;
integ := integ + ki * err;
IF integ > hi THEN
  integ := hi;
ELSIF integ < lo THEN
  integ := lo;
END_IF;
raw := kp * err + integ;
IF raw > hi THEN
  out := hi; sat := TRUE;
ELSIF raw < lo THEN
  out := lo; sat := TRUE;
ELSE
  out := raw; sat := FALSE;
END_IF;
END_FUNCTION_BLOCK

PROGRAM P
VAR
  k : DINT; scan : DINT; acc : DINT; gain : DINT := 40;
  c : PI; u : REAL; sat : BOOL; pv : REAL; sp : REAL := 50.0;
  b : ARRAY [1..8] OF DINT; i : INT; top : INT := 7; wsum : DINT; swaps : DINT; tmp : DINT;
  st : INT; f : BOOL; e : BOOL; g : BOOL;
END_VAR
acc := 0;
FOR k := 1 TO 60 DO
  acc := acc + SC(x := (k * 37 + scan) MOD 1000 - 500, gain := gain, lo := -1000, hi := 1000);
END_FOR;
c(sp := sp, pv := pv, out => u, sat => sat);
pv := pv + 0.0625 * (u - pv);
FOR i := 1 TO 8 DO
  b[i] := (INT_TO_DINT(i) * 7919 + scan * 31) MOD 101;
END_FOR;
FOR i := 1 TO top DO
  IF b[i] > b[i + 1] THEN
    tmp := b[i]; b[i] := b[i + 1]; b[i + 1] := tmp; swaps := swaps + 1;
  END_IF;
END_FOR;
wsum := 0;
FOR i := 1 TO 8 DO
  wsum := wsum + b[i] * INT_TO_DINT(i);
END_FOR;
st := DINT_TO_INT(scan MOD 3);
f := scan MOD 2 = 0;
e := (st = 1) AND f;
g := NOT f AND e OR (st = 2);
scan := scan + 1;
END_PROGRAM
)";

TEST(VmSuperinstructions, ChainsHandOnTheValueTheSourceComputes) {
  Prog p(kChains);
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  for (const char* name : {"MADD_I32+MODK_I32", "MUL_I32+DIVK_I32+JGE_I32", "SUB_F32+MUL_F32+ADD_F32",
                           "MUL_F32+ADD_F32+JNLT_F32", "CVT_I16_I32+MADD_I32", "MOV4+MOV4+CALL",
                           "LDXH4+JGE_I32", "JNLT_F32+COV", "EQ_I16+BAND"})
    EXPECT_LE(1u, p.uses(name)) << name << " not used:\n" << p.all_names();
  // The same sums, computed here from the source.
  int64_t acc = 0;
  for (int64_t k = 1; k <= 60; ++k) {
    int64_t t = ((k * 37) % 1000 - 500) * 40 / 16;
    acc += std::clamp<int64_t>(t, -1000, 1000);
  }
  EXPECT_EQ(acc, p.get("P.acc"));
  // PI, first call: err = 50, integ = 6.25, raw = 31.25.
  EXPECT_DOUBLE_EQ(31.25, p.real("P.u"));
  EXPECT_EQ(0, p.get("P.sat"));
}

TEST(VmSuperinstructions, ChainsBehaveTheSameInTheNativeTierNaNIncluded) {
  same_in_both_tiers(kChains, 40, [](Machine& m, int s) {
    std::string err;
    auto sp = resolve(m.app(), "P.sp", &err);
    ASSERT_TRUE(sp) << err;
    if (s == 7) write_real(m, *sp, std::numeric_limits<double>::quiet_NaN());
    if (s == 9) write_real(m, *sp, 250.0);  // saturates high
    if (s == 20) write_real(m, *sp, -80.0);  // saturates low
    if (s == 25) set(m, "P.gain", -300);
  });
}

TEST(VmSuperinstructions, AnIndexTrapInTheFirstInstructionOfAPairIsReportedThere) {
  Prog p(kChains);
  ASSERT_TRUE(p.ok());
  p.set("P.top", 8);  // b[i + 1] with i = 8
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, p.m->trap().kind);
  EXPECT_EQ("index 9 outside 1..8", p.m->trap().message);
  EXPECT_EQ(51u, p.m->trap().loc.line);
  same_in_both_tiers(kChains, 3, [](Machine& m, int s) { set(m, "P.top", s == 1 ? 8 : 7); });
}

}  // namespace
}  // namespace plcfi::st
