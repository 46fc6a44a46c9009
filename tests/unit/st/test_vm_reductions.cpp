// Reduction loops: a FOR loop whose body only accumulates one or two elements indexed by
// the counter (s := s + a[i], s := s + a[i] * b[i], DINT or REAL) runs in one handler of
// the interpreter. The program must compute what it computes when another statement in
// the body keeps the loop plain, in every element access form (rank 1 checked and
// proven, a field of a structure element, a row of a rank-2 array), with DINT and INT
// counters counting up and down, through wraparound, traps and the watchdog; and the
// native tier (which has no such handler) must agree.
#include <gtest/gtest.h>

#include <string>

#include "engine.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

// `@` marks the end of each reduction loop's body; `plain` puts a statement there, which
// keeps the loop a plain one. Both versions have the same lines.
std::string program(bool plain) {
  std::string src = R"(TYPE
  Pt : STRUCT w : REAL; n : DINT; k : INT; END_STRUCT;
END_TYPE
PROGRAM P
VAR
  a, b : ARRAY [0..15] OF DINT;
  m : ARRAY [0..3, 0..15] OF DINT;
  x, y : ARRAY [1..16] OF REAL;
  pts : ARRAY [0..9] OF Pt;
  e : ARRAY [32760..32767] OF DINT;
  c : ARRAY [0..3] OF DINT;
  i, j, k : DINT;
  n : INT;
  lo : DINT := 0;
  hi : DINT := 15;
  top : INT := 9;
  seed : DINT := 7;
  s1, s2, s3, s4, s5, s6, s7, s8 : DINT;
  r1, r2, r3, r4 : REAL;
  pad : DINT;
END_VAR
FOR i := 0 TO 15 DO
  seed := (seed * 1103 + 12345) MOD 65521;
  a[i] := seed MOD 2001 - 1000;
  b[i] := (seed / 7) MOD 301 - 150;
  x[i + 1] := DINT_TO_REAL(a[i]) * 0.125;
  y[i + 1] := DINT_TO_REAL(b[i]) / 3.0;
END_FOR;
FOR j := 0 TO 3 DO
  FOR k := 0 TO 15 DO
    m[j, k] := a[k] * (j + 1) - b[15 - k];
  END_FOR;
END_FOR;
FOR i := 0 TO 9 DO
  pts[i].w := x[i + 1] - y[16 - i];
  pts[i].n := a[i] * 3;
  pts[i].k := DINT_TO_INT(b[i]);
END_FOR;
FOR i := 32760 TO 32767 DO
  e[i] := seed MOD 1000 + i;
END_FOR;
s1 := 0;
FOR i := lo TO hi DO s1 := s1 + a[i]; @ END_FOR;
s2 := 0;
FOR i := 0 TO 15 DO s2 := s2 + a[i] * b[i]; @ END_FOR;
FOR j := 0 TO 3 DO
  s3 := j;
  FOR k := 0 TO 15 DO s3 := m[j, k] * a[k] + s3; @ END_FOR;
  c[j] := s3;
END_FOR;
r1 := 0.0;
FOR i := 1 TO 16 DO r1 := x[i] + r1; @ END_FOR;
r2 := 1.5;
FOR i := 1 TO 16 DO r2 := r2 + x[i] * y[i]; @ END_FOR;
r3 := 0.0;
FOR i := 9 TO 0 BY -1 DO r3 := r3 + pts[i].w; @ END_FOR;
r4 := 0.0;
FOR i := 1 TO 16 DO r4 := y[i] * x[i] + r4; @ END_FOR;
s4 := 0;
FOR n := 0 TO top DO s4 := s4 + pts[n].n; @ END_FOR;
s5 := 0;
FOR n := 0 TO 15 BY 3 DO s5 := s5 + a[n] * b[n]; @ END_FOR;
s6 := 0;
FOR i := hi TO lo BY -3 DO s6 := s6 + b[i]; @ END_FOR;
s7 := 2147480000;
FOR i := 0 TO 15 DO s7 := s7 + a[i] * b[i]; @ END_FOR;
s8 := 0;
FOR i := 32760 TO 32767 DO s8 := s8 + e[i]; @ END_FOR;
FOR n := 32765 TO 32767 DO s8 := s8 + e[n]; @ END_FOR;
END_PROGRAM
)";
  for (size_t at = src.find('@'); at != std::string::npos; at = src.find('@', at))
    src.replace(at, 1, plain ? "pad := pad + 1;" : "");
  return src;
}

constexpr size_t kReductions = 13;

// The reduction loops the interpreter runs as such (named by all their instructions).
size_t reductions(const Machine& m) {
  size_t n = 0;
  for (const auto& [pc, name] : m.superinstructions()) {
    const bool loop = name.find("+LOOPUP_") != std::string::npos || name.find("+LOOPDN_") != std::string::npos;
    n += loop && name.rfind("LDX", 0) == 0 ? 1 : 0;
  }
  return n;
}

const char* const kInts[] = {"P.s1", "P.s2", "P.s3", "P.s4", "P.s5", "P.s6", "P.s7", "P.s8", "P.c[0]", "P.c[3]",
                             "P.i", "P.j", "P.k", "P.n", "P.seed"};
const char* const kReals[] = {"P.r1", "P.r2", "P.r3", "P.r4"};

// Scan by scan with these limits: in range, a range inside, an empty loop, an index past
// the end (the DINT loop) and past the end of the structure array (the INT loop).
struct Limits {
  int64_t lo, hi, top;
};
const Limits kScans[] = {{0, 15, 9}, {5, 9, 4}, {3, 2, 9}, {0, 16, 9}, {0, 15, 10}, {-1, 15, 9}, {2, 13, 0}};

void same_as_plain(uint64_t budget) {
  vmtest::VmRun fused(program(false), CompileOptions{}, "reduce.st"), plain(program(true), CompileOptions{}, "reduce.st");
  ASSERT_TRUE(fused.ok());
  ASSERT_TRUE(plain.ok());
  fused.m->set_budget(budget);
  plain.m->set_budget(budget);
  int scan = 0;
  for (const Limits& l : kScans) {
    for (vmtest::VmRun* r : {&fused, &plain}) {
      r->set("P.lo", l.lo);
      r->set("P.hi", l.hi);
      r->set("P.top", l.top);
    }
    const bool ok = fused.scan();
    ASSERT_EQ(plain.scan(), ok) << "scan " << scan;
    if (!ok) {
      EXPECT_EQ(plain.m->trap().kind, fused.m->trap().kind) << "scan " << scan;
      EXPECT_EQ(plain.m->trap().message, fused.m->trap().message) << "scan " << scan;
      EXPECT_EQ(plain.m->trap().loc.line, fused.m->trap().loc.line) << "scan " << scan;
    }
    for (const char* v : kInts) EXPECT_EQ(plain.get(v), fused.get(v)) << v << " after scan " << scan;
    for (const char* v : kReals) EXPECT_EQ(plain.real(v), fused.real(v)) << v << " after scan " << scan;
    ++scan;
  }
  EXPECT_EQ(kReductions, reductions(*fused.m));
  EXPECT_EQ(0u, reductions(*plain.m));
}

TEST(VmReductions, EveryFormComputesWhatThePlainLoopComputesTrapsIncluded) { same_as_plain(100'000'000); }

TEST(VmReductions, TheWatchdogStopsAReductionLoopAtThePlainLoopsIteration) {
  // The budget runs out at a different place in each: inside the set-up loops, in the
  // first reduction loops, in the row loop, in the last ones.
  for (uint64_t budget : {60u, 150u, 163u, 200u, 230u, 260u, 300u}) {
    SCOPED_TRACE("budget " + std::to_string(budget));
    same_as_plain(budget);
  }
}

TEST(VmReductions, ValuesCheckedByHand) {
  vmtest::VmRun r(R"(PROGRAM P
VAR
  a : ARRAY [1..5] OF DINT := [1, 2, 3, 4, 5];
  b : ARRAY [1..5] OF DINT := [10, 20, 30, 40, 50];
  f : ARRAY [0..3] OF REAL := [0.5, 0.25, 2.0, 4.0];
  e : ARRAY [32765..32767] OF DINT := [7, 8, 9];
  i : DINT; n : INT; hi : DINT := 5;
  s, t, w : DINT; q : REAL;
END_VAR
s := 0;
FOR i := 1 TO hi DO s := s + a[i] * b[i]; END_FOR;
t := 100;
FOR i := 5 TO 1 BY -2 DO t := t + a[i]; END_FOR;
q := 1.0;
FOR i := 0 TO 3 DO q := q + f[i]; END_FOR;
w := 0;
FOR n := 32765 TO 32767 DO w := w + e[n]; END_FOR;
END_PROGRAM
)",
                  CompileOptions{}, "reduce.st");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan()) << r.m->trap().message;
  EXPECT_EQ(4u, reductions(*r.m));
  EXPECT_EQ(10 + 40 + 90 + 160 + 250, r.get("P.s"));
  EXPECT_EQ(4, r.get("P.i"));  // past the end of the last loop on i, as after any FOR
  EXPECT_EQ(100 + 5 + 3 + 1, r.get("P.t"));
  EXPECT_EQ(7.75, r.real("P.q"));
  EXPECT_EQ(24, r.get("P.w"));
  EXPECT_EQ(-32768, r.get("P.n"));  // 32767 + 1 wraps: the loop ends on the overflow
  // An index past the end: the elements before it are added, then the plain load traps.
  r.set("P.hi", 7);
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, r.m->trap().kind);
  EXPECT_EQ("index 6 outside 1..5", r.m->trap().message);
  EXPECT_EQ(11u, r.m->trap().loc.line);
  EXPECT_EQ(550, r.get("P.s"));
  EXPECT_EQ(6, r.get("P.i"));
}

TEST(VmReductions, TheNativeTierComputesTheSame) {
  same_in_both_tiers("reduce.st", program(false), 7, 100'000'000, [](Machine& m, int scan) {
    const Limits& l = kScans[scan];
    std::string err;
    write_int(m, *resolve(m.app(), "P.lo", &err), l.lo);
    write_int(m, *resolve(m.app(), "P.hi", &err), l.hi);
    write_int(m, *resolve(m.app(), "P.top", &err), l.top);
  });
}

// A sum whose bytes are an element of the array it adds up (a UNION): each iteration
// must read the sum the last one stored through the element, so the loop stays plain.
TEST(VmReductions, ASumInsideTheArrayKeepsTheLoopPlain) {
  CompileOptions codesys;
  codesys.dialect = Dialect::Codesys;
  const char* src = R"(TYPE
  R : STRUCT p0, p1, p2 : DINT; s : DINT; END_STRUCT;
  U : UNION a : ARRAY [0..7] OF DINT; r : R; END_UNION;
END_TYPE
PROGRAM P
VAR u : U; i : DINT; END_VAR
FOR i := 0 TO 7 DO u.a[i] := i + 1; END_FOR;
FOR i := 0 TO 7 DO u.r.s := u.r.s + u.a[i]; END_FOR;
END_PROGRAM
)";
  vmtest::VmRun r(src, codesys, "reduce.st");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan()) << r.m->trap().message;
  EXPECT_EQ(0u, reductions(*r.m));
  // s starts as a[3] = 4: 4 + 1 + 2 + 3 = 10 is stored into a[3], which is then added.
  EXPECT_EQ(46, r.get("P.u.r.s"));
}

}  // namespace
}  // namespace plcfi::st
