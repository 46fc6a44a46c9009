// The native tier against the interpreter: same memory, coverage and clock after every
// scan, and the same trap (kind, location, message) for every kind of runtime error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <regex>
#include <sstream>

#include <unistd.h>

#include <fmt/format.h>

#include "engine.hpp"
#include "native/native.hpp"
#include "same_memory.hpp"
#include "testing/test_files.hpp"

namespace plcfi::st {
namespace {

std::string read_file(const std::string& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct Pair {
  std::unique_ptr<Build> b;
  std::unique_ptr<NativeCode> native;
};

Pair build_both(const std::vector<std::pair<std::string, std::string>>& sources, CompileOptions opt = {},
                const NativeOptions& no = {}) {
  Pair p;
  p.b = build_sources(sources, opt);
  EXPECT_TRUE(p.b->ok()) << p.b->diags.render_all();
  if (!p.b->ok()) return p;
  std::string err;
  p.native = NativeCode::build(*p.b->app, no, &err);
  EXPECT_TRUE(p.native) << err;
  if (p.native) {
    EXPECT_EQ(p.native->interpreted(), 0u);
  }
  return p;
}

// Runs `scans` scans of every program instance in both tiers, comparing after each.
// Returns the scan that trapped (or -1); the traps must agree.
int compare_runs(const Pair& p, int scans, uint64_t budget = 100'000) {
  const Application& app = *p.b->app;
  Machine a(app), n(app);
  a.set_budget(budget);
  n.set_budget(budget);
  n.set_native(p.native.get());
  for (int s = 0; s < scans; ++s) {
    a.set_now(s * 10'000'000LL);
    n.set_now(s * 10'000'000LL);
    for (const auto& inst : app.programs) {
      bool ra = a.call(inst.pou->entry, inst.addr);
      bool rn = n.call(inst.pou->entry, inst.addr);
      EXPECT_EQ(ra, rn) << "scan " << s << " program " << inst.name;
      EXPECT_EQ(static_cast<int>(a.trap().kind), static_cast<int>(n.trap().kind));
      EXPECT_EQ(a.trap().pc, n.trap().pc);
      EXPECT_EQ(a.trap().message, n.trap().message);
      EXPECT_EQ(describe_trap(app, a.trap()), describe_trap(app, n.trap()));
      EXPECT_TRUE(same_memory(app, a, n)) << "memory differs after scan " << s;
      EXPECT_EQ(a.taken(), n.taken()) << "coverage differs after scan " << s;
      EXPECT_EQ(a.now(), n.now());
      if (!ra) return s;
    }
  }
  return -1;
}

TEST(NativeTier, StampingProgramScansLikeTheInterpreter) {
  Pair p = build_both({{"stamping.st", read_file(std::string(PLCFI_SOURCE_DIR) + "/st_programs/stamping/stamping.st")}});
  ASSERT_TRUE(p.native);
  EXPECT_EQ(compare_runs(p, 500), -1);
}

TEST(NativeTier, BenchKernelsScanLikeTheInterpreter) {
  for (const char* k : {"state_machine", "int_loop", "real_math", "array_struct", "fb_calls"}) {
    SCOPED_TRACE(k);
    std::string file = std::string(k) + ".st";
    Pair p = build_both({{file, read_file(std::string(PLCFI_SOURCE_DIR) + "/tests/bench/kernels/" + file)}});
    ASSERT_TRUE(p.native);
    EXPECT_EQ(compare_runs(p, 50, 10'000'000), -1);
  }
}

// Issue 31's kernels (both halves): bits, strings, REAL FBs, enum CASE, loops, arrays of
// structs, timers and edges. The same memory outside compiler temporaries after every scan.
TEST(NativeTier, Matiec31KernelsScanLikeTheInterpreter) {
  for (const char* k : {"crc16_parity", "bitpack", "str_build", "real_ctrl", "enum_fsm", "int_nested", "struct_sort", "crc32",
                        "str_parse", "ring_filter", "fb_timers", "int_while", "struct_search", "int_sieve",
                        "struct_queue"}) {
    SCOPED_TRACE(k);
    std::string file = std::string(k) + ".st";
    Pair p = build_both({{file, read_file(std::string(PLCFI_SOURCE_DIR) + "/tests/bench/matiec31/" + file)}});
    ASSERT_TRUE(p.native);
    EXPECT_EQ(compare_runs(p, 20, 10'000'000), -1);
  }
}

// Scratch is only ever a frame's temporaries: no variable of a program, of an FB
// instance inside it (arrays of instances included) or of a global instance lies in it.
TEST(NativeTier, ScratchRangesHoldNoVariable) {
  const char* src = R"(FUNCTION_BLOCK Cell
VAR_INPUT x : DINT; END_VAR
VAR_OUTPUT y : DINT; END_VAR
VAR acc : ARRAY [0..3] OF DINT; END_VAR
acc[x MOD 4] := acc[x MOD 4] + x * 2 + 1;
y := acc[0] + acc[1] * 3;
END_FUNCTION_BLOCK
VAR_GLOBAL g : Cell; END_VAR
PROGRAM Main
VAR cells : ARRAY [1..3] OF Cell; one : Cell; n : DINT; total : DINT; END_VAR
n := n + 1;
cells[n MOD 3 + 1](x := n * 5);
one(x := n);
g(x := n + 2);
total := cells[1].y + cells[2].y + cells[3].y + one.y + g.y;
END_PROGRAM
)";
  Pair p = build_both({{"scratch.st", src}});
  ASSERT_TRUE(p.native);
  const Application& app = *p.b->app;
  auto scratch = scratch_ranges(app);
  ASSERT_FALSE(scratch.empty());
  auto clear_of = [&](uint64_t from, uint64_t to, const std::string& what) {
    for (auto [a, e] : scratch) EXPECT_TRUE(e <= from || to <= a) << what << " [" << from << ", " << to << ") in scratch [" << a << ", " << e << ")";
  };
  std::function<void(const PouInfo*, uint64_t, const std::string&)> vars = [&](const PouInfo* pou, uint64_t at, const std::string& path) {
    for (const auto& v : pou->vars) {
      if (v->where != Where::Frame) continue;
      bool instances = v->type->kind == TypeKind::Pou || (v->type->kind == TypeKind::Array && v->type->elem->kind == TypeKind::Pou);
      if (!instances) clear_of(at + v->offset, at + v->offset + v->type->size, path + "." + v->name);  // an instance holds its temporaries
      if (v->type->kind == TypeKind::Pou) vars(v->type->pou, at + v->offset, path + "." + v->name);
      if (v->type->kind == TypeKind::Array && v->type->elem->kind == TypeKind::Pou)
        for (uint32_t k = 0; k < 3; ++k) vars(v->type->elem->pou, at + v->offset + k * v->type->elem->size, path + "." + v->name + "[]");
    }
  };
  for (const auto& inst : app.programs) vars(inst.pou, inst.addr, inst.name);
  for (const auto& g : app.globals)
    if (g.sym->where == Where::Abs) {
      vars(g.sym->type->pou, g.sym->offset, g.sym->name);
    }
  EXPECT_EQ(compare_runs(p, 30), -1);
}

// A loop over a two-dimensional array keeps its temporaries in registers: no store of a
// temporary, and no null or memory-bounds check on an element proven inside its array
// (the index checks stay).
TEST(NativeTier, ArrayLoopTemporariesStayInRegisters) {
  const char* src = R"(PROGRAM Main
VAR m : ARRAY [0..7, 0..7] OF DINT; i : DINT; j : DINT; s : DINT; END_VAR
FOR i := 0 TO 7 DO
  FOR j := 0 TO 7 DO
    m[i, j] := m[j, i] + i * 8 + j;
    s := s + m[i, (j + 1) MOD 8] MOD 7;
  END_FOR;
END_FOR;
END_PROGRAM
)";
  Pair p = build_both({{"loop.st", src}});
  ASSERT_TRUE(p.native);
  const Application& app = *p.b->app;
  std::vector<uint32_t> entries, skipped;
  std::string code = native_source(app, &entries, &skipped);
  const PouInfo* main = app.programs.at(0).pou;
  const uint64_t temps = (uint64_t{main->const_from} + main->consts.size() + 7) & ~uint64_t{7};
  std::regex store(R"(ST\(\w+, base \+ (\d+)u)");
  int stores = 0;
  for (auto it = std::sregex_iterator(code.begin(), code.end(), store); it != std::sregex_iterator(); ++it) {
    ++stores;
    EXPECT_LT(std::stoull((*it)[1]), temps) << "a store of a temporary: " << it->str();
  }
  EXPECT_GT(stores, 0);  // the variables are still stored
  EXPECT_EQ(code.find("TRAP(4,"), std::string::npos) << "a null check";
  EXPECT_EQ(code.find("TRAP(9,"), std::string::npos) << "a memory-bounds check";
  EXPECT_NE(code.find("TRAP(2,"), std::string::npos) << "the index checks of m[i, (j + 1) MOD 8] are kept";
  // m[i, j] and m[j, i]: the loops prove both indices in range; the C++ compiler is told so.
  EXPECT_NE(code.find("__builtin_unreachable()"), std::string::npos) << code;
  EXPECT_EQ(compare_runs(p, 5), -1);
}

// Direct calls into functions that cannot recurse skip the general call's bookkeeping
// (depth, method stack, budget, result) where their callees cannot use it; every way
// those could still matter is compared here against the interpreter.
const char* kCallKinds = R"(FUNCTION Leaf : DINT
VAR_INPUT x : DINT; d : DINT; END_VAR
Leaf := x / d;  (* traps when d = 0 *)
END_FUNCTION

FUNCTION Spin : DINT
VAR_INPUT n : DINT; END_VAR
VAR i : DINT; END_VAR
FOR i := 1 TO n DO Spin := Spin + i; END_FOR;  (* the watchdog counts these *)
END_FUNCTION

FUNCTION Mid : DINT
VAR_INPUT x : DINT; d : DINT; END_VAR
Mid := Leaf(x := x, d := d) + Spin(n := 3);
END_FUNCTION

FUNCTION_BLOCK Acc
VAR_INPUT x : REAL; END_VAR
VAR_OUTPUT y : REAL; hi : BOOL; END_VAR
y := y * 0.5 + x;
IF y > 10.0 THEN hi := TRUE; ELSE hi := FALSE; END_IF;
END_FUNCTION_BLOCK

(* Recursion through a method: the general call, counting depth; every level also makes
   direct calls three deep, which must fall back to the general call near the limit. *)
FUNCTION_BLOCK Counter
METHOD Down : DINT
VAR_INPUT k : DINT; END_VAR
Down := Mid(x := k, d := 1);
IF k > 0 THEN
  Down := Down + THIS^.Down(k := k - 1);
END_IF;
END_METHOD
END_FUNCTION_BLOCK

PROGRAM P
VAR
  n : DINT; r : DINT; a : Acc; b : Acc; c : Counter; deep : BOOL; div : DINT := 1; loops : DINT := 2;
END_VAR
n := n + 1;
a(x := DINT_TO_REAL(n));
b(x := a.y);
deep := n = 3 OR n = 4;                   (* deeper than the call stack: CallDepth *)
IF n = 5 THEN div := 0; END_IF;           (* a trap two calls down *)
IF n = 7 THEN div := 1; loops := 1000000; END_IF;  (* the watchdog, in a callee *)
IF n = 9 THEN loops := 2; END_IF;
r := Mid(x := n, d := div) + Spin(n := loops) + c.Down(k := 20);
IF deep THEN r := r + c.Down(k := 300); END_IF;
END_PROGRAM
)";

TEST(NativeTier, DirectCallsKeepDepthTrapsAndTheWatchdogExact) {
  CompileOptions opt;
  opt.dialect = Dialect::Codesys;  // methods (THIS^) for the recursion
  Pair p = build_both({{"calls.st", kCallKinds}}, opt);
  ASSERT_TRUE(p.native);
  const Application& app = *p.b->app;
  Machine a(app), n(app);
  a.set_budget(50'000);
  n.set_budget(50'000);
  n.set_native(p.native.get());
  const auto& inst = app.programs.at(0);
  std::vector<TrapKind> seen;
  for (int s = 0; s < 12; ++s) {
    bool ra = a.call(inst.pou->entry, inst.addr);
    bool rn = n.call(inst.pou->entry, inst.addr);
    ASSERT_EQ(ra, rn) << "scan " << s;
    EXPECT_EQ(describe_trap(app, a.trap()), describe_trap(app, n.trap())) << "scan " << s;
    EXPECT_TRUE(same_memory(app, a, n)) << "memory differs after scan " << s;
    EXPECT_EQ(a.taken(), n.taken()) << "coverage differs after scan " << s;
    if (!ra) seen.push_back(a.trap().kind);
  }
  // Each kind happened, and the tiers agreed on it.
  EXPECT_NE(std::find(seen.begin(), seen.end(), TrapKind::CallDepth), seen.end());
  EXPECT_NE(std::find(seen.begin(), seen.end(), TrapKind::DivisionByZero), seen.end());
  EXPECT_NE(std::find(seen.begin(), seen.end(), TrapKind::Watchdog), seen.end());
  // The leaf calls took the direct path.
  std::vector<uint32_t> entries, skipped;
  std::string src = native_source(app, &entries, &skipped);
  EXPECT_NE(src.find("} else { int r = F"), std::string::npos) << "no direct call in the generated code";
}

// Slots the native code keeps in locals (write-through) must be re-read wherever
// something else may have written them: a whole-structure copy over a field, a write
// through a reference, an FB that changes its own input, a callee in a loop, an array
// element next to a scalar.
const char* kCachedSlots = R"(TYPE Pair : STRUCT a : DINT; b : REAL; c : LREAL; d : DINT; END_STRUCT; END_TYPE

FUNCTION_BLOCK SelfReset
VAR_INPUT trigger : BOOL; END_VAR
VAR_OUTPUT seen : DINT; END_VAR
IF trigger THEN seen := seen + 1; trigger := FALSE; END_IF;
END_FUNCTION_BLOCK

FUNCTION Bump : DINT
VAR_IN_OUT v : DINT; END_VAR
v := v + 3;
Bump := v;
END_FUNCTION

PROGRAM P
VAR
  p, q : Pair; r : REF_TO DINT; x, y, i, k : DINT; f : SelfReset; arr : ARRAY[0..3] OF DINT; z : DINT;
END_VAR
p.a := p.a + 1;
q.a := p.a * 10;
p := q;                 (* a block copy over p.a *)
y := p.a;
x := x + 1;
r := REF(x);
r^ := r^ * 2;           (* through a reference *)
y := y + x;
f.trigger := TRUE;
f();                    (* the FB clears its own input *)
IF f.trigger THEN y := y + 1000; END_IF;
k := 0;
FOR i := 1 TO 4 DO
  k := k + 1;
  y := y + Bump(v := k);  (* the callee writes k *)
  k := k + 1;
END_FOR;
z := z + 1;
arr[z MOD 4] := z;      (* an element write next to z *)
y := y + z + arr[0] + arr[1] + arr[2] + arr[3] + k;
END_PROGRAM
)";

TEST(NativeTier, CachedSlotsAreReadAgainAfterEveryOtherWrite) {
  Pair p = build_both({{"cached.st", kCachedSlots}});
  ASSERT_TRUE(p.native);
  EXPECT_EQ(compare_runs(p, 20), -1);
  Machine n(*p.b->app);
  n.set_native(p.native.get());
  const auto& inst = p.b->app->programs.at(0);
  ASSERT_TRUE(n.call(inst.pou->entry, inst.addr));
  std::string err;
  auto y = resolve(*p.b->app, "P.y", &err);
  ASSERT_TRUE(y) << err;
  // p.a = 10, x = 2, trigger cleared, k: 1+3=4 -> 5, 6+3=9 -> 10, ... Bump results 4+9+14+19,
  // k = 20, z = 1, arr[1] = 1.
  EXPECT_EQ(read_int(n, *y), 10 + 2 + (4 + 9 + 14 + 19) + 1 + 1 + 20);
}

// Functions longer than chunk_instructions are compiled as pieces that hand control to
// each other (loops, CASE tables and calls across the cuts): cut every few instructions,
// programs of every kind scan as in the interpreter, traps and the watchdog included.
TEST(NativeTier, LongFunctionsAreCompiledInPieces) {
  NativeOptions no;
  no.chunk_instructions = 7;
  no.optimize = "-O1";
  no.cache_dir = ::testing::TempDir() + "plcfi_native_pieces." + std::to_string(::getpid());
  std::vector<std::pair<std::string, std::string>> files = {
      {"stamping.st", std::string(PLCFI_SOURCE_DIR) + "/st_programs/stamping/stamping.st"}};
  for (const char* k : {"crc16_parity", "str_build", "enum_fsm", "int_nested", "struct_sort", "fb_timers", "int_while"})
    files.emplace_back(std::string(k) + ".st", std::string(PLCFI_SOURCE_DIR) + "/tests/bench/matiec31/" + k + ".st");
  for (const auto& [name, path] : files) {
    SCOPED_TRACE(name);
    Pair p = build_both({{name, read_file(path)}}, {}, no);
    ASSERT_TRUE(p.native);
    EXPECT_EQ(compare_runs(p, 20, 10'000'000), -1);
    NativeProgram np = native_program(*p.b->app, 0, no.chunk_instructions);
    EXPECT_NE(np.units.at(0).text.find("_1(Ctx* c, uint8_t* base, uint32_t* at)"), std::string::npos) << "not cut";
  }
  CompileOptions opt;
  opt.dialect = Dialect::Codesys;
  Pair calls = build_both({{"calls.st", kCallKinds}}, opt, no);
  ASSERT_TRUE(calls.native);
  EXPECT_GE(compare_runs(calls, 12, 50'000), 0);  // a trap, the same in both tiers
  std::filesystem::remove_all(no.cache_dir);
}

// Each program traps on its 3rd scan; both tiers must report the same trap.
struct TrapCase {
  const char* name;
  const char* body;  // statements; n counts the scans
  const char* vars;
  TrapKind kind;
};

class NativeTraps : public ::testing::TestWithParam<TrapCase> {};

TEST_P(NativeTraps, SameTrapKindLocationAndMessage) {
  const TrapCase& c = GetParam();
  std::string src = std::string("PROGRAM P\nVAR\n  n : DINT;\n  zero : DINT;\n") + c.vars + "END_VAR\nn := n + 1;\nIF n >= 3 THEN\n" +
                    c.body + "\nEND_IF;\nEND_PROGRAM\n";
  CompileOptions opt;
  opt.dialect = Dialect::Codesys;  // x MOD 0 traps there (IEC: 0)
  Pair p = build_both({{"p.st", src}}, opt);
  ASSERT_TRUE(p.native);
  EXPECT_EQ(compare_runs(p, 5), 2);
  Machine n(*p.b->app);
  n.set_budget(100'000);
  n.set_native(p.native.get());
  const auto& inst = p.b->app->programs[0];
  for (int i = 0; i < 3; ++i) n.call(inst.pou->entry, inst.addr);
  EXPECT_EQ(static_cast<int>(n.trap().kind), static_cast<int>(c.kind)) << n.trap().message;
  // The statement's line: after the header (7 lines) and the extra declarations.
  auto line = 8u + static_cast<uint32_t>(std::count(c.vars, c.vars + std::strlen(c.vars), '\n'));
  EXPECT_EQ(n.trap().loc.line, line) << describe_trap(*p.b->app, n.trap());
}

const TrapCase kTraps[] = {
    {"division", "  n := 100 / zero;", "", TrapKind::DivisionByZero},
    {"modulo", "  n := 100 MOD zero;", "", TrapKind::DivisionByZero},  // under --dialect codesys
    {"index_frame_array", "  a[n * 5] := 1;", "  a : ARRAY[1..10] OF DINT;\n", TrapKind::IndexOutOfRange},
    {"index_read", "  n := a[n - 10];", "  a : ARRAY[1..10] OF DINT;\n", TrapKind::IndexOutOfRange},
    {"index_struct_array", "  r[n * 5].x := 1;", "  r : ARRAY[1..4] OF STRUCT x : INT; y : REAL; END_STRUCT;\n",
     TrapKind::IndexOutOfRange},
    {"subrange", "  s := DINT_TO_INT(n * 10);", "  s : INT(0..20);\n", TrapKind::RangeError},
    {"watchdog", "  WHILE TRUE DO n := n + 1; END_WHILE;", "", TrapKind::Watchdog},
    {"for_watchdog", "  FOR i := 0 TO 1000000 DO n := n + 1; END_FOR;", "  i : DINT;\n", TrapKind::Watchdog},
    {"null_reference", "  n := r^;", "  r : REF_TO DINT;\n", TrapKind::NullReference},
};

INSTANTIATE_TEST_SUITE_P(All, NativeTraps, ::testing::ValuesIn(kTraps),
                         [](const ::testing::TestParamInfo<TrapCase>& i) { return std::string(i.param.name); });

// Differential fuzzing: conformance tests with one integer literal changed (so asserts
// fail, loops run longer, indexes leave their ranges...) give the same results, failure
// messages and locations in both tiers. Four shards of six programs each (a shard is one
// ctest with its own time-out; each program is a C++ compilation, at -O0 to keep a shard
// well inside its time on a loaded machine).
class NativeMutations : public ::testing::TestWithParam<int> {};

TEST_P(NativeMutations, GiveTheSameResultsInBothTiers) {
  namespace fs = std::filesystem;
  fs::path dir = fs::path(PLCFI_SOURCE_DIR) / "tests" / "st";
  std::vector<fs::path> tests;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("test_", 0) == 0) tests.push_back(e.path());
  std::sort(tests.begin(), tests.end());
  std::mt19937 rng(20261122u + static_cast<unsigned>(GetParam()));
  const std::regex number(R"(\b[0-9]+\b)");
  int compared = 0, failing = 0;
  for (int round = 0; round < 6; ++round) {
    const fs::path& t = tests[rng() % tests.size()];
    std::string text = read_file(t.string());
    std::vector<std::pair<size_t, size_t>> spots;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), number); it != std::sregex_iterator(); ++it)
      spots.emplace_back(static_cast<size_t>(it->position()), static_cast<size_t>(it->length()));
    if (spots.empty()) continue;
    auto [pos, len] = spots[rng() % spots.size()];
    text.replace(pos, len, std::to_string(rng() % 40));
    std::vector<std::pair<std::string, std::string>> sources;
    std::string topic = t.filename().string().substr(5);
    if (fs::exists(dir / topic)) sources.emplace_back(topic, read_file((dir / topic).string()));
    sources.emplace_back(t.filename().string(), text);
    CompileOptions opt;
    opt.test_mode = true;
    opt.warnings = false;
    auto b = build_sources(sources, opt);
    if (!b->ok() || b->app->tests.empty()) continue;  // the change made it ill-typed
    SCOPED_TRACE(t.filename().string() + " with a literal at offset " + std::to_string(pos) + " changed");
    std::string err;
    NativeOptions no;
    no.optimize = "-O0";
    auto native = NativeCode::build(*b->app, no, &err);
    ASSERT_TRUE(native) << err;
    Machine a(*b->app), n(*b->app);
    n.set_native(native.get());
    testing::TestRunOptions ro;
    ro.budget = 200'000;
    auto ra = testing::run_tests(*b->app, a, ro);
    auto rn = testing::run_tests(*b->app, n, ro);
    ASSERT_EQ(ra.size(), rn.size());
    for (size_t i = 0; i < ra.size(); ++i) {
      EXPECT_EQ(ra[i].name, rn[i].name);
      EXPECT_EQ(ra[i].passed, rn[i].passed) << ra[i].name;
      EXPECT_EQ(ra[i].where, rn[i].where) << ra[i].name;
      EXPECT_EQ(ra[i].message, rn[i].message) << ra[i].name;
      failing += !ra[i].passed;
    }
    ++compared;
  }
  std::printf("mutated programs compared: %d, failing tests among them: %d\n", compared, failing);
  EXPECT_GE(compared, 2);
  EXPECT_GE(failing, 1);  // the failure paths (asserts, traps) were exercised
}

INSTANTIATE_TEST_SUITE_P(Shards, NativeMutations, ::testing::Range(0, 4));

// A program over the split size is compiled as several units, each cached on its own:
// the same results as the interpreter (traps at the same place, the same coverage), and
// after an edit to one FB's body, which moves the code and the branch ids of everything
// after it, only that FB's unit and the index are compiled again.
std::string units_program(bool edited) {
  std::string src = "FUNCTION_BLOCK First\nVAR_INPUT go : BOOL; END_VAR\nVAR_OUTPUT n : DINT; END_VAR\n"
                    "IF go THEN n := n + 1; END_IF;\n";
  if (edited) src += "IF go THEN n := n + 1; END_IF;\n";  // more code, one more branch
  src += "END_FUNCTION_BLOCK\n";
  for (int k = 0; k < 12; ++k)
    src += fmt::format(
        "FUNCTION_BLOCK Leaf{0}\nVAR_INPUT d : DINT; END_VAR\nVAR_OUTPUT q : DINT; END_VAR\nVAR acc : DINT; END_VAR\n"
        "IF d > {0} THEN acc := acc + d; ELSE acc := acc - 1; END_IF;\nq := acc MOD 97;\nEND_FUNCTION_BLOCK\n",
        k);
  src += "FUNCTION Ratio : DINT\nVAR_INPUT a, b : DINT; END_VAR\nRatio := a / b;\nEND_FUNCTION\n";
  src += "PROGRAM Main\nVAR f : First; r : DINT; t : DINT; sum : DINT;\n";
  for (int k = 0; k < 12; ++k) src += fmt::format("l{} : Leaf{};\n", k, k);
  src += "END_VAR\nt := t + 1;\nf(go := TRUE);\nsum := 0;\n";
  for (int k = 0; k < 12; ++k) src += fmt::format("l{0}(d := t + {0});\nsum := sum + l{0}.q;\n", k);
  src += "r := Ratio(a := sum, b := 40 - t);\nEND_PROGRAM\n";  // divides by zero in scan 40
  return src;
}

TEST(NativeTier, LargeProgramsCompileInUnitsCachedOneByOne) {
  NativeOptions no;
  no.split_bytes = 1;  // this small program as if it were large
  no.cache_dir = ::testing::TempDir() + "plcfi_native_units." + std::to_string(::getpid());
  std::filesystem::remove_all(no.cache_dir);
  Pair p = build_both({{"units.st", units_program(false)}}, {}, no);
  ASSERT_TRUE(p.native);
  EXPECT_GE(p.native->units(), 3u);  // at least two units of functions and the index
  EXPECT_EQ(p.native->units_compiled(), p.native->units());
  EXPECT_EQ(compare_runs(p, 60), 39);  // the division by zero, at the same place in both tiers

  Pair e = build_both({{"units.st", units_program(true)}}, {}, no);
  ASSERT_TRUE(e.native);
  EXPECT_FALSE(e.native->from_cache());
  EXPECT_EQ(e.native->units_compiled(), 2u) << "the edited FB's unit and the index";
  EXPECT_EQ(compare_runs(e, 60), 39);

  // Only that unit's text changed: names and positions are relative.
  NativeProgram a = native_program(*p.b->app, 1, no.chunk_instructions), b = native_program(*e.b->app, 1, no.chunk_instructions);
  ASSERT_TRUE(a.split && b.split);
  ASSERT_EQ(a.units.size(), b.units.size());
  int changed = 0;
  for (size_t k = 0; k + 1 < a.units.size(); ++k) changed += a.units[k].text != b.units[k].text;
  EXPECT_EQ(changed, 1);

  Pair again = build_both({{"units.st", units_program(true)}}, {}, no);
  ASSERT_TRUE(again.native);
  EXPECT_TRUE(again.native->from_cache());
  std::filesystem::remove_all(no.cache_dir);
}

TEST(NativeTier, MissingCompilerIsAClearError) {
  auto b = build_sources({{"p.st", "PROGRAM P\nVAR x : INT; END_VAR\nx := x + 1;\nEND_PROGRAM\n"}}, CompileOptions{});
  ASSERT_TRUE(b->ok());
  NativeOptions o;
  o.compiler = "/nonexistent/c++";
  o.cache_dir = ::testing::TempDir() + "plcfi_native_missing_cc";
  std::string err;
  EXPECT_EQ(NativeCode::build(*b->app, o, &err), nullptr);
  EXPECT_NE(err.find("cannot run the C++ compiler '/nonexistent/c++'"), std::string::npos) << err;
}

TEST(NativeTier, SecondBuildComesFromTheCache) {
  auto b = build_sources({{"p.st", "PROGRAM P\nVAR x : INT; END_VAR\nx := x + 2;\nEND_PROGRAM\n"}}, CompileOptions{});
  ASSERT_TRUE(b->ok());
  std::string err;
  auto first = NativeCode::build(*b->app, NativeOptions{}, &err);
  ASSERT_TRUE(first) << err;
  auto second = NativeCode::build(*b->app, NativeOptions{}, &err);
  ASSERT_TRUE(second) << err;
  EXPECT_TRUE(second->from_cache());
  EXPECT_EQ(first->library(), second->library());
}

}  // namespace
}  // namespace plcfi::st
