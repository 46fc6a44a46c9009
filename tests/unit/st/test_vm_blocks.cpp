// Block moves of run-time size (whole structures, array elements of structure type,
// strings of fixed size) are done inline up to 16 bytes: every size from 0 to 40 and
// every overlap of source and destination gives what memmove gives, and structures of
// 1 to 24 bytes keep every field when copied whole, in the interpreter and the native tier.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <numeric>
#include <string>

#include "engine.hpp"
#include "native/native.hpp"
#include "same_memory.hpp"
#include "vm/ops.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

TEST(VmBlocks, MoveBlockAndMoveElementAreMemmoveForEverySizeAndOverlap) {
  constexpr int kSpan = 96;
  for (size_t n = 0; n <= 40; ++n) {
    for (int from = 0; from + static_cast<int>(n) <= kSpan; from += 3) {
      for (int to = 0; to + static_cast<int>(n) <= kSpan; to += 5) {
        std::array<uint8_t, kSpan> want{}, got{};
        std::iota(want.begin(), want.end(), uint8_t{1});
        got = want;
        std::memmove(want.data() + to, want.data() + from, n);
        ops::move_block(got.data() + to, got.data() + from, n);
        ASSERT_EQ(want, got) << "n " << n << " from " << from << " to " << to;
        // The structure elements' copy (pieces that do not overlap) gives the same.
        std::iota(got.begin(), got.end(), uint8_t{1});
        ops::move_element(got.data() + to, got.data() + from, n);
        ASSERT_EQ(want, got) << "move_element: n " << n << " from " << from << " to " << to;
      }
    }
  }
}

// Structures of 1, 2, 3, 5, 6, 7, 9, 12, 16, 17 and 24 bytes, moved whole between
// variables, array elements (LDXB/STXB), globals and through a VAR_IN_OUT.
const char* kBlocks = R"(TYPE
  S1 : STRUCT a : BYTE; END_STRUCT;
  S2 : STRUCT a : BYTE; b : BYTE; END_STRUCT;
  S3 : STRUCT a : BYTE; b : BYTE; c : BYTE; END_STRUCT;
  S5 : STRUCT a : BYTE; b : BYTE; c : BYTE; d : BYTE; e : BYTE; END_STRUCT;
  S6 : STRUCT a : INT; b : INT; c : INT; END_STRUCT;
  S7 : STRUCT a : BYTE; b : BYTE; c : BYTE; d : BYTE; e : BYTE; f : BYTE; g : BYTE; END_STRUCT;
  S9 : STRUCT a : BYTE; b : BYTE; c : BYTE; d : BYTE; e : BYTE; f : BYTE; g : BYTE; h : BYTE; i : BYTE; END_STRUCT;
  S12 : STRUCT id : DINT; key : INT; w : REAL; END_STRUCT;
  S16 : STRUCT a : LINT; b : DINT; c : DINT; END_STRUCT;
  S17 : STRUCT a : LINT; b : LINT; c : BYTE; END_STRUCT;
  S24 : STRUCT a : LINT; b : LINT; c : LREAL; END_STRUCT;
END_TYPE
VAR_GLOBAL
  g12 : S12;
END_VAR
FUNCTION_BLOCK Swap
VAR_IN_OUT x : S12; y : S12; END_VAR
VAR t : S12; END_VAR
t := x; x := y; y := t;
END_FUNCTION_BLOCK
PROGRAM P
VAR
  a1 : ARRAY [0..3] OF S1; a2 : ARRAY [0..3] OF S2; a3 : ARRAY [0..3] OF S3;
  a5 : ARRAY [0..3] OF S5; a6 : ARRAY [0..3] OF S6; a7 : ARRAY [0..3] OF S7;
  a9 : ARRAY [0..3] OF S9; a12 : ARRAY [0..3] OF S12; a16 : ARRAY [0..3] OF S16;
  a17 : ARRAY [0..3] OF S17; a24 : ARRAY [0..3] OF S24;
  t3 : S3; t7 : S7; t12 : S12; t17 : S17;
  i : DINT; j : DINT; n : DINT;
  sw : Swap;
  sum : LINT;
END_VAR
n := n + 1;
FOR i := 0 TO 3 DO
  a1[i].a := DINT_TO_BYTE(i + n);
  a2[i].a := DINT_TO_BYTE(i + n); a2[i].b := DINT_TO_BYTE(i * 2 + n);
  a3[i].a := DINT_TO_BYTE(i + n); a3[i].b := DINT_TO_BYTE(i * 3); a3[i].c := DINT_TO_BYTE(i * 5 + n);
  a5[i].a := DINT_TO_BYTE(i); a5[i].e := DINT_TO_BYTE(i * 7 + n);
  a6[i].a := DINT_TO_INT(i * 100 + n); a6[i].c := DINT_TO_INT(-i - n);
  a7[i].a := DINT_TO_BYTE(i); a7[i].d := DINT_TO_BYTE(i + 9); a7[i].g := DINT_TO_BYTE(i * 11 + n);
  a9[i].a := DINT_TO_BYTE(i); a9[i].h := DINT_TO_BYTE(i + 3); a9[i].i := DINT_TO_BYTE(i * 13 + n);
  a12[i].id := i * 1000 + n; a12[i].key := DINT_TO_INT(i - 7); a12[i].w := DINT_TO_REAL(i) * 0.5;
  a16[i].a := DINT_TO_LINT(i) * 4294967296 + n; a16[i].c := -i;
  a17[i].a := DINT_TO_LINT(i + n); a17[i].b := DINT_TO_LINT(-i); a17[i].c := DINT_TO_BYTE(i + 200);
  a24[i].a := DINT_TO_LINT(i); a24[i].c := DINT_TO_LREAL(i + n) * 0.25;
END_FOR;
(* rotate each array by one element: whole elements in and out of a temporary and of
   their neighbours, as an insertion sort does *)
FOR i := 3 TO 1 BY -1 DO
  j := i - 1;
  a1[i] := a1[j]; a2[i] := a2[j]; a5[i] := a5[j]; a6[i] := a6[j];
  a9[i] := a9[j]; a16[i] := a16[j]; a24[i] := a24[j];
  t3 := a3[i]; a3[i] := a3[j]; a3[j] := t3;
  t7 := a7[j]; a7[j] := a7[i]; a7[i] := t7;
  t12 := a12[i]; a12[i] := a12[j]; a12[j] := t12;
  t17 := a17[j]; a17[j] := a17[i]; a17[i] := t17;
END_FOR;
g12 := a12[2];
sw(x := g12, y := a12[0]);
sum := BYTE_TO_LINT(a1[0].a) + BYTE_TO_LINT(a1[1].a) * 10 + BYTE_TO_LINT(a2[1].b) * 100
     + BYTE_TO_LINT(a3[0].c) * 1000 + BYTE_TO_LINT(a5[3].e) * 10000 + INT_TO_LINT(a6[2].c)
     + BYTE_TO_LINT(a7[0].g) + BYTE_TO_LINT(a9[3].i) + DINT_TO_LINT(a12[0].id) + INT_TO_LINT(g12.key)
     + a16[2].a + a17[3].b + BYTE_TO_LINT(a17[0].c) + LREAL_TO_LINT(a24[1].c * 4.0);
END_PROGRAM
)";

TEST(VmBlocks, StructuresOfEverySizeKeepTheirFieldsWhenMovedWhole) {
  vmtest::VmRun p(kBlocks, {}, "blocks.st");
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  EXPECT_NE(std::string::npos, dis.find("LDXB")) << dis;
  EXPECT_NE(std::string::npos, dis.find("STXB")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  // n = 1; e0..e3 are the elements as the first loop wrote them. The copied arrays end
  // as [e0, e0, e1, e2]; the swapped ones (a3, a7, a12, a17) as [e3, e0, e1, e2].
  EXPECT_EQ(1, p.get("P.a1[0].a"));
  EXPECT_EQ(1, p.get("P.a1[1].a"));
  EXPECT_EQ(3, p.get("P.a2[2].b"));            // e1.b = 1 * 2 + 1
  EXPECT_EQ(16, p.get("P.a3[0].c"));           // e3.c = 3 * 5 + 1
  EXPECT_EQ(0, p.get("P.a3[1].b"));            // e0.b
  EXPECT_EQ(6, p.get("P.a3[3].b"));            // e2.b
  EXPECT_EQ(15, p.get("P.a5[3].e"));           // e2.e = 2 * 7 + 1
  EXPECT_EQ(-2, p.get("P.a6[2].c"));           // e1.c = -1 - 1
  EXPECT_EQ(101, p.get("P.a6[2].a"));          // e1.a
  EXPECT_EQ(34, p.get("P.a7[0].g"));           // e3.g = 3 * 11 + 1
  EXPECT_EQ(12, p.get("P.a7[0].d"));           // e3.d
  EXPECT_EQ(27, p.get("P.a9[3].i"));           // e2.i = 2 * 13 + 1
  EXPECT_EQ(5, p.get("P.a9[3].h"));            // e2.h = 2 + 3
  EXPECT_EQ(1001, p.get("P.a12[0].id"));       // e1 after the swap with g12
  EXPECT_EQ(-6, p.get("P.a12[0].key"));
  EXPECT_EQ(2001, p.get("P.a12[3].id"));       // e2
  EXPECT_EQ(4294967297, p.get("P.a16[2].a"));  // e1.a
  EXPECT_EQ(-1, p.get("P.a16[2].c"));
  EXPECT_EQ(-2, p.get("P.a17[3].b"));          // e2.b
  EXPECT_EQ(203, p.get("P.a17[0].c"));         // e3.c
  EXPECT_EQ(4, p.get("P.a17[0].a"));           // e3.a
}

TEST(VmBlocks, StructureMovesAgreeWithTheNativeTier) { same_in_both_tiers("blocks.st", kBlocks, 3); }

// An element copied to another element (`a[j] := a[j - 1]`: LDXB to a temporary block,
// STXB from it): the native tier copies from the source element itself. The same and
// neighbouring elements, two arrays, indices computed into temporaries, an index the
// STXB refuses: memory must be what the interpreter leaves, byte for byte, traps
// included.
const char* kElementCopies = R"(TYPE
  Item : STRUCT id : DINT; key : INT; w : REAL; END_STRUCT;
END_TYPE
PROGRAM P
VAR
  a : ARRAY [0..9] OF Item;
  b : ARRAY [1..4] OF Item;
  i, j, k, n, bad : DINT;
  flag : BOOL;
END_VAR
FOR i := 0 TO 9 DO
  a[i].id := i * 11 + n; a[i].key := DINT_TO_INT(i - n); a[i].w := DINT_TO_REAL(i) * 0.5;
END_FOR;
FOR j := 9 TO 1 BY -1 DO
  a[j] := a[j - 1];
END_FOR;
a[3] := a[3];
FOR k := 1 TO 4 DO
  b[k] := a[k * 2 - 1];
END_FOR;
IF flag THEN
  a[0] := b[2];
END_IF;
a[n MOD 10] := b[(n MOD 4) + 1];
a[bad] := b[1];
n := n + 1;
flag := NOT flag;
END_PROGRAM
)";

TEST(VmBlocks, ElementToElementCopiesAgreeWithTheNativeTier) {
  auto b = build_sources({{"blocks.st", kElementCopies}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  std::vector<uint32_t> entries, skipped;
  const std::string cpp = native_source(*b->app, &entries, &skipped);
  // a[j] := a[j - 1], b[k] := a[k * 2 - 1], a[n MOD 10] := b[(n MOD 4) + 1]; the others
  // read a constant element, which is no LDXB (a[0] := b[2] is one MOVN, a[bad] := b[1]
  // an STXB from b[1]'s bytes).
  EXPECT_EQ(3u, vmtest::occurrences(cpp, "uint8_t b_[12u]")) << cpp;
  same_in_both_tiers("blocks.st", kElementCopies, 4, 0, [](Machine& m, int scan) {
    std::string err;
    write_int(m, *resolve(m.app(), "P.bad", &err), scan == 2 ? 10 : scan);
  });
}

// Rule 21: the interpreter runs an element-to-element copy (LDXB into a temporary, STXB
// from it) as one handler. The copies above are fused; an index refused on either side
// traps at the same instruction, with the same message, as the plain pair.
TEST(VmBlocks, ElementToElementCopiesAreOneHandlerInTheInterpreter) {
  auto fused = [](const std::string& src) {
    vmtest::VmRun p(src, {}, "blocks.st");
    if (!p.ok()) return size_t{0};
    p.scan();
    size_t n = 0;
    for (const auto& [pc, name] : p.m->superinstructions()) n += name.starts_with("LDXB+STXB");
    return n;
  };
  EXPECT_EQ(3u, fused(kElementCopies));
  // The source runs out first (s = 6 on the fourth scan), or the destination (d = 5 on
  // the third).
  for (const char* steps : {"ds : DINT := 2; dd : DINT := 1;", "ds : DINT := 1; dd : DINT := 2;"}) {
    const std::string refused = std::string(R"(TYPE
  Item : STRUCT id : DINT; key : INT; END_STRUCT;
END_TYPE
PROGRAM P
VAR a : ARRAY [0..4] OF Item; s : DINT; d : DINT := 1; n : DINT; )") + steps + R"( END_VAR
a[0].id := n + 10; a[0].key := DINT_TO_INT(n * 3);
a[d] := a[s];
s := s + ds; d := d + dd; n := n + 1;
END_PROGRAM
)";
    EXPECT_EQ(1u, fused(refused));
    same_in_both_tiers("blocks.st", refused, 5);
    vmtest::VmRun p(refused, {}, "blocks.st");
    ASSERT_TRUE(p.ok());
    const bool source_first = steps[13] == '2';
    const int good = source_first ? 3 : 2;
    for (int k = 0; k < good; ++k) ASSERT_TRUE(p.scan()) << k;
    EXPECT_EQ(p.get("P.a[1].id"), 10);  // a[1] := a[0] on the first scan
    EXPECT_EQ(p.get("P.a[1].key"), 0);
    EXPECT_FALSE(p.scan());
    EXPECT_EQ(p.m->trap().kind, TrapKind::IndexOutOfRange);
    EXPECT_EQ(p.m->trap().loc.line, 7u);
    EXPECT_NE(p.m->trap().message.find(source_first ? "6" : "5"), std::string::npos) << p.m->trap().message;
  }
}


// Rule 31: the temporary an element-to-element copy goes through is scratch within its
// statement, so the fused handler copies element to element and leaves it out, unless the
// instruction after the pair names the temporary's offset (it might read it: then the
// temporary is written as the LDXB writes it). Both kinds run here; the values are the
// native tier's, which never writes such temporaries.
TEST(VmBlocks, ElementCopiesLeaveTheTemporaryOutWhereNothingReadsIt) {
  const char* src = R"(TYPE
  Item : STRUCT id : DINT; key : INT; w : REAL; END_STRUCT;
END_TYPE
PROGRAM P
VAR a : ARRAY [0..9] OF Item; b : ARRAY [0..9] OF Item; i : DINT; n : DINT; END_VAR
FOR i := 0 TO 9 DO
  a[i].id := i + n * 100; a[i].key := DINT_TO_INT(i * 3 - n); a[i].w := DINT_TO_REAL(n) * 0.25;
END_FOR;
i := n MOD 9;
a[i + 1] := a[i];
b[i] := a[i + 1];
b[9 - i] := b[i];
n := n + 1;
END_PROGRAM
)";
  vmtest::VmRun p(src, {}, "temps.st");
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan());
  size_t direct = 0, kept = 0;
  for (const auto& [pc, name] : p.m->superinstructions()) {
    direct += name == "LDXB+STXB (no temporary)";
    kept += name == "LDXB+STXB";
  }
  // The first two copies are followed by the next copy's LDXB into the same temporary.
  EXPECT_EQ(kept, 2u);
  EXPECT_EQ(direct, 1u);
  for (int k = 1; k < 12; ++k) ASSERT_TRUE(p.scan());
  // After the 12th scan (n = 11 during it): i = 2, a[3] := a[2], b[2] := a[3], b[7] := b[2].
  EXPECT_EQ(p.get("P.b[7].id"), 2 + 11 * 100);
  EXPECT_EQ(p.get("P.b[7].key"), 2 * 3 - 11);
  EXPECT_EQ(p.get("P.a[3].id"), 2 + 11 * 100);
  same_in_both_tiers("temps.st", src, 12);
}

}  // namespace
}  // namespace plcfi::st
