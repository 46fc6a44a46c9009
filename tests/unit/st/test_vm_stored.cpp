// A load of the element the instruction just before stored (x[i] := v; IF x[i] ...) is
// not emitted: its value is read from the slot the store read. The program must compute
// what it computes when the two are kept apart by another statement, in every access
// form (rank 1 checked and proven, structure fields, a linear index, rank 2, row offsets)
// and in both tiers; a jump target between them, another field, a stored variable or an
// index the store may overwrite keep the load.
#include <gtest/gtest.h>

#include <string>

#include "engine.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

using vmtest::occurrences;

// `@` marks where a store is followed by a load of the same element; `apart` puts a
// statement there, which keeps every load.
std::string program(bool apart) {
  std::string src = R"(TYPE
  Rec : STRUCT x : INT; y : LREAL; f : BYTE; END_STRUCT;
END_TYPE
PROGRAM P
VAR
  a : ARRAY [0..15] OF DINT;
  b : ARRAY [1..8, 0..3] OF INT;
  c : ARRAY [0..5, 0..5] OF DINT;
  recs : ARRAY [0..7] OF Rec;
  flags, bits : ARRAY [0..63] OF BOOL;
  i, j, k, n, m : DINT;
  seed : DINT := 11;
  s : DINT;
  r : LREAL;
  pad : DINT;
  eight : DINT := 8;  (* a variable: the linear index stays LDXL, not a row *)
END_VAR
FOR i := 0 TO 15 DO
  seed := (seed * 1103 + 12345) MOD 65521;
  a[i] := seed MOD 100 - 50;
  @
  IF a[i] > 0 THEN
    s := s + a[i];
  END_IF;
END_FOR;
n := seed MOD 16;
a[n] := n * 3 + s MOD 11;
@
s := s + a[n] * 2;
FOR i := 0 TO 7 DO
  recs[i].x := DINT_TO_INT(i * 7 - seed MOD 5);
  @
  s := s + recs[i].x;
  recs[i].y := DINT_TO_LREAL(s) * 0.5;
  @
  r := r + recs[i].y;
  recs[i].f := DINT_TO_BYTE(s);
  @
  s := s + BYTE_TO_DINT(recs[i].f) + recs[i].x;
END_FOR;
j := seed MOD 8;
recs[j].x := 5;
@
s := s + recs[j].x;
FOR i := 1 TO 8 DO
  FOR k := 0 TO 3 DO
    b[i, k] := DINT_TO_INT(i * k + s MOD 7);
    @
    s := s + b[i, k];
  END_FOR;
END_FOR;
n := 1 + seed MOD 7;
m := seed MOD 4;
b[n, m] := DINT_TO_INT(s MOD 1000);
@
s := s - b[n, m];
FOR i := 0 TO 7 DO
  FOR k := 0 TO 7 DO
    flags[i * eight + k] := ((s + k + i) MOD 3) = 0;
    @
    IF flags[i * eight + k] = bits[i * eight + k] THEN
      n := n + 1;
    END_IF;
    bits[i * eight + k] := NOT flags[i * eight + k];
  END_FOR;
END_FOR;
m := seed MOD 6;
c[m, m] := s MOD 97 + m;
@
s := s + c[m, m];
s := s MOD 1000003;
END_PROGRAM
)";
  for (size_t at = src.find('@'); at != std::string::npos; at = src.find('@', at))
    src.replace(at, 1, apart ? "pad := pad + 1;" : "");
  return src;
}

TEST(VmStored, ALoadRightAfterAStoreOfTheElementReadsTheStoredValue) {
  // Without rule 27, which would spare the apart program's a[i] in the IF's body too.
  CompileOptions opt;
  opt.elsif_reuse = false;
  vmtest::VmRun next(program(false), opt, "stored.st"), apart(program(true), opt, "stored.st");
  ASSERT_TRUE(next.ok());
  ASSERT_TRUE(apart.ok());
  const std::string dis = next.disasm(), kept = apart.disasm();
  // Forwarded, one load each: a[i] (LDXN), a[n] (LDX), recs[i].x, .y and .f (LDXSN),
  // recs[j].x := 5 (a constant, LDXS), b[i, k] (row offsets: LDXR), b[n, m] and c[m, m]
  // (LDXX), flags[i * eight + k] (LDXL). Kept: the a[i] in the IF's body (a jump between),
  // recs[i].x after the store of .f (another field), the loads after those.
  EXPECT_EQ(occurrences(kept, " LDXN4") - 1, occurrences(dis, " LDXN4")) << dis;
  EXPECT_EQ(occurrences(kept, " LDX4") - 1, occurrences(dis, " LDX4")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXSN2") - 1, occurrences(dis, " LDXSN2")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXSN8") - 1, occurrences(dis, " LDXSN8")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXSN1") - 1, occurrences(dis, " LDXSN1")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXS2") - 1, occurrences(dis, " LDXS2")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXR2") - 1, occurrences(dis, " LDXR2")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXX2") - 1, occurrences(dis, " LDXX2")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXX4") - 1, occurrences(dis, " LDXX4")) << dis;
  EXPECT_EQ(occurrences(kept, " LDXL1") - 1, occurrences(dis, " LDXL1")) << dis;
  for (int scan = 0; scan < 5; ++scan) {
    ASSERT_TRUE(next.scan()) << next.m->trap().message;
    ASSERT_TRUE(apart.scan()) << apart.m->trap().message;
    for (const char* v : {"P.s", "P.n", "P.m", "P.seed", "P.a[15]", "P.b[8, 3]", "P.recs[7].x", "P.recs[7].f", "P.c[5, 5]"})
      EXPECT_EQ(apart.get(v), next.get(v)) << v << " after scan " << scan;
    EXPECT_EQ(apart.real("P.r"), next.real("P.r")) << "after scan " << scan;
    EXPECT_EQ(apart.real("P.recs[3].y"), next.real("P.recs[3].y")) << "after scan " << scan;
  }
}

TEST(VmStored, TheNativeTierComputesTheSame) { same_in_both_tiers("stored.st", program(false), 5); }

// A variable stored keeps its load (a call in the statement could change the variable),
// and so does an index the store may overwrite: here the index shares its bytes with
// the array's first element, so a[u.i] := 3 sets the index to 3 and the load that follows
// reads element 3.
TEST(VmStored, AStoredVariableOrAnIndexInsideTheArrayKeepsTheLoad) {
  CompileOptions codesys;
  codesys.dialect = Dialect::Codesys;
  vmtest::VmRun r(R"(TYPE
  U : UNION
    a : ARRAY [0..7] OF DINT;
    i : DINT;
  END_UNION;
END_TYPE
PROGRAM P
VAR
  u : U;
  x : ARRAY [0..7] OF DINT;
  v : DINT := 42;
  k : DINT := 2;
  y, z : DINT;
END_VAR
u.a[3] := 1000;
u.i := 0;
u.a[u.i] := 3;
y := u.a[u.i];
x[k] := v;
z := x[k];
END_PROGRAM
)",
                  codesys, "stored.st");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan()) << r.m->trap().message;
  EXPECT_EQ(3, r.get("P.u.i"));
  EXPECT_EQ(1000, r.get("P.y"));  // element 3, read after the store moved the index
  EXPECT_EQ(42, r.get("P.z"));
  const std::string dis = r.disasm();
  EXPECT_EQ(2u, occurrences(dis, " LDX4")) << dis;  // both loads stay
}

}  // namespace
}  // namespace plcfi::st
