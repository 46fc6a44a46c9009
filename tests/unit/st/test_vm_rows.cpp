// Row offsets: in a FOR loop over a proven counter, a rank-2 access indexed by the counter
// and by a counter of an enclosing loop reads the offset of its row from a slot set once on
// the loop's entry (ROWS, LDXR/STXR). Every such access must reach the element the
// indices name: the same values as the program compiled without row offsets, in the
// interpreter and in the native tier, whatever the bounds, strides, steps and fields. So
// must a rank-1 access whose index is linear in the two counters (`a[i * 8 + k]`).
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

// A rank-2 table kept in a rank-1 array: one index linear in the loop's counter and an
// outer counter (v * C + w, C * v + w, w + v * C), proven inside the array by the
// counters' ranges, reaches its element through a row as a rank-2 access does: stores
// and loads of 1, 2, 4 and 8 bytes, the counter scaled or added, a lower bound of 1, a
// descending loop by 2. An index whose range is not inside the array stays checked.
const char* kLinear = R"(PROGRAM P
VAR
  flags : ARRAY [0..255] OF BOOL;
  w : ARRAY [0..63] OF DINT;
  v : ARRAY [1..16] OF INT;
  t : ARRAY [0..19] OF DINT;
  r8 : ARRAY [0..11] OF LREAL;
  q : ARRAY [0..15] OF DINT;
  i, k, top : DINT;
  seed : DINT := 5;
  s, ones, sv, st : DINT;
  r : LREAL;
  scan : DINT;
END_VAR
FOR i := 0 TO 31 DO
  seed := (seed * 1103 + 12345) MOD 65521;
  FOR k := 0 TO 7 DO
    flags[i * 8 + k] := ((seed / (k + 1)) MOD 3) = 0;
  END_FOR;
END_FOR;
ones := 0;
FOR i := 0 TO 31 DO
  FOR k := 7 TO 0 BY -2 DO
    IF flags[i * 8 + k] THEN ones := ones + k + i; END_IF;
  END_FOR;
END_FOR;
FOR i := 0 TO 7 DO
  FOR k := 0 TO 7 DO
    w[8 * i + k] := i * 100 - k * 7 + scan;
  END_FOR;
END_FOR;
s := 0;
FOR i := 0 TO 7 DO
  FOR k := 0 TO 7 DO
    s := (s * 3 + w[8 * i + k]) MOD 1000003;
  END_FOR;
END_FOR;
FOR i := 0 TO 3 DO
  FOR k := 1 TO 4 DO
    v[k + i * 4] := DINT_TO_INT(i * 10 + k - scan);
  END_FOR;
END_FOR;
sv := 0;
FOR i := 0 TO 3 DO
  FOR k := 1 TO 4 DO
    sv := sv * 5 + INT_TO_DINT(v[k + i * 4]);
  END_FOR;
END_FOR;
FOR i := 0 TO 4 DO
  FOR k := 0 TO 3 DO
    t[k * 5 + i] := i * k + scan;
  END_FOR;
END_FOR;
st := 0;
FOR i := 0 TO 3 DO
  FOR k := 0 TO 2 DO
    r8[i * 3 + k] := DINT_TO_LREAL(t[k * 5 + i]) * 0.5;
    st := st * 7 + t[k * 5 + i];
  END_FOR;
END_FOR;
r := 0.0;
FOR i := 0 TO 3 DO
  FOR k := 0 TO 2 DO
    r := r * 1.5 + r8[i * 3 + k];
  END_FOR;
END_FOR;
FOR i := 0 TO 3 DO
  FOR k := 0 TO top DO
    q[i * 4 + k] := i + k;   (* k up to top: not proven inside q *)
  END_FOR;
END_FOR;
FOR i := 0 TO 3 DO
  FOR k := 0 TO 4 DO
    IF k < 4 THEN
      q[i * 4 + k] := q[i * 4 + k] + 1;   (* i * 4 + k may reach 16: checked *)
    END_IF;
  END_FOR;
END_FOR;
scan := scan + 1;
END_PROGRAM
)";

TEST(VmRows, ALinearIndexOverTwoCountersReadsItsRowFromASlot) {
  Prog on(kLinear, true), off(kLinear, false);
  ASSERT_TRUE(on.ok());
  ASSERT_TRUE(off.ok());
  const std::string dis = on.disasm(), plain = off.disasm();
  EXPECT_EQ(2u, occurrences(dis, " STXL")) << dis;  // the accesses to q only
  EXPECT_EQ(1u, occurrences(dis, " LDXL")) << dis;
  for (const char* op : {" STXR1", " LDXR1", " STXR4", " LDXR4", " STXR2", " LDXR2", " STXR8", " LDXR8"})
    EXPECT_GE(occurrences(dis, op), 1u) << op << "\n" << dis;
  EXPECT_EQ(0u, occurrences(plain, "LDXR")) << plain;
  EXPECT_GE(occurrences(plain, " LDXL"), 5u) << plain;
  for (int scan = 0; scan < 4; ++scan) {
    for (Prog* p : {&on, &off}) p->set("P.top", scan == 2 ? 4 : 3);  // q[3 * 4 + 4] is past the end
    const bool ok = on.scan();
    ASSERT_EQ(off.scan(), ok) << "scan " << scan;
    EXPECT_EQ(scan != 2, ok) << "scan " << scan;
    if (!ok) {
      EXPECT_EQ(TrapKind::IndexOutOfRange, on.m->trap().kind);
      EXPECT_EQ("index 16 outside 0..15", on.m->trap().message);
      EXPECT_EQ(off.m->trap().message, on.m->trap().message);
      EXPECT_EQ(off.m->trap().loc.line, on.m->trap().loc.line);
    }
    for (const char* v : {"P.ones", "P.s", "P.sv", "P.st", "P.seed", "P.w[63]", "P.v[16]", "P.t[19]", "P.q[15]", "P.i", "P.k"})
      EXPECT_EQ(off.get(v), on.get(v)) << v << " after scan " << scan;
    EXPECT_EQ(off.real("P.r"), on.real("P.r")) << "after scan " << scan;
    EXPECT_EQ(off.real("P.r8[11]"), on.real("P.r8[11]")) << "after scan " << scan;
  }
  // By hand, after the last scan (scan = 2 during it: the trap in the third kept it from
  // counting): w[63] = 700 - 49 + 2, v[16] = 30 + 4 - 2, t[19] = 4 * 3 + 2, q[15] = 3 + 3 + 1.
  EXPECT_EQ(653, on.get("P.w[63]"));
  EXPECT_EQ(32, on.get("P.v[16]"));
  EXPECT_EQ(14, on.get("P.t[19]"));
  EXPECT_EQ(7, on.get("P.q[15]"));
}

TEST(VmRows, ALinearIndexComputesTheSameInTheNativeTier) {
  same_in_both_tiers("rows.st", kLinear, 4, 0, [](Machine& m, int scan) {
    std::string err;
    write_int(m, *resolve(m.app(), "P.top", &err), scan == 2 ? 4 : 3);
  });
}

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
