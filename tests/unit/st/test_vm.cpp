// The VM: every trap kind with its location and message, recovery after a trap, integer wraparound and division semantics, no heap allocation per scan, branch coverage bits.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <string>

#include "engine.hpp"
#include "vm_run.hpp"

// The replacements below forward to malloc/free on purpose; GCC cannot see that they pair up.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

// Counts every heap allocation of the process (forwarded to malloc/free); the scan test
// compares the count before and after 1000 calls.
namespace {
std::atomic<uint64_t> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace plcfi::st {
namespace {

using vmtest::VmRun;

// ------------------------------------------------------------------ traps

const char* kDivide = R"(PROGRAM Main
VAR a : DINT := 10; z : DINT; q : DINT; op : INT; END_VAR
IF op = 0 THEN
  q := a / z;
ELSIF op = 1 THEN
  q := a MOD z;
ELSE
  q := a + 1;
END_IF;
END_PROGRAM
)";

TEST(VmTrap, IntegerDivisionByZeroAtTheDivision) {
  VmRun r(kDivide);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::DivisionByZero, r.m->trap().kind);
  EXPECT_EQ(4u, r.m->trap().loc.line);
  EXPECT_EQ(8u, r.m->trap().loc.col);
  EXPECT_EQ("integer division by zero", r.m->trap().message);
  EXPECT_EQ("vm.st:4:8: runtime error[ST501]: division by zero: integer division by zero",
            describe_trap(*r.b->app, r.m->trap()));
  EXPECT_EQ(0, r.get("Main.q"));  // the trapping assignment did not happen
}

TEST(VmTrap, ModByZeroIsZeroAsIecDefinesIt) {
  VmRun r(kDivide);
  ASSERT_TRUE(r.ok());
  r.set("Main.op", 1);
  r.set("Main.q", 99);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(0, r.get("Main.q"));
}

TEST(VmTrap, ModByZeroTrapsUnderCodesysAsTheTargetDoes) {
  CompileOptions opt;
  opt.dialect = Dialect::Codesys;
  VmRun r(kDivide, opt);
  ASSERT_TRUE(r.ok());
  r.set("Main.op", 1);
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::DivisionByZero, r.m->trap().kind);
  EXPECT_EQ(6u, r.m->trap().loc.line);
  EXPECT_EQ(8u, r.m->trap().loc.col);
  EXPECT_EQ("MOD by zero", r.m->trap().message);
  EXPECT_STREQ("ST501", trap_code(r.m->trap().kind));
}

TEST(VmTrap, MachineRunsNormallyAfterADivisionTrap) {
  VmRun r(kDivide);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scan());
  r.set("Main.op", 2);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(TrapKind::None, r.m->trap().kind);
  EXPECT_EQ(11, r.get("Main.q"));
  r.set("Main.op", 0);
  r.set("Main.z", 3);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(3, r.get("Main.q"));
}

TEST(VmTrap, RealDivisionByZeroDoesNotTrap) {
  VmRun r("PROGRAM Main\nVAR x : LREAL := 1.0; z : LREAL; q : LREAL; END_VAR\nq := x / z;\nEND_PROGRAM\n");
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.scan());
  EXPECT_TRUE(std::isinf(read_real(*r.m, r.h("Main.q"))));
}

const char* kIndex = R"(PROGRAM Main
VAR
  arr : ARRAY [1..5] OF INT;
  grid : ARRAY [0..2, 0..3] OF DINT;
  i : DINT := 7;
  j : INT;
  x : INT;
  op : INT;
END_VAR
CASE op OF
  0: x := arr[i];
  1: arr[i] := 3;
  2: grid[1, j] := 5;
ELSE
  arr[1] := 9;
END_CASE;
END_PROGRAM
)";

TEST(VmTrap, ArrayReadOutOfRangeNamesIndexAndBounds) {
  VmRun r(kIndex);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, r.m->trap().kind);
  EXPECT_EQ(11u, r.m->trap().loc.line);
  EXPECT_EQ("index 7 outside 1..5", r.m->trap().message);
  EXPECT_STREQ("ST502", trap_code(r.m->trap().kind));
}

TEST(VmTrap, ArrayWriteOutOfRangeBelowTheLowerBound) {
  VmRun r(kIndex);
  ASSERT_TRUE(r.ok());
  r.set("Main.op", 1);
  r.set("Main.i", 0);
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, r.m->trap().kind);
  EXPECT_EQ(12u, r.m->trap().loc.line);
  EXPECT_EQ("index 0 outside 1..5", r.m->trap().message);
  for (int k = 1; k <= 5; ++k) EXPECT_EQ(0, r.get("Main.arr[" + std::to_string(k) + "]"));
}

TEST(VmTrap, SecondDimensionOutOfRange) {
  VmRun r(kIndex);
  ASSERT_TRUE(r.ok());
  r.set("Main.op", 2);
  r.set("Main.j", 4);
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, r.m->trap().kind);
  EXPECT_EQ(13u, r.m->trap().loc.line);
  EXPECT_EQ("index 4 outside 0..3", r.m->trap().message);
  r.set("Main.j", 3);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(5, r.get("Main.grid[1, 3]"));
  EXPECT_EQ(0, r.get("Main.grid[2, 0]"));
}

TEST(VmTrap, MachineRunsNormallyAfterAnIndexTrap) {
  VmRun r(kIndex);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scan());
  r.set("Main.op", 9);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(9, r.get("Main.arr[1]"));
  r.set("Main.op", 0);
  r.set("Main.i", 1);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(9, r.get("Main.x"));
}

// An index wider than DINT must be checked at its full width, not after truncation.
TEST(VmTrap, LintIndexIsCheckedWithoutTruncation) {
  VmRun r("PROGRAM Main\nVAR arr : ARRAY [1..5] OF INT := [11, 12, 13, 14, 15]; i : LINT := 4294967297; x : INT; END_VAR\n"
        "x := arr[i];\nEND_PROGRAM\n");
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, r.m->trap().kind);
  EXPECT_NE(r.m->trap().message.find("index 4294967297 outside 1..5"), std::string::npos) << r.m->trap().message;
  EXPECT_EQ(0, r.get("Main.x"));
  // In range, a wide index works as any other.
  VmRun ok("PROGRAM Main\nVAR arr : ARRAY [1..5] OF INT := [11, 12, 13, 14, 15]; i : LINT := 3; x : INT; END_VAR\n"
           "x := arr[i];\nEND_PROGRAM\n");
  ASSERT_TRUE(ok.ok());
  EXPECT_TRUE(ok.scan());
  EXPECT_EQ(13, ok.get("Main.x"));
  // UDINT 4294967295 is not -1, although its 32 bits read as DINT are.
  VmRun u("PROGRAM Main\nVAR arr : ARRAY [-1..1] OF INT := [7, 8, 9]; i : UDINT := 4294967295; x : INT; END_VAR\n"
          "x := arr[i];\nEND_PROGRAM\n");
  ASSERT_TRUE(u.ok());
  EXPECT_FALSE(u.scan());
  EXPECT_EQ(TrapKind::IndexOutOfRange, u.m->trap().kind);
}

const char* kSubrange = R"(PROGRAM Main
VAR
  pct : INT (0..100);
  n : INT := 150;
END_VAR
pct := n;
END_PROGRAM
)";

TEST(VmTrap, SubrangeViolationOnAssignment) {
  VmRun r(kSubrange);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::RangeError, r.m->trap().kind);
  EXPECT_EQ(6u, r.m->trap().loc.line);
  EXPECT_EQ("value 150 outside subrange 0..100", r.m->trap().message);
  EXPECT_STREQ("ST503", trap_code(r.m->trap().kind));
  EXPECT_EQ(0, r.get("Main.pct"));
  r.set("Main.n", 100);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(100, r.get("Main.pct"));
  r.set("Main.n", -1);
  EXPECT_FALSE(r.scan());
  EXPECT_EQ("value -1 outside subrange 0..100", r.m->trap().message);
  EXPECT_EQ(100, r.get("Main.pct"));
}

const char* kNull = R"(PROGRAM Main
VAR
  target : INT := 42;
  r : REF_TO INT;
  x : INT;
  bind : BOOL;
END_VAR
IF bind THEN
  r := REF(target);
END_IF;
x := r^;
END_PROGRAM
)";

TEST(VmTrap, NullReferenceDereference) {
  VmRun r(kNull);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::NullReference, r.m->trap().kind);
  EXPECT_EQ(11u, r.m->trap().loc.line);
  EXPECT_EQ("dereference of a null reference", r.m->trap().message);
  EXPECT_STREQ("ST504", trap_code(r.m->trap().kind));
  r.set("Main.bind", 1);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(42, r.get("Main.x"));
}

const char* kLoop = R"(PROGRAM Main
VAR spin : BOOL := TRUE; n : DINT; END_VAR
n := n + 1;
WHILE spin DO
END_WHILE;
END_PROGRAM
)";

TEST(VmTrap, WatchdogStopsAnEndlessLoop) {
  VmRun r(kLoop);
  ASSERT_TRUE(r.ok());
  r.m->set_budget(1000);
  EXPECT_FALSE(r.scan());
  EXPECT_EQ(TrapKind::Watchdog, r.m->trap().kind);
  EXPECT_EQ(4u, r.m->trap().loc.line);
  EXPECT_EQ("more than 1000 loop iterations in one call (endless loop?)", r.m->trap().message);
  EXPECT_STREQ("ST505", trap_code(r.m->trap().kind));
  EXPECT_EQ(1, r.get("Main.n"));
  r.set("Main.spin", 0);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(2, r.get("Main.n"));
}

TEST(VmTrap, WatchdogBudgetIsPerCall) {
  VmRun r("PROGRAM Main\nVAR i, n : DINT; END_VAR\nFOR i := 1 TO 900 DO n := n + 1; END_FOR;\nEND_PROGRAM\n");
  ASSERT_TRUE(r.ok());
  r.m->set_budget(1000);
  for (int k = 1; k <= 5; ++k) {
    ASSERT_TRUE(r.scan()) << "call " << k << ": " << r.m->trap().message;
    EXPECT_EQ(900 * k, r.get("Main.n"));
  }
}

TEST(VmTrap, TrapKindsHaveDistinctCodes) {
  EXPECT_STREQ("ST506", trap_code(TrapKind::CallDepth));
  EXPECT_STREQ("ST507", trap_code(TrapKind::AssertFailed));
  EXPECT_STREQ("ST508", trap_code(TrapKind::NotImplemented));
  EXPECT_STREQ("ST509", trap_code(TrapKind::BadAddress));
}

TEST(VmTrap, CallOutsideTheApplicationIsABadAddress) {
  VmRun r(kDivide);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.m->call(static_cast<uint32_t>(r.b->app->code.size()) + 5, 0));
  EXPECT_EQ(TrapKind::BadAddress, r.m->trap().kind);
  r.set("Main.op", 2);
  EXPECT_TRUE(r.scan());
  EXPECT_EQ(11, r.get("Main.q"));
}

// ------------------------------------------------------------------ integer semantics

const char* kWrap = R"(PROGRAM Main
VAR
  si : SINT := 127;  i : INT := 32767;  di : DINT := 2147483647;  li : LINT := 9223372036854775807;
  us : USINT := 255; ui : UINT := 0;    ud : UDINT := 0;          ul : ULINT := 0;
  bt : BYTE := 255;  wo : WORD := 0;
  mi : INT := 200;   mul : INT;
  nsi : SINT := -128; neg : SINT;
END_VAR
si := si + 1;  i := i + 1;  di := di + 1;  li := li + 1;
us := us + 1;  ui := ui - 1; ud := ud - 1;  ul := ul - 1;
bt := bt + 1;  wo := wo - 1;
mul := mi * mi;
neg := -nsi;
END_PROGRAM
)";

TEST(VmArithmetic, EveryIntegerTypeWrapsAround) {
  VmRun r(kWrap);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan()) << r.m->trap().message;
  EXPECT_EQ(-128, r.get("Main.si"));
  EXPECT_EQ(-32768, r.get("Main.i"));
  EXPECT_EQ(INT32_MIN, r.get("Main.di"));
  EXPECT_EQ(INT64_MIN, r.get("Main.li"));
  EXPECT_EQ(0, r.get("Main.us"));
  EXPECT_EQ(65535, r.get("Main.ui"));
  EXPECT_EQ(4294967295, r.get("Main.ud"));
  EXPECT_EQ("18446744073709551615", format(*r.m, r.h("Main.ul")));
  EXPECT_EQ(0, r.get("Main.bt"));
  EXPECT_EQ(65535, r.get("Main.wo"));
  EXPECT_EQ(-25536, r.get("Main.mul"));  // 40000 in 16 bits
  EXPECT_EQ(-128, r.get("Main.neg"));    // -(-128) wraps back
}

const char* kDiv = R"(PROGRAM Main
VAR
  a : DINT; b : DINT; q : DINT; m : DINT;
  ia : INT; ib : INT; iq : INT; im : INT;
  la : LINT; lb : LINT; lq : LINT; lm : LINT;
END_VAR
q := a / b;  m := a MOD b;
iq := ia / ib; im := ia MOD ib;
lq := la / lb; lm := la MOD lb;
END_PROGRAM
)";

TEST(VmArithmetic, DivisionTruncatesTowardZeroAndModTakesTheDividendsSign) {
  VmRun r(kDiv);
  ASSERT_TRUE(r.ok());
  struct {
    int64_t a, b, q, m;
  } cases[] = {{7, 2, 3, 1}, {-7, 2, -3, -1}, {7, -2, -3, 1}, {-7, -2, 3, -1}, {6, 3, 2, 0}, {1, 5, 0, 1}, {-1, 5, 0, -1}};
  for (auto c : cases) {
    for (const char* p : {"", "i", "l"}) {
      std::string x = p;
      r.set("Main." + x + (x.empty() ? "a" : "a"), c.a);
      r.set("Main." + x + "b", c.b);
    }
    ASSERT_TRUE(r.scan()) << r.m->trap().message;
    EXPECT_EQ(c.q, r.get("Main.q")) << c.a << " / " << c.b;
    EXPECT_EQ(c.m, r.get("Main.m")) << c.a << " MOD " << c.b;
    EXPECT_EQ(c.q, r.get("Main.iq")) << c.a << " / " << c.b;
    EXPECT_EQ(c.m, r.get("Main.im")) << c.a << " MOD " << c.b;
    EXPECT_EQ(c.q, r.get("Main.lq")) << c.a << " / " << c.b;
    EXPECT_EQ(c.m, r.get("Main.lm")) << c.a << " MOD " << c.b;
  }
}

TEST(VmArithmetic, MostNegativeDividedByMinusOneWrapsWithoutCrashing) {
  VmRun r(kDiv);
  ASSERT_TRUE(r.ok());
  r.set("Main.a", INT32_MIN);
  r.set("Main.b", -1);
  r.set("Main.ia", INT16_MIN);
  r.set("Main.ib", -1);
  r.set("Main.la", INT64_MIN);
  r.set("Main.lb", -1);
  ASSERT_TRUE(r.scan()) << r.m->trap().message;
  EXPECT_EQ(INT32_MIN, r.get("Main.q"));
  EXPECT_EQ(0, r.get("Main.m"));
  EXPECT_EQ(INT16_MIN, r.get("Main.iq"));
  EXPECT_EQ(0, r.get("Main.im"));
  EXPECT_EQ(INT64_MIN, r.get("Main.lq"));
  EXPECT_EQ(0, r.get("Main.lm"));
}

TEST(VmArithmetic, UnsignedDivisionUsesUnsignedValues) {
  VmRun r("PROGRAM Main\nVAR a : UDINT := 4294967295; b : UDINT := 2; q, m : UDINT; END_VAR\nq := a / b; m := a MOD b;\nEND_PROGRAM\n");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(2147483647, r.get("Main.q"));
  EXPECT_EQ(1, r.get("Main.m"));
}

TEST(VmArithmetic, RealToIntegerConversionRoundsHalvesToEven) {
  VmRun r("PROGRAM Main\nVAR x : REAL := 2.5; y : REAL := -2.5; z : LREAL := 3.5; a, b, c : DINT; END_VAR\n"
          "a := REAL_TO_DINT(x); b := REAL_TO_DINT(y); c := LREAL_TO_DINT(z);\nEND_PROGRAM\n");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(2, r.get("Main.a"));
  EXPECT_EQ(-2, r.get("Main.b"));
  EXPECT_EQ(4, r.get("Main.c"));
}

TEST(VmArithmetic, TruncOfLrealRoundsTowardZero) {
  VmRun r("PROGRAM Main\nVAR y : LREAL := -2.7; z : LREAL := 2.7; d, e : DINT; END_VAR\nd := TRUNC(y); e := TRUNC(z);\nEND_PROGRAM\n");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(-2, r.get("Main.d"));
  EXPECT_EQ(2, r.get("Main.e"));
}

TEST(VmArithmetic, TruncOfRealRoundsTowardZero) {
  VmRun r("PROGRAM Main\nVAR x : REAL := 2.5; y : REAL := -2.5; c, d : DINT; END_VAR\nc := TRUNC(x); d := TRUNC(y);\nEND_PROGRAM\n");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(2, r.get("Main.c"));
  EXPECT_EQ(-2, r.get("Main.d"));
}

// ------------------------------------------------------------------ no allocation per scan

const char* kBusy = R"(FUNCTION_BLOCK Acc
VAR_INPUT x : DINT; END_VAR
VAR_OUTPUT sum : DINT; END_VAR
sum := sum + x;
END_FUNCTION_BLOCK

FUNCTION Twice : DINT
VAR_INPUT v : DINT; END_VAR
Twice := v * 2;
END_FUNCTION

PROGRAM Main
VAR
  t : TON; trig : R_TRIG; c : CTU; acc : Acc;
  s : STRING; s2 : STRING[20]; l : INT;
  arr : ARRAY [0..9] OF DINT;
  i, k, state : INT; n : DINT;
  r : REAL;
END_VAR
n := n + 1;
t(IN := NOT t.Q, PT := T#10ms);
trig(CLK := t.Q);
c(CU := trig.Q, R := c.Q, PV := 5);
FOR i := 0 TO 9 DO
  arr[i] := arr[i] + i;
END_FOR;
acc(x := Twice(arr[n MOD 10]));
CASE state OF
  0: s := CONCAT('count ', INT_TO_STRING(k)); state := 1;
  1: s2 := LEFT(s, 4); state := 2;
  2: l := LEN(s) + FIND(s, 'n'); state := 3;
  3: r := SQRT(INT_TO_REAL(k)); s := REAL_TO_STRING(r); state := 0;
ELSE
  state := 0;
END_CASE;
k := k + 1;
END_PROGRAM
)";

TEST(VmAllocation, AScanPerformsNoHeapAllocation) {
  VmRun r(kBusy);
  ASSERT_TRUE(r.ok());
  const auto& p = r.b->app->programs.at(0);
  Machine& m = *r.m;
  ASSERT_TRUE(m.call(p.pou->entry, p.addr)) << m.trap().message;  // warm-up
  uint64_t before = g_allocations.load();
  bool all_ok = true;
  for (int i = 0; i < 1000; ++i) {
    m.set_now(static_cast<int64_t>(i + 2) * 1'000'000);
    all_ok = m.call(p.pou->entry, p.addr) && all_ok;
  }
  uint64_t count = g_allocations.load() - before;
  EXPECT_EQ(0u, count);
  ASSERT_TRUE(all_ok) << m.trap().message;
  EXPECT_EQ(1001, r.get("Main.k"));
  EXPECT_EQ(1001, r.get("Main.n"));
  EXPECT_GT(r.get("Main.c.CV"), 0);
}

TEST(VmAllocation, TheCounterSeesAllocations) {
  uint64_t before = g_allocations.load();
  auto* p = new std::string(100, 'x');
  EXPECT_GE(g_allocations.load() - before, 1u);
  delete p;
}

// ------------------------------------------------------------------ branch coverage

const char* kBranches = R"(PROGRAM Main
VAR x : INT; y : INT; i : INT; END_VAR
IF x = 1 THEN
  y := 1;
ELSIF x = 2 THEN
  y := 2;
ELSE
  y := 3;
END_IF;
CASE x OF
  1: y := 10;
  2: y := 20;
ELSE
  y := 30;
END_CASE;
FOR i := 1 TO x DO
  y := y + 1;
END_FOR;
END_PROGRAM
)";

// Branch ids by (kind, line), so the test does not depend on numbering order.
struct Arms {
  const Application& app;
  const Machine& m;
  int id(const char* kind, uint32_t line) const {
    int found = -1;
    for (size_t k = 0; k < app.branches.size(); ++k)
      if (app.branches[k].kind == kind && app.branches[k].loc.line == line && app.file_paths[app.branches[k].loc.file] == "vm.st")
        found = static_cast<int>(k);
    return found;
  }
  bool taken(const char* kind, uint32_t line) const {
    int k = id(kind, line);
    EXPECT_GE(k, 0) << "no " << kind << " branch on line " << line;
    if (k < 0) return false;
    return (m.taken()[static_cast<size_t>(k) / 64] >> (k % 64)) & 1u;
  }
};

TEST(VmCoverage, BranchPointsAreListedWithKindsAndLines) {
  VmRun r(kBranches);
  ASSERT_TRUE(r.ok());
  std::vector<std::string> got;
  for (const auto& b : r.b->app->branches)
    if (r.b->app->file_paths[b.loc.file] == "vm.st") got.push_back(b.kind + "@" + std::to_string(b.loc.line) + " in " + b.pou);
  EXPECT_EQ((std::vector<std::string>{"IF@3 in Main", "ELSIF@5 in Main", "ELSE@7 in Main", "CASE@11 in Main",
                                      "CASE@12 in Main", "ELSE@13 in Main", "FOR@16 in Main"}),
            got);
}

TEST(VmCoverage, TakenBitsMatchTheArmsThatRan) {
  VmRun r(kBranches);
  ASSERT_TRUE(r.ok());
  Arms a{*r.b->app, *r.m};
  r.set("Main.x", 2);
  r.m->clear_taken();
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(22, r.get("Main.y"));
  EXPECT_FALSE(a.taken("IF", 3));
  EXPECT_TRUE(a.taken("ELSIF", 5));
  EXPECT_FALSE(a.taken("ELSE", 7));
  EXPECT_FALSE(a.taken("CASE", 11));
  EXPECT_TRUE(a.taken("CASE", 12));
  EXPECT_FALSE(a.taken("ELSE", 13));
  EXPECT_TRUE(a.taken("FOR", 16));

  r.set("Main.x", 0);
  r.m->clear_taken();
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(30, r.get("Main.y"));
  EXPECT_FALSE(a.taken("IF", 3));
  EXPECT_FALSE(a.taken("ELSIF", 5));
  EXPECT_TRUE(a.taken("ELSE", 7));
  EXPECT_FALSE(a.taken("CASE", 11));
  EXPECT_FALSE(a.taken("CASE", 12));
  EXPECT_TRUE(a.taken("ELSE", 13));
  EXPECT_FALSE(a.taken("FOR", 16));  // the loop body never ran
}

TEST(VmCoverage, CoveredAccumulatesAcrossScansAndReportsMisses) {
  VmRun r(kBranches);
  ASSERT_TRUE(r.ok());
  for (int x : {1, 0}) {
    r.set("Main.x", x);
    r.m->clear_taken();
    ASSERT_TRUE(r.scan());
    r.m->merge_coverage();
  }
  std::string rep = coverage_report(*r.b->app, r.m->covered());
  EXPECT_NE(std::string::npos, rep.find("vm.st: 5/7 branches (71%)")) << rep;
  EXPECT_NE(std::string::npos, rep.find("not taken: vm.st:5:")) << rep;
  EXPECT_NE(std::string::npos, rep.find("ELSIF in Main")) << rep;
  EXPECT_NE(std::string::npos, rep.find("not taken: vm.st:12:")) << rep;
  EXPECT_EQ(std::string::npos, rep.find("vm.st:3:")) << rep;
}

// Compiled without coverage (`plcfi run` without --coverage), the arms are still numbered
// but no COV is laid down: the program computes the same values and marks no arm.
TEST(VmCoverage, WithoutCoverageTheArmsMarkNothingAndComputeTheSame) {
  CompileOptions off;
  off.coverage = false;
  VmRun with(kBranches), without(kBranches, off);
  ASSERT_TRUE(with.ok());
  ASSERT_TRUE(without.ok());
  EXPECT_EQ(with.b->app->branches.size(), without.b->app->branches.size());
  EXPECT_NE(std::string::npos, with.disasm().find("COV ")) << with.disasm();
  EXPECT_EQ(std::string::npos, without.disasm().find("COV ")) << without.disasm();
  for (int x : {1, 0, 7, -3}) {
    with.set("Main.x", x);
    without.set("Main.x", x);
    ASSERT_TRUE(with.scan());
    ASSERT_TRUE(without.scan());
    EXPECT_EQ(with.get("Main.y"), without.get("Main.y")) << "x = " << x;
  }
  EXPECT_GT(with.taken_count(), 0u);
  EXPECT_EQ(0u, without.taken_count());
}

}  // namespace

// ------------------------------------------------------------------ numerics as IEC and MATIEC

TEST(VmNumerics, RealToIntRoundsHalvesToEven) {
  VmRun r(R"(PROGRAM Main
VAR a, b, c, d, e, f, g : DINT; x : REAL := 71598.5; END_VAR
a := REAL_TO_DINT(2.5); b := REAL_TO_DINT(3.5); c := REAL_TO_DINT(-2.5);
d := LREAL_TO_DINT(LREAL#-3.5); e := REAL_TO_DINT(x); f := REAL_TO_DINT(2.4999999);
g := LREAL_TO_DINT(LREAL#0.5);
END_PROGRAM
)");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(2, r.get("Main.a"));
  EXPECT_EQ(4, r.get("Main.b"));
  EXPECT_EQ(-2, r.get("Main.c"));
  EXPECT_EQ(-4, r.get("Main.d"));
  EXPECT_EQ(71598, r.get("Main.e"));
  EXPECT_EQ(2, r.get("Main.f"));
  EXPECT_EQ(0, r.get("Main.g"));
}

TEST(VmNumerics, RealSinIsTheDoubleResultRoundedOnce) {
  // sinf is 1 ulp off for some arguments; SIN on REAL is (float)sin((double)x).
  VmRun r(R"(PROGRAM Main
VAR x : REAL; y : REAL; i : INT; bad : INT; END_VAR
bad := 0;
FOR i := 1 TO 2000 DO
  x := INT_TO_REAL(i) * 0.0078125;
  y := SIN(x);
  IF y <> LREAL_TO_REAL(SIN(REAL_TO_LREAL(x))) THEN bad := bad + 1; END_IF;
  y := COS(x);
  IF y <> LREAL_TO_REAL(COS(REAL_TO_LREAL(x))) THEN bad := bad + 1; END_IF;
  y := EXP(x * 0.125);
  IF y <> LREAL_TO_REAL(EXP(REAL_TO_LREAL(x * 0.125))) THEN bad := bad + 1; END_IF;
END_FOR;
END_PROGRAM
)");
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r.scan());
  EXPECT_EQ(0, r.get("Main.bad"));
}

}  // namespace plcfi::st
