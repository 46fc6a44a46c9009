// Row offsets: in a FOR loop over a proven counter, a rank-2 access indexed by the counter
// and by a counter of an enclosing loop reads the offset of its row from a slot set once on
// the loop's entry (ROWS, LDXR/STXR). Every such access must reach the element the
// indices name: the same values as the program compiled without row offsets, in the
// interpreter and in the native tier, whatever the bounds, strides, steps and fields.
#include <gtest/gtest.h>

#include <string>

#include "engine.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

struct Prog : vmtest::VmRun {
  explicit Prog(const std::string& src, bool rows) : VmRun(src, options(rows), "rows.st") {}
  static CompileOptions options(bool rows) {
    CompileOptions o;
    o.row_offsets = rows;
    return o;
  }
};

using vmtest::occurrences;

// Lower bounds other than 0, a row-major and a column-major walk, stores by the counter as
// the first index, a displaced index, a descending loop and a step of 2, structure fields
// of every width, a rank-3 array with a literal index, and a row kept across a middle loop.
const char* kRows = R"(TYPE
  Rec : STRUCT x : INT; y : LREAL; f : BYTE; END_STRUCT;
END_TYPE
PROGRAM P
VAR
  a : ARRAY [1..4, -2..3] OF DINT;
  b : ARRAY [-2..3, 1..4] OF DINT;
  m : ARRAY [0..5, 0..2] OF DINT;
  recs : ARRAY [0..2, 0..3] OF Rec;
  c3 : ARRAY [0..1, 1..4, -2..3] OF INT;
  bytes : ARRAY [1..4, 0..7] OF BYTE;
  i, j, k : DINT;
  seed : DINT := 7;
  s, t, u, v, w : DINT;
  r : LREAL;
  scan : DINT;
END_VAR
FOR i := 1 TO 4 DO
  FOR k := -2 TO 3 DO
    seed := (seed * 1103 + 12345) MOD 65521;
    a[i, k] := seed MOD 1000 - 500;
    b[k, i] := a[i, k] * 3 + scan;
  END_FOR;
END_FOR;
s := 0;
FOR i := 1 TO 4 DO
  FOR k := -2 TO 2 DO
    s := s + a[i, k] * b[k + 1, i] - a[i, k + 1];
  END_FOR;
END_FOR;
t := 0;
FOR i := 1 TO 4 DO
  FOR k := 3 TO -2 BY -1 DO
    t := t * 3 + a[i, k] MOD 97;
    t := t MOD 1000003;
  END_FOR;
  FOR k := -2 TO 3 BY 2 DO
    t := t + b[k, i];
  END_FOR;
END_FOR;
FOR i := 0 TO 5 DO
  FOR k := 0 TO 2 DO
    m[i, k] := i * 10 + k + scan;
  END_FOR;
END_FOR;
u := 0;
FOR i := 1 TO 4 DO
  FOR j := 0 TO 2 DO
    FOR k := -2 TO 3 DO
      u := (u + a[i, k] * m[k + 2, j]) MOD 1000003;
    END_FOR;
  END_FOR;
END_FOR;
FOR i := 0 TO 2 DO
  FOR k := 0 TO 3 DO
    recs[i, k].x := DINT_TO_INT(i * 100 + k - scan);
    recs[i, k].y := DINT_TO_LREAL(recs[i, k].x) * 0.5;
    recs[i, k].f := DINT_TO_BYTE(i * 16 + k + scan);
  END_FOR;
END_FOR;
v := 0;
r := 0.0;
FOR k := 0 TO 3 DO
  FOR i := 0 TO 2 DO
    v := v + INT_TO_DINT(recs[i, k].x) * 7 + BYTE_TO_DINT(recs[i, k].f);
    r := r + recs[i, k].y;
  END_FOR;
END_FOR;
w := 0;
FOR i := 1 TO 4 DO
  FOR k := -2 TO 3 DO
    c3[1, i, k] := DINT_TO_INT(i * k + scan);
    c3[0, i, k] := DINT_TO_INT(-i);
  END_FOR;
  FOR k := 0 TO 7 DO
    bytes[i, k] := DINT_TO_BYTE(i + k * 3);
  END_FOR;
END_FOR;
FOR k := -2 TO 3 DO
  FOR i := 1 TO 4 DO
    w := w + INT_TO_DINT(c3[1, i, k]) * 11 + INT_TO_DINT(c3[0, i, k]);
  END_FOR;
END_FOR;
FOR i := 1 TO 4 DO
  FOR k := 0 TO 7 DO
    w := w + BYTE_TO_DINT(bytes[i, k]);
  END_FOR;
END_FOR;
scan := scan + 1;
END_PROGRAM
)";

TEST(VmRows, RankTwoAccessesInALoopReadTheirRowFromASlotSetOnEntry) {
  Prog on(kRows, true), off(kRows, false);
  ASSERT_TRUE(on.ok());
  ASSERT_TRUE(off.ok());
  const std::string dis = on.disasm(), plain = off.disasm();
  EXPECT_GE(occurrences(dis, "ROWS "), 10u) << dis;
  EXPECT_GE(occurrences(dis, "LDXR"), 10u) << dis;
  EXPECT_GE(occurrences(dis, "STXR"), 6u) << dis;
  EXPECT_EQ(0u, occurrences(dis, "LDXXN")) << dis;  // every proven rank-2 access went through a row
  EXPECT_EQ(0u, occurrences(plain, "ROWS ")) << plain;
  EXPECT_EQ(0u, occurrences(plain, "LDXR")) << plain;
  for (int scan = 0; scan < 5; ++scan) {
    ASSERT_TRUE(on.scan()) << on.m->trap().message;
    ASSERT_TRUE(off.scan()) << off.m->trap().message;
    for (const char* v : {"P.s", "P.t", "P.u", "P.v", "P.w", "P.seed", "P.a[4, 3]", "P.b[3, 4]", "P.m[5, 2]",
                          "P.recs[2, 3].x", "P.recs[2, 3].f", "P.c3[1, 4, 3]", "P.bytes[4, 7]"})
      EXPECT_EQ(off.get(v), on.get(v)) << v << " after scan " << scan;
    EXPECT_EQ(off.real("P.r"), on.real("P.r")) << "after scan " << scan;
  }
  // Values a reader can check by hand: m[5, 2] = 50 + 2 + 4 (the last scan's), w's bytes.
  EXPECT_EQ(56, on.get("P.m[5, 2]"));
  EXPECT_EQ(4 + 7 * 3, on.get("P.bytes[4, 7]"));
}

TEST(VmRows, TheNativeTierComputesTheSameElements) { same_in_both_tiers("rows.st", kRows, 5); }

// Where the other index is not a counter of an enclosing loop, or the loop's counter is
// not proven, the access computes its whole offset as before.
TEST(VmRows, OnlyCountersOfEnclosingLoopsGetARow) {
  Prog p(R"(PROGRAM P
VAR
  a : ARRAY [0..3, 0..3] OF DINT;
  i, k, n, s : DINT;
END_VAR
n := 2;
FOR k := 0 TO 3 DO
  a[n, k] := k;          (* n is no counter *)
END_FOR;
FOR i := 0 TO 3 DO
  FOR k := 0 TO 3 DO
    a[i, k] := a[i, k] + i;
    IF k = 9 THEN i := 0; END_IF;   (* the body may change i: i is not proven *)
  END_FOR;
END_FOR;
FOR i := 0 TO 3 DO
  FOR k := 0 TO 3 DO
    s := s + a[k, k];    (* both indices the inner counter *)
  END_FOR;
END_FOR;
END_PROGRAM
)",
         true);
  ASSERT_TRUE(p.ok());
  const std::string dis = p.disasm();
  EXPECT_EQ(0u, occurrences(dis, "LDXR")) << dis;
  EXPECT_EQ(0u, occurrences(dis, "STXR")) << dis;
  EXPECT_EQ(0u, occurrences(dis, "ROWS ")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(3 + 2, p.get("P.a[2, 3]"));
  EXPECT_EQ(4 * (0 + 1 + 4 + 3), p.get("P.s"));
}

}  // namespace
}  // namespace plcfi::st
