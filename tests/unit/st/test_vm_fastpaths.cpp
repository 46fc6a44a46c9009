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
  explicit Prog(const std::string& src) : VmRun(src, {}, "fast.st") {}
};

// Both tiers, scan by scan: same result, trap, memory, coverage.
void same_in_both_tiers(const std::string& src, int scans) {
  auto b = build_sources({{"fast.st", src}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  std::string err;
  auto native = NativeCode::build(*b->app, NativeOptions{}, &err);
  ASSERT_TRUE(native) << err;
  EXPECT_EQ(native->interpreted(), 0u);
  Machine a(*b->app), n(*b->app);
  n.set_native(native.get());
  const auto& inst = b->app->programs.at(0);
  for (int s = 0; s < scans; ++s) {
    a.clear_taken();
    n.clear_taken();
    bool ra = a.call(inst.pou->entry, inst.addr);
    bool rn = n.call(inst.pou->entry, inst.addr);
    ASSERT_EQ(ra, rn) << "scan " << s;
    EXPECT_EQ(describe_trap(*b->app, a.trap()), describe_trap(*b->app, n.trap())) << "scan " << s;
    ASSERT_TRUE(same_memory(*b->app, a, n)) << "memory differs after scan " << s;
    ASSERT_EQ(a.taken(), n.taken()) << "coverage differs after scan " << s;
  }
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

TEST(VmFastPaths, FunctionFramesBehaveTheSameInTheNativeTier) { same_in_both_tiers(kFrames, 3); }

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
  same_in_both_tiers(src, 30);
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
  same_in_both_tiers(src, 14);
}

TEST(VmFastPaths, IntIndexedReadsBehaveTheSameInTheNativeTier) {
  std::string src = kIntIndex;
  // bad walks 0..9: scans trap at 0 and 9 in both tiers alike.
  src.replace(src.find("v := a[bad];"), 12, "bad := (bad + 1) MOD 10; v := a[bad];");
  same_in_both_tiers(src, 12);
}

}  // namespace
}  // namespace plcfi::st
