// The interpreter's shortcuts keep the language's meaning: a FUNCTION call copies only the
// part of its frame template it needs, REAL comparisons jump on their own instruction
// (NaN included), and an array read through an INT index skips the DINT copy. Each case
// runs in the interpreter against what the source says, and in the native tier against
// the interpreter (memory, coverage and traps after every scan).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "engine.hpp"
#include "native/native.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

// The VM fixture, compiling the source as fast.st.
struct Prog : vmtest::VmRun {
  explicit Prog(const std::string& src, CompileOptions opt = {}) : VmRun(src, opt, "fast.st") {}
};

// The rank-2 accesses of the tests below without the row offsets FOR loops keep for them
// (test_vm_rows.cpp), which would stand for most LDXXN/STXXN here.
CompileOptions without_rows() {
  CompileOptions o;
  o.row_offsets = false;
  return o;
}


// ------------------------------------------------------------------ FUNCTION frames

// Omitted inputs take their declared initial value in every call, whatever an earlier
// call passed; a local read before it is written sees its initial value every call.
const char* kFrames = R"(FUNCTION F : DINT
VAR_INPUT a : DINT; b : DINT := 7; END_VAR
VAR acc : DINT := 100; t : DINT; u : DINT := 5; END_VAR
t := a * 2;            (* written first: no initial value needed *)
F := acc + t + b + u;  (* acc and u read first: their initial values *)
acc := acc + 1;
u := 0;
END_FUNCTION

FUNCTION G : DINT
VAR_INPUT x : DINT; END_VAR
VAR r : DINT := 3; END_VAR
IF x > 0 THEN
  r := x;
END_IF;
G := r;                (* r written only on one path: initial value otherwise *)
END_FUNCTION

FUNCTION H : DINT
VAR_INPUT x : DINT; END_VAR
IF x > 10 THEN
  H := 1;
  RETURN;
END_IF;
H := H + x;            (* the result read before written: starts at 0 every call *)
END_FUNCTION

FUNCTION O : BOOL
VAR_INPUT x : DINT; END_VAR
VAR_OUTPUT q : DINT := 42; END_VAR
IF x > 0 THEN q := x; END_IF;
O := TRUE;
END_FUNCTION

(* An INT input, then the in-out pointer two bytes on, then a local read first: the
   template copy must not reach back over what the call stored. *)
FUNCTION K : INT
VAR_IN_OUT io : INT; END_VAR
VAR_INPUT a : INT; END_VAR
VAR z : INT := 3; END_VAR
io := io + a + z;
K := io;
END_FUNCTION

PROGRAM P
VAR r1, r2, r3, r4, g1, g2, h1, h2, h3, q1, q2 : DINT; ok : BOOL; v, k1 : INT; END_VAR
v := 1;
k1 := K(io := v, a := 2);  (* v = 6 *)
r1 := F(a := 1, b := 1);   (* 100 + 2 + 1 + 5 *)
r2 := F(a := 1);           (* b omitted: 7 *)
r3 := F(a := 2, b := 3);
r4 := F(a := 0);
g1 := G(x := 9);
g2 := G(x := -1);          (* 3, not the 9 the last call left in the frame *)
h1 := H(x := 20);
h2 := H(x := 4);
h3 := H(x := 4);
ok := O(x := 5, q => q1);
ok := O(x := -5, q => q2); (* 42, not 5 *)
END_PROGRAM
)";

TEST(VmFastPaths, FunctionCallsSeeInitialValuesOfWhatTheyDoNotPassOrWriteFirst) {
  Prog p(kFrames);
  ASSERT_TRUE(p.ok());
  for (int s = 0; s < 3; ++s) {
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    EXPECT_EQ(108, p.get("P.r1"));
    EXPECT_EQ(114, p.get("P.r2"));
    EXPECT_EQ(112, p.get("P.r3"));
    EXPECT_EQ(112, p.get("P.r4"));
    EXPECT_EQ(9, p.get("P.g1"));
    EXPECT_EQ(3, p.get("P.g2"));
    EXPECT_EQ(1, p.get("P.h1"));
    EXPECT_EQ(4, p.get("P.h2"));
    EXPECT_EQ(4, p.get("P.h3"));
    EXPECT_EQ(5, p.get("P.q1"));
    EXPECT_EQ(42, p.get("P.q2"));
    EXPECT_EQ(6, p.get("P.v"));
    EXPECT_EQ(6, p.get("P.k1"));
  }
}

TEST(VmFastPaths, FunctionFramesAreNotCopiedWholeWhenTheCallPassesEverything) {
  Prog p(kFrames);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  // r1 := F(a := 1, b := 1): acc and u (read first) and the constants are copied; a, b,
  // t and the result are not: less than the whole template.
  uint32_t whole = 0;
  for (const auto& pou : p.b->app->pous)
    if (pou->name == "F") whole = pou->tmpl_to - pou->tmpl_from;
  ASSERT_GT(whole, 24u);
  size_t at = dis.find("r1 := F(");
  ASSERT_NE(std::string::npos, at) << dis;
  size_t end = dis.find("r2 := F(", at);
  std::string call = dis.substr(at, end - at);
  size_t ib = call.find("INITBLK");
  if (ib != std::string::npos) {
    unsigned dst = 0, src = 0, n = 0;
    ASSERT_EQ(3, std::sscanf(call.c_str() + ib, "INITBLK %u %u %u", &dst, &src, &n)) << call;
    EXPECT_LE(n, whole - 16) << call;
  }
  // G(x := 9) passes its one input, and G's result is written last: neither is copied,
  // only r (written on one path) and the constants.
  uint32_t whole_g = 0;
  for (const auto& pou : p.b->app->pous)
    if (pou->name == "G") whole_g = pou->tmpl_to - pou->tmpl_from;
  at = dis.find("g1 := G(");
  ASSERT_NE(std::string::npos, at) << dis;
  call = dis.substr(at, dis.find("g2 := G(", at) - at);
  ib = call.find("INITBLK");
  if (ib != std::string::npos) {
    unsigned dst = 0, src = 0, n = 0;
    ASSERT_EQ(3, std::sscanf(call.c_str() + ib, "INITBLK %u %u %u", &dst, &src, &n)) << call;
    EXPECT_LE(n, whole_g - 16) << call;
  }
}

TEST(VmFastPaths, FunctionFramesBehaveTheSameInTheNativeTier) { same_in_both_tiers("fast.st", kFrames, 3); }

// (A mocked FUNCTION's outputs: tests/st/test_call_frames.st, through `plcfi test`.)

// ------------------------------------------------------------------ REAL compare-and-jump

const char* kRealBranches = R"(PROGRAM P
VAR x, y : REAL; a, b : LREAL; n1, n2, n3, n4, n5, n6, n7, n8 : DINT; END_VAR
IF x > y THEN n1 := n1 + 1; ELSE n2 := n2 + 1; END_IF;
IF x < y THEN n3 := n3 + 1; END_IF;
IF x >= y THEN n4 := n4 + 1; END_IF;
IF x <= y THEN n5 := n5 + 1; END_IF;
IF a > b THEN n6 := n6 + 1; END_IF;
IF a <= b THEN n7 := n7 + 1; END_IF;
IF x = y THEN n8 := n8 + 1; END_IF;
END_PROGRAM
)";

TEST(VmFastPaths, RealComparisonsJumpOnTheirOwnInstructionAndCountNaNAsFalse) {
  Prog p(kRealBranches);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("JNLT_F32")) << dis;
  EXPECT_NE(std::string::npos, dis.find("JNGE_F32")) << dis;
  EXPECT_NE(std::string::npos, dis.find("JNLT_F64")) << dis;
  EXPECT_NE(std::string::npos, dis.find("JNGE_F64")) << dis;
  EXPECT_EQ(std::string::npos, dis.find("GT_F32")) << dis;
  auto put_real = [&](const std::string& path, double v) { write_real(*p.m, p.h(path), v); };
  // x = 1, y = 2: only <, <= (and the ELSE of >).
  put_real("P.x", 1.0);
  put_real("P.y", 2.0);
  put_real("P.a", 3.0);
  put_real("P.b", 3.0);
  ASSERT_TRUE(p.scan());
  EXPECT_EQ(0, p.get("P.n1"));
  EXPECT_EQ(1, p.get("P.n2"));
  EXPECT_EQ(1, p.get("P.n3"));
  EXPECT_EQ(0, p.get("P.n4"));
  EXPECT_EQ(1, p.get("P.n5"));
  EXPECT_EQ(0, p.get("P.n6"));
  EXPECT_EQ(1, p.get("P.n7"));
  EXPECT_EQ(0, p.get("P.n8"));
  // Both arms of the first IF covered once each arm ran.
  uint32_t after_first = p.taken_count();
  // NaN: every ordered comparison and = are FALSE; the ELSE arms run.
  put_real("P.x", std::nan(""));
  put_real("P.a", std::nan(""));
  ASSERT_TRUE(p.scan());
  EXPECT_EQ(0, p.get("P.n1"));
  EXPECT_EQ(2, p.get("P.n2"));
  EXPECT_EQ(1, p.get("P.n3"));
  EXPECT_EQ(0, p.get("P.n4"));
  EXPECT_EQ(1, p.get("P.n5"));
  EXPECT_EQ(0, p.get("P.n6"));
  EXPECT_EQ(1, p.get("P.n7"));
  EXPECT_EQ(0, p.get("P.n8"));
  // x = 3, y = 2: the THEN arm of the first IF.
  put_real("P.x", 3.0);
  p.m->clear_taken();
  ASSERT_TRUE(p.scan());
  EXPECT_EQ(1, p.get("P.n1"));
  EXPECT_EQ(1, p.get("P.n4"));
  EXPECT_GT(after_first, 0u);
}

TEST(VmFastPaths, RealBranchesGiveTheSameCoverageInBothTiers) {
  // x and y walk through ordered, equal and NaN pairs (0.0 / 0.0 is NaN).
  const char* src = R"(PROGRAM P
VAR x, y, z : REAL; a, b : LREAL; k : DINT; n : ARRAY [0..7] OF DINT; END_VAR
k := k + 1;
x := DINT_TO_REAL(k MOD 5) - 2.0;
y := DINT_TO_REAL(k MOD 3) - 1.0;
IF k MOD 7 = 0 THEN x := z / z; END_IF;
a := REAL_TO_LREAL(x);
b := REAL_TO_LREAL(y);
IF x > y THEN n[0] := n[0] + 1; ELSIF x < y THEN n[1] := n[1] + 1; ELSE n[2] := n[2] + 1; END_IF;
IF a >= b THEN n[3] := n[3] + 1; ELSIF a <= b THEN n[4] := n[4] + 1; END_IF;
WHILE x < y DO x := x + 1.0; n[5] := n[5] + 1; END_WHILE;
IF NOT (x = y) THEN n[6] := n[6] + 1; END_IF;
END_PROGRAM
)";
  same_in_both_tiers("fast.st", src, 30);
}

// ------------------------------------------------------------------ INT-indexed reads

const char* kIntIndex = R"(TYPE Item : STRUCT id : DINT; w : INT; b : BOOL; END_STRUCT; END_TYPE
PROGRAM P
VAR a : ARRAY [1..8] OF DINT; s : ARRAY [-2..2] OF INT; it : ARRAY [1..4] OF Item;
    i : INT; sum, wsum : DINT; k : INT := 1; bad : INT; v : DINT; END_VAR
FOR i := 1 TO 8 DO a[i] := i * 10; END_FOR;
FOR i := -2 TO 2 DO s[i] := i; END_FOR;
FOR i := 1 TO 4 DO it[i].id := i; it[i].w := i * 3; it[i].b := i MOD 2 = 0; END_FOR;
sum := 0; wsum := 0;
FOR i := 1 TO 8 DO sum := sum + a[i]; END_FOR;
FOR i := 1 TO 4 DO
  wsum := wsum + it[i].id * it[i].w;
  IF it[i].b THEN wsum := wsum + 1000; END_IF;
END_FOR;
a[k] := a[k] + a[k + 1];   (* the same index read and written in one statement *)
sum := sum + s[k - 3];
v := a[bad];               (* out of range: traps at this line *)
END_PROGRAM
)";

TEST(VmFastPaths, IntIndexedReadsUseTheIntAndTrapWithTheSameMessage) {
  Prog p(kIntIndex);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("LDXH4")) << dis;
  EXPECT_NE(std::string::npos, dis.find("LDXSH2")) << dis;
  EXPECT_NE(std::string::npos, dis.find("LDXSH1")) << dis;
  p.set("P.bad", 1);
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(360 - 2, p.get("P.sum"));  // 10+..+80, plus s[-2]
  EXPECT_EQ(3 * (1 + 4 + 9 + 16) + 2000, p.get("P.wsum"));
  EXPECT_EQ(30, p.get("P.a[1]"));
  p.set("P.bad", 9);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, p.m->trap().kind);
  EXPECT_EQ("index 9 outside 1..8", p.m->trap().message);
  EXPECT_EQ(16u, p.m->trap().loc.line);
  p.set("P.bad", -32768);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ("index -32768 outside 1..8", p.m->trap().message);
}

// Stores through an INT variable index read it at the store (STXH) only when nothing in
// the statement can change it first: a call on the right (here one that increments the
// index through VAR_IN_OUT) keeps the element chosen before the call.
const char* kIntIndexStores = R"(FUNCTION Bump : DINT
VAR_IN_OUT io : INT; END_VAR
io := io + 1;
Bump := 7;
END_FUNCTION
TYPE Pt : STRUCT x : DINT; y : INT; END_STRUCT; END_TYPE
PROGRAM P
VAR a : ARRAY [1..4] OF DINT; ps : ARRAY [0..3] OF Pt; i : INT := 1; j : INT; bad : INT := 4; END_VAR
a[i] := Bump(io := i);     (* a[1] := 7, then i = 2 *)
a[i] := i * 10;            (* a[2] := 20 *)
ps[j].y := i + 1;          (* ps[0].y := 3 *)
ps[j + 1].x := 5;
a[bad] := 1;               (* traps at this line when bad is outside 1..4 *)
END_PROGRAM
)";

TEST(VmFastPaths, IntIndexedStoresKeepTheElementChosenBeforeACall) {
  Prog p(kIntIndexStores);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("STXH4")) << dis;
  EXPECT_NE(std::string::npos, dis.find("STXSH2")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(7, p.get("P.a[1]"));
  EXPECT_EQ(20, p.get("P.a[2]"));
  EXPECT_EQ(2, p.get("P.i"));
  EXPECT_EQ(3, p.get("P.ps[0].y"));
  EXPECT_EQ(5, p.get("P.ps[1].x"));
  EXPECT_EQ(1, p.get("P.a[4]"));
  p.set("P.i", 1);
  p.set("P.bad", 5);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, p.m->trap().kind);
  EXPECT_EQ("index 5 outside 1..4", p.m->trap().message);
  EXPECT_EQ(13u, p.m->trap().loc.line);
  p.set("P.i", 1);
  p.set("P.bad", 4);
  p.set("P.j", 4);  // ps[4]: the STXSH traps
  EXPECT_FALSE(p.scan());
  EXPECT_EQ("index 4 outside 0..3", p.m->trap().message);
  EXPECT_EQ(11u, p.m->trap().loc.line);
}

TEST(VmFastPaths, IntIndexedStoresBehaveTheSameInTheNativeTier) {
  std::string src = kIntIndexStores;
  // i, j and bad walk through and past the bounds: both tiers trap alike.
  src.replace(src.find("a[i] := Bump"), 0, "i := (i + 1) MOD 6; j := (j + 1) MOD 5; bad := (bad + 1) MOD 7;\n");
  same_in_both_tiers("fast.st", src, 14);
}

TEST(VmFastPaths, IntIndexedReadsBehaveTheSameInTheNativeTier) {
  std::string src = kIntIndex;
  // bad walks 0..9: scans trap at 0 and 9 in both tiers alike.
  src.replace(src.find("v := a[bad];"), 12, "bad := (bad + 1) MOD 10; v := a[bad];");
  same_in_both_tiers("fast.st", src, 12);
}

// ------------------------------------------------------------------ rank-2 arrays, whole elements

// Two variable indices into a frame array (of scalars or structures, of rank 2 or with the
// other indices constant) are one instruction; each index is checked in turn, the first one
// first, with the message the ELEM chain gave. A whole structure element moves as a block.
const char* kRank2 = R"(TYPE Cell : STRUCT v : DINT; f : INT; on : BOOL; END_STRUCT; END_TYPE
PROGRAM P
VAR m : ARRAY [1..3, -1..2] OF DINT; g : ARRAY [0..1, 0..2] OF Cell;
    cube : ARRAY [0..1, 0..2, 0..3] OF INT; row : ARRAY [0..3] OF Cell;
    i, j, k : DINT; s : DINT; t : Cell; bi : DINT := 1; bj : DINT := -1; x : DINT; END_VAR
FOR i := 1 TO 3 DO FOR j := -1 TO 2 DO m[i, j] := i * 10 + j; END_FOR; END_FOR;
FOR i := 0 TO 1 DO FOR j := 0 TO 2 DO g[i, j].v := i * 3 + j; g[i, j].f := INT#7; g[i, j].on := j = 1; END_FOR; END_FOR;
FOR i := 0 TO 1 DO FOR j := 0 TO 3 DO cube[i, 1, j] := DINT_TO_INT(i * 4 + j); END_FOR; END_FOR;
s := 0;
FOR i := 1 TO 3 DO FOR j := -1 TO 2 DO s := s + m[i, j]; END_FOR; END_FOR;
FOR k := 0 TO 3 DO row[k].v := k * 100; row[k].f := DINT_TO_INT(k); END_FOR;
i := 2; t := row[i];              (* a whole element out *)
i := 0; j := 3; row[i] := row[j]; (* element to element *)
t.v := t.v + 1;
i := 1; row[i] := t;              (* a whole element in *)
FOR i := 0 TO 1 DO FOR j := 0 TO 2 DO IF g[i, j].on THEN s := s + g[i, j].v * 1000; END_IF; END_FOR; END_FOR;
s := s + INT_TO_DINT(cube[1, 1, 3]) * 100000 + INT_TO_DINT(g[1, 2].f);
x := m[bi, bj];                   (* traps when bi or bj is outside its bounds *)
END_PROGRAM
)";

TEST(VmFastPaths, RankTwoAccessIsOneInstructionAndChecksEachIndex) {
  Prog p(kRank2, without_rows());
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("LDXX4 ")) << dis;   // m[bi, bj]
  // Inside FOR loops over the arrays' own bounds, the indices need no check (below).
  EXPECT_NE(std::string::npos, dis.find("STXXN4")) << dis;  // m[i, j] :=
  EXPECT_NE(std::string::npos, dis.find("LDXXN1")) << dis;  // g[i, j].on
  EXPECT_NE(std::string::npos, dis.find("STXXN2")) << dis;  // cube[i, 1, j]
  EXPECT_NE(std::string::npos, dis.find("LDXB")) << dis;
  EXPECT_NE(std::string::npos, dis.find("STXB")) << dis;
  EXPECT_EQ(std::string::npos, dis.find("ELEM")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  // m: sum of i*10+j over i 1..3, j -1..2 = 4*60 + 3*2; g: (1 + 4) * 1000; cube[1,1,3] = 7.
  EXPECT_EQ(246 + 5000 + 700000 + 7, p.get("P.s"));
  EXPECT_EQ(9, p.get("P.x"));
  EXPECT_EQ(300, p.get("P.row[0].v"));
  EXPECT_EQ(3, p.get("P.row[0].f"));
  EXPECT_EQ(201, p.get("P.row[1].v"));
  EXPECT_EQ(2, p.get("P.row[1].f"));
  EXPECT_EQ(200, p.get("P.t.v") - 1);
  p.set("P.bi", 4);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, p.m->trap().kind);
  EXPECT_EQ("index 4 outside 1..3", p.m->trap().message);
  EXPECT_EQ(18u, p.m->trap().loc.line);
  p.set("P.bi", 3);
  p.set("P.bj", 3);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ("index 3 outside -1..2", p.m->trap().message);
  p.set("P.bi", 0);  // both outside: the first index is reported
  EXPECT_FALSE(p.scan());
  EXPECT_EQ("index 0 outside 1..3", p.m->trap().message);
}

TEST(VmFastPaths, RankTwoAccessBehavesTheSameInTheNativeTier) {
  std::string src = kRank2;
  // bi and bj walk through and past their bounds: both tiers trap alike, on either index.
  src.replace(src.find("x := m[bi, bj];"), 15, "bi := (bi + 1) MOD 5; bj := (bj + 2) MOD 5 - 1; x := m[bi, bj];");
  same_in_both_tiers("fast.st", src, 12);
}

// ------------------------------------------------------------------ FOR counters proven in range

// An index that is a FOR loop's DINT counter needs no check inside the body when the loop's
// bounds (constants, or counters of enclosing loops proven the same way) lie inside the
// dimension and nothing in the body can change the counter. Every other case keeps the check.
const char* kProven = R"(PROGRAM P
VAR m : ARRAY [1..3, -1..2] OF DINT; q : ARRAY [0..4, 0..4] OF DINT;
    i, j : DINT; s, t, u, w, x : DINT; n : DINT := 3; v : ARRAY [-2..5] OF INT; END_VAR
FOR i := -2 TO 5 DO v[i] := DINT_TO_INT(i * 3); END_FOR;
w := 0;
FOR i := 5 TO -2 BY -1 DO w := w * 2 + INT_TO_DINT(v[i]); END_FOR;
FOR i := 1 TO 3 DO FOR j := -1 TO 2 DO m[i, j] := i * 10 + j; END_FOR; END_FOR;
FOR i := 0 TO 4 DO FOR j := 0 TO 4 DO q[i, j] := i * 5 + j; END_FOR; END_FOR;
s := 0;
FOR i := 3 TO 1 BY -1 DO FOR j := 2 TO -1 BY -1 DO s := s * 3 + m[i, j]; END_FOR; END_FOR;
t := 0;
FOR i := 1 TO 4 DO FOR j := 0 TO i DO t := t + q[i, j] * (i - j) + q[j, i]; END_FOR; END_FOR;
u := 0;
FOR i := 0 TO 2 DO FOR j := 0 TO 2 DO IF q[i, j] > 3 THEN u := u + q[i, j]; ELSE u := u - 1; END_IF; END_FOR; END_FOR;
x := 0;
FOR j := 0 TO 4 DO x := x * 3 + q[2, j]; END_FOR;
END_PROGRAM
)";

TEST(VmFastPaths, ForCountersInRangeNeedNoIndexCheck) {
  Prog p(kProven, without_rows());
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_EQ(std::string::npos, dis.find("LDXX4 ")) << dis;
  EXPECT_EQ(std::string::npos, dis.find("STXX4 ")) << dis;
  EXPECT_NE(std::string::npos, dis.find("LDXXN4")) << dis;
  EXPECT_NE(std::string::npos, dis.find("STXXN4")) << dis;
  EXPECT_NE(std::string::npos, dis.find("STXN2")) << dis;   // v[i] :=
  EXPECT_NE(std::string::npos, dis.find("LDXN2")) << dis;   // v[i]
  EXPECT_NE(std::string::npos, dis.find("LDXSN4")) << dis;  // q[2, j]
  EXPECT_EQ(std::string::npos, dis.find("LDX2 ")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  // The same sums, computed here from the definitions.
  int64_t s = 0, t = 0, u = 0, w = 0, x = 0;
  for (int64_t i = 5; i >= -2; --i) w = w * 2 + i * 3;
  for (int64_t j = 0; j <= 4; ++j) x = x * 3 + 2 * 5 + j;
  EXPECT_EQ(w, p.get("P.w"));
  EXPECT_EQ(x, p.get("P.x"));
  EXPECT_EQ(-6, p.get("P.v[-2]"));
  auto m = [](int64_t i, int64_t j) { return i * 10 + j; };
  auto q = [](int64_t i, int64_t j) { return i * 5 + j; };
  for (int64_t i = 3; i >= 1; --i)
    for (int64_t j = 2; j >= -1; --j) s = static_cast<int32_t>(s * 3 + m(i, j));
  for (int64_t i = 1; i <= 4; ++i)
    for (int64_t j = 0; j <= i; ++j) t += q(i, j) * (i - j) + q(j, i);
  for (int64_t i = 0; i <= 2; ++i)
    for (int64_t j = 0; j <= 2; ++j) u += q(i, j) > 3 ? q(i, j) : -1;
  EXPECT_EQ(s, p.get("P.s"));
  EXPECT_EQ(t, p.get("P.t"));
  EXPECT_EQ(u, p.get("P.u"));
  EXPECT_EQ(9, p.get("P.m[1,-1]"));  // the lower bounds folded into the offset
  EXPECT_EQ(32, p.get("P.m[3,2]"));
  same_in_both_tiers("fast.st", kProven, 3);
}

// Each loop below could reach outside q (or changes its counter, or may): the check stays,
// and where the index does leave the array, both tiers trap with the usual message.
TEST(VmFastPaths, IndexChecksStayWhereTheCounterIsNotProven) {
  struct Case {
    const char* what;
    const char* body;   // statements; q is ARRAY [0..4, 0..4] OF DINT
    bool proven;        // the check is left out
    const char* trap;   // "" when the loop stays inside q
  };
  const Case cases[] = {
      {"the proven case, for contrast", "FOR i := 0 TO 4 DO s := s + q[i, i]; END_FOR;", true, ""},
      {"a bound outside the dimension", "FOR i := 0 TO 5 DO s := s + q[i, i]; END_FOR;", false, "index 5 outside 0..4"},
      {"a bound outside a rank-1 array", "FOR i := -1 TO 4 DO s := s + v[i] + q[i, i]; END_FOR;", false, "index -1 outside 0..4"},
      {"a bound that is a variable", "FOR i := 0 TO n DO s := s + q[i, i]; END_FOR;", false, "index 5 outside 0..4"},
      {"a counter bounded by a variable", "FOR i := 0 TO n DO FOR j := 0 TO i DO s := s + q[j, j]; END_FOR; END_FOR;", false,
       "index 5 outside 0..4"},
      {"the counter assigned", "FOR i := 0 TO 4 DO s := s + q[i, i]; i := i + 2; END_FOR;", false, ""},
      {"the counter assigned in a nested loop",
       "FOR i := 0 TO 4 DO FOR j := 0 TO 1 DO IF i = 1 THEN i := 6; END_IF; END_FOR; s := s + q[i, i]; END_FOR;", false,
       "index 6 outside 0..4"},
      {"a call of a function block", "FOR i := 0 TO 4 DO f(CLK := TRUE); s := s + q[i, i]; END_FOR;", false, ""},
      {"a call of a function", "FOR i := 0 TO 4 DO s := s + Twice(i) + q[i, i]; END_FOR;", false, ""},
      {"an empty range past the array", "FOR i := 5 TO 4 DO s := s + q[i, i]; END_FOR;", false, ""},
      {"a range whose start may pass the array", "FOR j := 0 TO 4 DO FOR i := j + 0 TO 4 DO s := s + q[i, i]; END_FOR; END_FOR;",
       false, ""},
      {"a start from a counter that may pass the end",
       "FOR j := 0 TO 6 DO FOR i := j TO 4 DO s := s + q[i, i]; END_FOR; END_FOR;", false, ""},
      {"a start from a counter that stays inside", "FOR j := 0 TO 4 DO FOR i := j TO 4 DO s := s + q[i, i]; END_FOR; END_FOR;",
       true, ""},
      {"a write through a pointer", "p := ADR(i); FOR i := 0 TO 4 DO IF i = 1 THEN p^ := 7; END_IF; s := s + q[i, i]; END_FOR;",
       false, "index 7 outside 0..4"},
  };
  for (const Case& c : cases) {
    std::string src = std::string(R"(FUNCTION Twice : DINT
VAR_INPUT x : DINT; END_VAR
Twice := 2 * x;
END_FUNCTION
PROGRAM P
VAR q : ARRAY [0..4, 0..4] OF DINT; v : ARRAY [0..4] OF DINT; i, j, s : DINT; n : DINT := 9; f : R_TRIG;
    p : POINTER TO DINT; END_VAR
)") + c.body + "\nEND_PROGRAM\n";
    Prog prog(src);
    ASSERT_TRUE(prog.ok()) << c.what;
    std::string dis = prog.disasm();
    EXPECT_EQ(c.proven, dis.find("LDXXN4") != std::string::npos) << c.what << "\n" << dis;
    EXPECT_EQ(c.proven, dis.find("LDXX4 ") == std::string::npos) << c.what << "\n" << dis;
    for (const char* op : {" LDXN4", " STXN4", " LDXSN4", " STXSN4"})  // no unchecked rank-1 access either
      EXPECT_EQ(std::string::npos, dis.find(op)) << c.what << ": " << op << "\n" << dis;
    bool ok = prog.scan();
    if (*c.trap) {
      ASSERT_FALSE(ok) << c.what;
      EXPECT_EQ(c.trap, prog.m->trap().message) << c.what;
    } else {
      EXPECT_TRUE(ok) << c.what << ": " << prog.m->trap().message;
    }
    same_in_both_tiers("fast.st", src, 2);
  }
}

// ------------------------------------------------------------------ loops tested at the bottom

// WHILE and REPEAT end with one conditional jump back, which counts against the watchdog
// as JMPB did; CONTINUE goes to the test, EXIT past it; coverage marks the body once per
// entry. An endless loop still traps in both tiers.
const char* kLoops = R"(PROGRAM P
VAR n, w, r, c, e, z : DINT; spin : BOOL; END_VAR
z := 0;
WHILE spin DO z := z + 1; END_WHILE;             (* endless when spin *)
n := n + 1;
w := 0;
WHILE w < n DO w := w + 1; END_WHILE;            (* n passes *)
r := 0;
REPEAT r := r + 2; UNTIL r >= n END_REPEAT;      (* at least one pass *)
c := 0;
WHILE c < 10 DO
  c := c + 1;
  IF c MOD 2 = 0 THEN CONTINUE; END_IF;
  IF c = 7 THEN EXIT; END_IF;
  e := e + c;
END_WHILE;
WHILE z > 0 DO z := z - 1; END_WHILE;            (* never runs here *)
END_PROGRAM
)";

TEST(VmFastPaths, LoopsTestAtTheBottomAndStillCountAgainstTheWatchdog) {
  Prog p(kLoops);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  // One JMPB: `WHILE spin DO z := z + 1;` never writes spin, which stays TRUE once the
  // test on entry passed (rule 28); the watchdog counts its passes the same (below).
  EXPECT_EQ(1u, vmtest::occurrences(dis, " JMPB ")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(1, p.get("P.w"));
  EXPECT_EQ(2, p.get("P.r"));
  EXPECT_EQ(7, p.get("P.c"));
  EXPECT_EQ(1 + 3 + 5, p.get("P.e"));
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(2, p.get("P.w"));
  EXPECT_EQ(2, p.get("P.r"));
  p.m->set_budget(1000);
  p.set("P.spin", 1);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::Watchdog, p.m->trap().kind);
  EXPECT_EQ(4u, p.m->trap().loc.line);
  EXPECT_EQ(1001, p.get("P.z"));  // 1000 jumps back allowed: the body ran 1001 times
}

TEST(VmFastPaths, LoopsTestedAtTheBottomBehaveTheSameInTheNativeTier) {
  std::string src = kLoops;
  // spin on every fifth scan: both tiers stop on the watchdog alike.
  src.replace(src.find("n := n + 1;"), 11, "n := n + 1; spin := n MOD 5 = 0;");
  same_in_both_tiers("fast.st", src, 11, 5000);
}

// ------------------------------------------------------------------ tests of bits

// `(x AND m) <> 0` and `(x AND m) = 0` as a condition are one jump on x and m, in every
// width, also as a loop's test at the bottom; a comparison with anything but zero is not.
const char* kBits = R"(PROGRAM P
VAR b : BYTE := 16#A5; w : WORD := 16#8001; d : DWORD; l : LWORD := 16#8000000000000000;
    n, odd, hi, ones, other : DINT; k : DINT; END_VAR
n := n + 1;
d := DINT_TO_DWORD(n * 7919);
odd := 0; hi := 0; ones := 0; other := 0;
FOR k := 0 TO 7 DO
  IF (SHR(b, k) AND 16#1) <> 0 THEN odd := odd + 1; END_IF;
END_FOR;
IF (w AND 16#8000) = 16#0 THEN hi := 1; END_IF;
IF 0 <> (l AND 16#8000000000000000) THEN hi := hi + 10; END_IF;
WHILE (d AND 16#FFFF) <> 0 DO d := d AND DINT_TO_DWORD(DWORD_TO_DINT(d) - 1); ones := ones + 1; END_WHILE;
IF (w AND 16#3) = 16#1 THEN other := 1; END_IF;
b := ROL(b, 1);
w := w XOR 16#8000;
END_PROGRAM
)";

TEST(VmFastPaths, TestsOfBitsAreOneJump) {
  Prog p(kBits);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("JTZ_U8")) << dis;
  EXPECT_NE(std::string::npos, dis.find("JTNZ_U16")) << dis;
  EXPECT_NE(std::string::npos, dis.find("JTZ_U64")) << dis;
  EXPECT_NE(std::string::npos, dis.find("JTZ_U32")) << dis;   // the WHILE's entry test
  EXPECT_NE(std::string::npos, dis.find("JTNZ_U32")) << dis;  // and its test at the bottom
  EXPECT_NE(std::string::npos, dis.find("JNE_U16")) << dis;   // (w AND 3) = 1: an ordinary comparison
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(4, p.get("P.odd"));  // 16#A5 has four bits set
  EXPECT_EQ(10, p.get("P.hi"));  // w has bit 15: no 1; l has bit 63: 10
  EXPECT_EQ(__builtin_popcount(7919u & 0xFFFFu), p.get("P.ones"));
  EXPECT_EQ(1, p.get("P.other"));
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(11, p.get("P.hi"));  // w without bit 15 now
  EXPECT_EQ(__builtin_popcount((2u * 7919u) & 0xFFFFu), p.get("P.ones"));
}

TEST(VmFastPaths, TestsOfBitsBehaveTheSameInTheNativeTier) { same_in_both_tiers("fast.st", kBits, 20); }

// ------------------------------------------------------------------ shift counts

// A DINT count is read as it is (SHLD...); the result is SHL's after the count's conversion
// to ULINT: a negative count or one of the width or more shifts everything out, and a
// rotation takes the count modulo the width (a negative one, sign-extended, too).
const char* kShifts = R"(PROGRAM P
VAR b : BYTE := 16#81; w : WORD := 16#8001; d : DWORD := 16#80000001; l : LWORD := 16#8000000000000001;
    n : DINT; r1, r2, r3, r4 : DWORD; q1, q2 : BYTE; s1, s2 : WORD; z1, z2 : LWORD; i : INT := 3; ri : WORD; END_VAR
r1 := SHL(d, n); r2 := SHR(d, n); r3 := ROL(d, n); r4 := ROR(d, n);
q1 := ROL(b, n); q2 := SHR(b, n);
s1 := ROR(w, n); s2 := SHL(w, n);
z1 := ROL(l, n); z2 := SHR(l, n);
ri := ROL(w, i);
END_PROGRAM
)";

TEST(VmFastPaths, DintShiftCountsAreReadAsTheyAre) {
  Prog p(kShifts);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  for (const char* op : {"SHLD_U32", "SHRD_U32", "ROLD_U32", "RORD_U32", "ROLD_U8", "RORD_U16", "SHRD_U64"})
    EXPECT_NE(std::string::npos, dis.find(op)) << op << "\n" << dis;
  EXPECT_NE(std::string::npos, dis.find("ROL_U16")) << dis;  // an INT count keeps its conversion
  auto rol32 = [](uint32_t v, int k) { k &= 31; return k ? (v << k) | (v >> (32 - k)) : v; };
  for (int n : {0, 1, 5, 31, 32, 33, 40, -1, -33}) {
    p.set("P.n", n);
    ASSERT_TRUE(p.scan()) << p.m->trap().message;
    uint32_t d = 0x80000001u;
    bool out = n < 0 || n >= 32;
    EXPECT_EQ(out ? 0u : static_cast<uint32_t>(uint64_t{d} << n), static_cast<uint32_t>(p.get("P.r1"))) << n;
    EXPECT_EQ(out ? 0u : d >> n, static_cast<uint32_t>(p.get("P.r2"))) << n;
    // A negative count is 2^64 + n as ULINT: modulo 32 that is n modulo 32 (32 divides 2^64).
    int k = ((n % 32) + 32) % 32;
    EXPECT_EQ(rol32(d, k), static_cast<uint32_t>(p.get("P.r3"))) << n;
    EXPECT_EQ(rol32(d, (32 - k) % 32), static_cast<uint32_t>(p.get("P.r4"))) << n;
  }
  EXPECT_EQ(((0x8001 << 3) & 0xFFFF) | (0x8001 >> 13), p.get("P.ri"));
}

TEST(VmFastPaths, DintShiftCountsBehaveTheSameInTheNativeTier) {
  std::string src = kShifts;
  src.replace(src.find("r1 := SHL"), 0, "n := n + 7; IF n > 70 THEN n := -70; END_IF;\n");
  same_in_both_tiers("fast.st", src, 25);
}

// ------------------------------------------------------------------ indices linear in two variables

// An index x * m + y (variables or constants, in either order of the sum) is one
// instruction with one bounds check; the sum wraps in DINT as MUL and ADD do, and the
// trap names the sum. A store reads x and y at the store only when the right-hand side
// runs no call; a pure standard function (SHR, DINT_TO_WORD) is no call, a FUNCTION with
// a VAR_IN_OUT is, and the element is then chosen before it.
const char* kLinear = R"(FUNCTION Bump : DINT
VAR_IN_OUT io : DINT; END_VAR
io := io + 1;
Bump := 7;
END_FUNCTION
PROGRAM P
VAR flat : ARRAY [0..11] OF DINT; bits : ARRAY [1..8] OF BOOL; w : ARRAY [-4..3] OF INT;
    i, k, s, c, x : DINT; n : DINT := 4; r : DINT := 1; big : DINT := 65536; bad : DINT; END_VAR
FOR i := 0 TO 2 DO FOR k := 0 TO 3 DO flat[i * n + k] := i * 10 + k; END_FOR; END_FOR;
s := 0;
FOR i := 0 TO 2 DO FOR k := 0 TO 3 DO s := s + flat[k + i * n]; END_FOR; END_FOR;
FOR i := 0 TO 3 DO bits[i * 2 + 1] := SHR(DINT_TO_WORD(i), 0) = WORD#2; bits[i * 2 + 2] := i = 1; END_FOR;
c := 0;
FOR i := 0 TO 7 DO IF bits[i * r + 1] THEN c := c + i; END_IF; END_FOR;
i := 1; k := 2;
flat[i * n + k] := Bump(io := k);  (* flat[6] := 7, then k = 3 *)
x := flat[big * 65536 + 5];        (* 2^32 wraps to 0: flat[5]; big = 3 traps *)
w[bad * 2 + r] := INT#9;           (* w[1]; bad = 2 traps *)
END_PROGRAM
)";

TEST(VmFastPaths, LinearIndicesAreOneInstructionWithOneCheck) {
  Prog p(kLinear);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("STXL4")) << dis;
  EXPECT_NE(std::string::npos, dis.find("LDXL4")) << dis;
  EXPECT_NE(std::string::npos, dis.find("STXL1")) << dis;
  EXPECT_NE(std::string::npos, dis.find("LDXL1")) << dis;
  EXPECT_NE(std::string::npos, dis.find("STXL2")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(4 * (0 + 10 + 20) + 3 * (0 + 1 + 2 + 3), p.get("P.s"));
  EXPECT_EQ(1, p.get("P.bits[5]"));  // i = 2
  EXPECT_EQ(1, p.get("P.bits[4]"));  // i = 1
  EXPECT_EQ(0, p.get("P.bits[3]"));
  EXPECT_EQ(3 + 4, p.get("P.c"));
  EXPECT_EQ(7, p.get("P.flat[6]"));   // the element chosen before Bump
  EXPECT_EQ(13, p.get("P.flat[7]"));  // untouched
  EXPECT_EQ(3, p.get("P.k"));
  EXPECT_EQ(11, p.get("P.x"));
  EXPECT_EQ(9, p.get("P.w[1]"));
  p.set("P.big", 3);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, p.m->trap().kind);
  EXPECT_EQ("index 196613 outside 0..11", p.m->trap().message);
  EXPECT_EQ(17u, p.m->trap().loc.line);
  p.set("P.big", 65536);
  p.set("P.bad", 2);
  EXPECT_FALSE(p.scan());
  EXPECT_EQ("index 5 outside -4..3", p.m->trap().message);
  EXPECT_EQ(18u, p.m->trap().loc.line);
}

TEST(VmFastPaths, LinearIndicesBehaveTheSameInTheNativeTier) {
  std::string src = kLinear;
  // big alternates between wrapping and trapping; bad walks into and past the bounds.
  src.replace(src.find("i := 1; k := 2;"), 0,
              "IF big = 65536 THEN big := 3; ELSE big := 65536; END_IF; bad := (bad + 1) MOD 4;\n");
  same_in_both_tiers("fast.st", src, 12);
}

// ------------------------------------------------------------------ multiply-accumulate

// A DINT sum with a product just computed as one operand is one MADD_I32, in either
// order, after a conversion, and for the second of two products; it wraps as MUL and ADD.
const char* kMadd = R"(PROGRAM P
VAR a : ARRAY [0..3] OF DINT := [3, -5, 7, 100000]; s, t, u, v, x : DINT; big : DINT := 65536; k : INT := 3; END_VAR
s := 0;
FOR x := 0 TO 3 DO s := s + a[x] * a[3 - x]; END_FOR;
t := a[0] * a[1] + a[2] * a[3];
u := big * big + 1;
v := 2 + INT_TO_DINT(k) * big;
END_PROGRAM
)";

TEST(VmFastPaths, MultiplyAccumulateIsOneInstructionThatWraps) {
  Prog p(kMadd);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_EQ(std::string::npos, dis.find(" ADD_I32")) << dis;
  EXPECT_NE(std::string::npos, dis.find("MADD_I32")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(3 * 100000 - 5 * 7 + 7 * -5 + 100000 * 3, p.get("P.s"));
  EXPECT_EQ(-15 + 700000, p.get("P.t"));
  EXPECT_EQ(1, p.get("P.u"));  // 2^32 wraps to 0
  EXPECT_EQ(2 + 3 * 65536, p.get("P.v"));
}

TEST(VmFastPaths, MultiplyAccumulateBehavesTheSameInTheNativeTier) {
  std::string src = kMadd;
  src.replace(src.find("s := 0;"), 0, "big := big * 3 + 7; k := k + 1000;\n");
  same_in_both_tiers("fast.st", src, 20);
}

}  // namespace
}  // namespace plcfi::st
