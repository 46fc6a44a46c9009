// An index v + K or v - K (v a DINT variable, K an integer literal) into a rank-1 frame
// array is one access that checks v against the bounds minus K. It must reach the element
// the sum names, trap where the sum traps, with the message the sum's check gives (the
// index and bounds of the source), in the interpreter and the native tier; and a store
// whose right-hand side may call something keeps the sum computed before it.
#include <gtest/gtest.h>

#include <string>

#include "engine.hpp"
#include "native/native.hpp"
#include "same_memory.hpp"
#include "vm_run.hpp"

namespace plcfi::st {
namespace {

struct Prog : vmtest::VmRun {
  explicit Prog(const std::string& src) : VmRun(src, {}, "disp.st") {}
};

const char* kDisplaced = R"(TYPE
  Item : STRUCT id : DINT; key : INT; w : REAL; END_STRUCT;
END_TYPE
PROGRAM P
VAR
  a : ARRAY [0..9] OF DINT;
  b : ARRAY [1..10] OF INT;
  items : ARRAY [0..4] OF Item;
  tmp : Item;
  i, j, s, t, u : DINT;
END_VAR
FOR i := 0 TO 9 DO a[i] := i * 10; END_FOR;
FOR i := 1 TO 10 DO b[i] := DINT_TO_INT(i); END_FOR;
FOR i := 0 TO 4 DO items[i].id := 100 + i; items[i].key := DINT_TO_INT(50 - i); END_FOR;
j := 4;
s := a[j - 1] + a[j + 1] * 1000 + a[2 + j] * 1000000;  (* 30 + 50000 + 60000000 *)
t := INT_TO_DINT(b[j + 6]) + INT_TO_DINT(b[j - 3]) * 100;  (* 10 + 100 *)
a[j + 2] := 7;                      (* stored at 6 *)
items[j - 1] := items[j - 4];       (* element 3 := element 0 *)
tmp := items[j - 2];                (* element 2 *)
u := INT_TO_DINT(items[j - 1].key) * 1000 + tmp.id;  (* 50 * 1000 + 102 *)
FOR i := 1 TO 9 DO u := u + a[i - 1]; END_FOR;  (* proven: the counter stays inside *)
END_PROGRAM
)";

TEST(VmDisplaced, AnIndexPlusAConstantIsOneAccessToTheElementItNames) {
  Prog p(kDisplaced);
  ASSERT_TRUE(p.ok());
  std::string dis = p.disasm();
  // No subtraction computes an index: the one SUB left is 50 - i's.
  size_t subs = 0;
  for (size_t at = dis.find("SUB_I32"); at != std::string::npos; at = dis.find("SUB_I32", at + 1)) ++subs;
  EXPECT_EQ(1u, subs) << dis;
  EXPECT_NE(std::string::npos, dis.find("LDXN4")) << dis;  // a[i - 1], i in 1..9
  EXPECT_NE(std::string::npos, dis.find("(index - 1)")) << dis;  // the listing names K
  EXPECT_NE(std::string::npos, dis.find("(index + 2)")) << dis;
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(30 + 50000 + 60000000, p.get("P.s"));
  EXPECT_EQ(10 + 100, p.get("P.t"));
  EXPECT_EQ(7, p.get("P.a[6]"));
  EXPECT_EQ(100, p.get("P.items[3].id"));
  EXPECT_EQ(50, p.get("P.items[3].key"));
  EXPECT_EQ(102, p.get("P.tmp.id"));
  // 50 * 1000 + 102, then a[0..8] = 0, 10, ..., 50, 7, 70, 80
  EXPECT_EQ(50102 + (0 + 10 + 20 + 30 + 40 + 50 + 7 + 70 + 80), p.get("P.u"));
}

TEST(VmDisplaced, BothTiersAgreeOnDisplacedAccesses) { same_in_both_tiers("disp.st", kDisplaced, 2); }

// Each access traps as the sum computed into a variable first traps: same kind, message
// and source line, in both tiers.
TEST(VmDisplaced, TrapsNameTheIndexAndBoundsOfTheSource) {
  struct Case {
    const char* what;
    const char* displaced;  // the access with v + K written in the index
    const char* summed;     // the same with the sum in k first
    const char* message;
  };
  const Case cases[] = {
      {"a read below the array", "s := a[j - 5];", "k := j - 5; s := a[k];", "index -1 outside 0..9"},
      {"a read past the array", "s := a[j + 6];", "k := j + 6; s := a[k];", "index 10 outside 0..9"},
      {"a literal first", "s := a[7 + j];", "k := 7 + j; s := a[k];", "index 11 outside 0..9"},
      {"a store", "a[j + 6] := 1;", "k := j + 6; a[k] := 1;", "index 10 outside 0..9"},
      {"a field of a structure element", "s := items[j + 1].id;", "k := j + 1; s := items[k].id;", "index 5 outside 0..4"},
      {"a whole structure element", "tmp := items[j - 5];", "k := j - 5; tmp := items[k];", "index -1 outside 0..4"},
      {"a whole element stored", "items[j + 3] := tmp;", "k := j + 3; items[k] := tmp;", "index 7 outside 0..4"},
      {"a lower bound of 1", "s := INT_TO_DINT(b[j - 4]);", "k := j - 4; s := INT_TO_DINT(b[k]);", "index 0 outside 1..10"},
      {"a FOR counter that leaves the array", "FOR i := 0 TO 9 DO s := s + a[i + 1]; END_FOR;",
       "FOR i := 0 TO 9 DO k := i + 1; s := s + a[k]; END_FOR;", "index 10 outside 0..9"},
      {"a sum that wraps", "j := 2147483647; s := a[j + 1];", "j := 2147483647; k := j + 1; s := a[k];",
       "index -2147483648 outside 0..9"},
  };
  for (const Case& c : cases) {
    for (const char* body : {c.displaced, c.summed}) {
      std::string src = std::string(R"(TYPE Item : STRUCT id : DINT; key : INT; END_STRUCT; END_TYPE
PROGRAM P
VAR a : ARRAY [0..9] OF DINT; b : ARRAY [1..10] OF INT; items : ARRAY [0..4] OF Item; tmp : Item;
    i, k, s : DINT; j : DINT := 4; END_VAR
)") + body + "\nEND_PROGRAM\n";
      auto bs = build_sources({{"disp.st", src}}, CompileOptions{});
      ASSERT_TRUE(bs->ok()) << c.what << "\n" << bs->diags.render_all();
      std::string err;
      auto native = NativeCode::build(*bs->app, NativeOptions{}, &err);
      ASSERT_TRUE(native) << err;
      Machine vm(*bs->app), nat(*bs->app);
      nat.set_native(native.get());
      const auto& inst = bs->app->programs.at(0);
      EXPECT_FALSE(vm.call(inst.pou->entry, inst.addr)) << c.what << ": " << body;
      EXPECT_FALSE(nat.call(inst.pou->entry, inst.addr)) << c.what << ": " << body;
      EXPECT_EQ(TrapKind::IndexOutOfRange, vm.trap().kind) << c.what << ": " << body;
      EXPECT_EQ(c.message, vm.trap().message) << c.what << ": " << body;
      EXPECT_EQ(describe_trap(*bs->app, vm.trap()), describe_trap(*bs->app, nat.trap())) << c.what << ": " << body;
      EXPECT_EQ(5, vm.trap().loc.line) << c.what << ": " << body;
    }
  }
}

// a[g + 1] := Bump() with Bump changing g: the element is the one g + 1 named before the
// call, as the source orders it (the index is not displaced there).
TEST(VmDisplaced, AStoreAfterACallUsesTheIndexComputedBeforeIt) {
  Prog p(R"(VAR_GLOBAL g : DINT := 2; END_VAR
FUNCTION Bump : DINT
g := g + 5;
Bump := 99;
END_FUNCTION
PROGRAM P
VAR a : ARRAY [0..9] OF DINT; END_VAR
a[g + 1] := Bump();
END_PROGRAM
)");
  ASSERT_TRUE(p.ok());
  ASSERT_TRUE(p.scan()) << p.m->trap().message;
  EXPECT_EQ(99, p.get("P.a[3]"));
  EXPECT_EQ(0, p.get("P.a[8]"));
  EXPECT_EQ(7, p.get("g"));
}

// What the rule leaves alone: an INT variable (its sum wraps at 16 bits), a typed
// literal, a product; each is computed as before and reaches the same element.
TEST(VmDisplaced, OnlyDintVariablesPlusUntypedLiteralsAreDisplaced) {
  Prog p(R"(PROGRAM P
VAR a : ARRAY [-5..5] OF DINT; n : INT := 32767; m : DINT := 2; s, t : DINT; END_VAR
a[-5] := 11; a[4] := 44; a[3] := 33;
s := a[m * 2];          (* a product: 4 *)
t := a[m + DINT#1];     (* a typed literal: 3 *)
s := s * 100 + t;
t := a[n + 1];          (* INT: 32767 + 1 wraps to -32768, outside -5..5 *)
END_PROGRAM
)");
  ASSERT_TRUE(p.ok());
  EXPECT_FALSE(p.scan());
  EXPECT_EQ(4433, p.get("P.s"));
  EXPECT_EQ("index -32768 outside -5..5", p.m->trap().message);
}

}  // namespace
}  // namespace plcfi::st
