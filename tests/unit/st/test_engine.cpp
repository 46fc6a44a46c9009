// The engine facade: resolving variable paths to handles, typed reads and writes, format and write_text, configurations with tasks, cold and warm restarts.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "engine.hpp"

namespace plcfi::st {
namespace {

const char* kGvl = R"(VAR_GLOBAL
  x : INT := 7;
  limit : DINT := 100;
END_VAR
)";

const char* kMain = R"(TYPE Point : STRUCT field : INT; y : REAL; END_STRUCT; END_TYPE
TYPE Color : (Red, Green, Blue); END_TYPE
PROGRAM Main
VAR
  x : DINT;
  fb : TON;
  arr : ARRAY [1..5] OF INT;
  grid : ARRAY [0..1, 0..2] OF INT;
  s : Point;
  pts : ARRAY [1..3] OF Point;
  w : WORD;
  b : BOOL; si : SINT; i : INT; di : DINT; li : LINT;
  us : USINT; ui : UINT; ud : UDINT; ul : ULINT;
  bt : BYTE; dw : DWORD; lw : LWORD;
  r : REAL; lr : LREAL; t : TIME;
  str : STRING; str10 : STRING[10];
  c : Color := Color#Green;
  pct : INT (0..100);
  in3 AT %IX0.3 : BOOL;
  qw AT %QW2 : WORD;
END_VAR
x := x + 1;
fb(IN := b, PT := T#1s);
END_PROGRAM
)";

class Engine : public ::testing::Test {
 protected:
  void SetUp() override {
    b = build_sources({{"GVL.st", kGvl}, {"main.st", kMain}}, CompileOptions{});
    ASSERT_TRUE(b->ok()) << b->diags.render_all();
    m = std::make_unique<Machine>(*b->app);
  }
  VarHandle h(const std::string& path) {
    std::string err;
    auto r = resolve(*b->app, path, &err);
    EXPECT_TRUE(r.has_value()) << path << ": " << err;
    return r.value_or(VarHandle{});
  }
  std::string resolve_error(const std::string& path) {
    std::string err;
    auto r = resolve(*b->app, path, &err);
    EXPECT_FALSE(r.has_value()) << path << " resolved";
    return err;
  }
  std::string set_text(const std::string& path, const std::string& text) {
    std::string err;
    bool ok = write_text(*m, h(path), text, &err);
    if (ok) return "ok";
    return err;
  }
  uint32_t main_addr() const { return b->app->programs.at(0).addr; }
  uint32_t offset_of(const char* name) const { return b->app->programs.at(0).pou->find_var(name)->offset; }

  std::unique_ptr<Build> b;
  std::unique_ptr<Machine> m;
};

// ------------------------------------------------------------------ resolve

TEST_F(Engine, ResolvesAProgramVariable) {
  VarHandle v = h("Main.x");
  EXPECT_EQ("Main.x", v.path);
  EXPECT_EQ(TypeKind::DInt, v.type->kind);
  EXPECT_EQ(main_addr() + offset_of("x"), v.addr);
  EXPECT_FALSE(v.is_bit);
  EXPECT_EQ(v.addr, h("main.X").addr);  // names are case-insensitive
}

TEST_F(Engine, ResolvesAnFbOutput) {
  VarHandle q = h("Main.fb.Q"), et = h("Main.fb.ET");
  EXPECT_EQ(TypeKind::Bool, q.type->kind);
  EXPECT_EQ(TypeKind::Time, et.type->kind);
  const Type* ton = h("Main.fb").type;
  ASSERT_EQ(TypeKind::Pou, ton->kind);
  EXPECT_EQ(main_addr() + offset_of("fb") + ton->field("Q")->offset, q.addr);
}

TEST_F(Engine, ResolvesArrayElements) {
  VarHandle a1 = h("Main.arr[1]"), a3 = h("Main.arr[3]");
  EXPECT_EQ(TypeKind::Int, a3.type->kind);
  EXPECT_EQ(main_addr() + offset_of("arr"), a1.addr);
  EXPECT_EQ(a1.addr + 4, a3.addr);
  // row-major: grid[1, 2] is element 1 * 3 + 2
  EXPECT_EQ(h("Main.grid[0,0]").addr + 5 * 2, h("Main.grid[1, 2]").addr);
  EXPECT_EQ(TypeKind::Real, h("Main.pts[2].y").type->kind);
  EXPECT_EQ(h("Main.pts[1].field").addr + h("Main.pts").type->elem->size, h("Main.pts[2].field").addr);
}

TEST_F(Engine, ResolvesAStructField) {
  VarHandle f = h("Main.s.field"), y = h("Main.s.y");
  EXPECT_EQ(TypeKind::Int, f.type->kind);
  EXPECT_EQ(TypeKind::Real, y.type->kind);
  EXPECT_EQ(main_addr() + offset_of("s"), f.addr);
  EXPECT_EQ(f.addr + 4, y.addr);  // REAL aligned to 4 after the INT
}

TEST_F(Engine, ResolvesSingleBitsOfAWord) {
  VarHandle b3 = h("Main.w.3"), b11 = h("Main.w.11");
  EXPECT_TRUE(b3.is_bit);
  EXPECT_EQ(3, b3.bit);
  EXPECT_EQ(TypeKind::Bool, b3.type->kind);
  EXPECT_EQ(main_addr() + offset_of("w"), b3.addr);
  EXPECT_EQ(b3.addr + 1, b11.addr);
  EXPECT_EQ(3, b11.bit);
  write_int(*m, h("Main.w"), 0x0808);
  EXPECT_TRUE(read_bool(*m, b3));
  EXPECT_TRUE(read_bool(*m, b11));
  EXPECT_FALSE(read_bool(*m, h("Main.w.4")));
  write_bool(*m, b3, false);
  EXPECT_EQ(0x0800, read_int(*m, h("Main.w")));
}

TEST_F(Engine, ResolvesGlobalsByNameAndByListName) {
  VarHandle g = h("x"), scoped = h("GVL.x");
  EXPECT_EQ(TypeKind::Int, g.type->kind);
  EXPECT_EQ(g.addr, scoped.addr);
  EXPECT_EQ(7, read_int(*m, g));
  EXPECT_EQ(100, read_int(*m, h("GVL.limit")));
  EXPECT_NE(g.addr, h("Main.x").addr);  // the program's own x is another variable
  bool found = false;
  for (const auto& gv : b->app->globals)
    if (gv.sym->name == "x") found = gv.scope == "GVL";
  EXPECT_TRUE(found);
}

TEST_F(Engine, ResolvesDirectAddresses) {
  VarHandle ix = h("%IX0.3");
  EXPECT_TRUE(ix.is_bit);
  EXPECT_EQ(3, ix.bit);
  EXPECT_EQ(b->app->image_i.addr, ix.addr);
  EXPECT_EQ(TypeKind::Bool, ix.type->kind);
  VarHandle qw = h("%QW2");
  EXPECT_FALSE(qw.is_bit);
  EXPECT_EQ(TypeKind::Word, qw.type->kind);
  EXPECT_EQ(b->app->image_q.addr + 4, qw.addr);
  EXPECT_EQ(TypeKind::DWord, h("%MD1").type->kind);
  EXPECT_EQ(b->app->image_m.addr + 4, h("%MD1").addr);
  // located program variables resolve to the same place
  VarHandle in3 = h("Main.in3");
  EXPECT_EQ(ix.addr, in3.addr);
  EXPECT_EQ(ix.bit, in3.bit);
  EXPECT_EQ(qw.addr, h("Main.qw").addr);
  write_bool(*m, ix, true);
  EXPECT_TRUE(read_bool(*m, in3));
  EXPECT_EQ(8, read_int(*m, h("%IB0")));
}

TEST_F(Engine, ResolveErrorsNameTheProblem) {
  EXPECT_EQ("path 'Nope.x': no program instance or global variable named 'Nope' (program instances: Main)",
            resolve_error("Nope.x"));
  EXPECT_EQ("path 'Main.nothing': 'Main' has no member 'nothing'", resolve_error("Main.nothing"));
  EXPECT_EQ("path 'Main.fb.QQ': 'TON' has no member 'QQ'", resolve_error("Main.fb.QQ"));
  EXPECT_EQ("path 'Main.arr[6]': index 6 outside 1..5", resolve_error("Main.arr[6]"));
  EXPECT_EQ("path 'Main.arr[0]': index 0 outside 1..5", resolve_error("Main.arr[0]"));
  EXPECT_EQ("path 'Main.arr[1,2]': 'arr' needs 1 index(es)", resolve_error("Main.arr[1,2]"));
  EXPECT_EQ("path 'Main.x[1]': 'x' needs no index (not an array)", resolve_error("Main.x[1]"));
  EXPECT_EQ("path 'Main.arr[i]': expected a constant index at column 10", resolve_error("Main.arr[i]"));
  EXPECT_EQ("path 'Main.w.16': bit 16 does not exist in WORD", resolve_error("Main.w.16"));
  EXPECT_EQ("path 'Main.r.1': bit access needs an integer or bit string, not REAL", resolve_error("Main.r.1"));
  EXPECT_EQ("path 'Main.w.3.x': a single bit has no members", resolve_error("Main.w.3.x"));
  EXPECT_EQ("path 'Main.x.': ends with '.'", resolve_error("Main.x."));
  EXPECT_EQ("path 'Main x': unexpected ' ' at column 5", resolve_error("Main x"));
}

TEST_F(Engine, BadDirectAddressesAreRejected) {
  EXPECT_EQ("'%IX0.8': a bit address is %IXbyte.bit with bit 0..7", resolve_error("%IX0.8"));
  EXPECT_EQ("'%IX0': a bit address is %IXbyte.bit with bit 0..7", resolve_error("%IX0"));
  EXPECT_EQ("'%QW1.2': a byte/word address has one number", resolve_error("%QW1.2"));
  EXPECT_EQ("'%ZX0.0': the area must be I, Q or M", resolve_error("%ZX0.0"));
  EXPECT_EQ("'%QW2048' is outside the %Q image (4096 bytes)", resolve_error("%QW2048"));
  EXPECT_EQ("'%IXa.1' is not a valid address", resolve_error("%IXa.1"));
  EXPECT_EQ("'%I' is not a direct address", resolve_error("%I"));
}

// ------------------------------------------------------------------ typed access

TEST_F(Engine, IntegerRoundTripsForEveryWidth) {
  struct {
    const char* path;
    int64_t v;
  } cases[] = {{"Main.si", -128}, {"Main.si", 127},      {"Main.i", -32768},      {"Main.i", 32767},
               {"Main.di", INT32_MIN}, {"Main.li", INT64_MIN}, {"Main.li", INT64_MAX}, {"Main.us", 255},
               {"Main.ui", 65535}, {"Main.ud", 4294967295}, {"Main.bt", 0xAB},      {"Main.dw", 0xDEADBEEF},
               {"Main.t", 1'500'000'000}, {"Main.c", 2}};
  for (auto c : cases) {
    write_int(*m, h(c.path), c.v);
    EXPECT_EQ(c.v, read_int(*m, h(c.path))) << c.path;
  }
  write_int(*m, h("Main.ul"), -1);
  EXPECT_EQ(18446744073709551615.0, read_real(*m, h("Main.ul")));
  EXPECT_EQ("18446744073709551615", format(*m, h("Main.ul")));
}

TEST_F(Engine, WriteIntWrapsToTheTypesWidth) {
  write_int(*m, h("Main.si"), 200);
  EXPECT_EQ(-56, read_int(*m, h("Main.si")));
  write_int(*m, h("Main.us"), 256 + 7);
  EXPECT_EQ(7, read_int(*m, h("Main.us")));
  write_int(*m, h("Main.i"), 65536 + 65535);
  EXPECT_EQ(-1, read_int(*m, h("Main.i")));
  write_int(*m, h("Main.b"), 5);
  EXPECT_EQ(1, read_int(*m, h("Main.b")));  // a BOOL stores 0 or 1
}

TEST_F(Engine, BoolAndRealRoundTrips) {
  write_bool(*m, h("Main.b"), true);
  EXPECT_TRUE(read_bool(*m, h("Main.b")));
  EXPECT_EQ(1, read_int(*m, h("Main.b")));
  write_bool(*m, h("Main.b"), false);
  EXPECT_FALSE(read_bool(*m, h("Main.b")));
  write_real(*m, h("Main.r"), 1.5);
  EXPECT_EQ(1.5, read_real(*m, h("Main.r")));
  write_real(*m, h("Main.r"), 0.1);
  EXPECT_EQ(static_cast<double>(0.1f), read_real(*m, h("Main.r")));  // stored as a 32-bit float
  write_real(*m, h("Main.lr"), -1e300);
  EXPECT_EQ(-1e300, read_real(*m, h("Main.lr")));
  write_real(*m, h("Main.i"), 2.6);  // a number into an integer rounds
  EXPECT_EQ(3, read_int(*m, h("Main.i")));
  EXPECT_EQ(3.0, read_real(*m, h("Main.i")));
  write_int(*m, h("Main.lr"), 42);
  EXPECT_EQ(42.0, read_real(*m, h("Main.lr")));
  EXPECT_EQ(42, read_int(*m, h("Main.lr")));
}

TEST_F(Engine, FormatWritesValuesAsStWould) {
  write_bool(*m, h("Main.b"), true);
  EXPECT_EQ("TRUE", format(*m, h("Main.b")));
  EXPECT_EQ("FALSE", format(*m, h("Main.w.0")));
  write_int(*m, h("Main.i"), -5);
  EXPECT_EQ("-5", format(*m, h("Main.i")));
  write_real(*m, h("Main.r"), 1.5);
  EXPECT_EQ("1.5", format(*m, h("Main.r")));
  write_real(*m, h("Main.lr"), 0.25);
  EXPECT_EQ("0.25", format(*m, h("Main.lr")));
  write_int(*m, h("Main.t"), 1'500'000'000);
  EXPECT_EQ("T#1s500ms", format(*m, h("Main.t")));
  write_int(*m, h("Main.t"), 0);
  EXPECT_EQ("T#0s", format(*m, h("Main.t")));
  write_int(*m, h("Main.t"), (26LL * 3600 + 60 + 1) * 1'000'000'000 + 2'000);
  EXPECT_EQ("T#1d2h1m1s2us", format(*m, h("Main.t")));
  write_int(*m, h("Main.t"), -250'000'000);
  EXPECT_EQ("T#-250ms", format(*m, h("Main.t")));
  EXPECT_EQ("Green", format(*m, h("Main.c")));  // the declared initial value
  write_int(*m, h("Main.c"), 7);
  EXPECT_EQ("Color#7", format(*m, h("Main.c")));
  write_int(*m, h("Main.bt"), 255);
  EXPECT_EQ("16#FF", format(*m, h("Main.bt")));
  EXPECT_EQ("(Point)", format(*m, h("Main.s")));
  EXPECT_EQ("''", format(*m, h("Main.str")));
  EXPECT_EQ("7", format(*m, h("GVL.x")));
}

TEST_F(Engine, WriteTextAcceptsStLiterals) {
  EXPECT_EQ("ok", set_text("Main.b", "TRUE"));
  EXPECT_TRUE(read_bool(*m, h("Main.b")));
  EXPECT_EQ("ok", set_text("Main.b", "0"));
  EXPECT_FALSE(read_bool(*m, h("Main.b")));
  EXPECT_EQ("ok", set_text("Main.i", "42"));
  EXPECT_EQ(42, read_int(*m, h("Main.i")));
  EXPECT_EQ("ok", set_text("Main.i", "-5"));
  EXPECT_EQ(-5, read_int(*m, h("Main.i")));
  EXPECT_EQ("ok", set_text("Main.i", "16#7FFF"));
  EXPECT_EQ(32767, read_int(*m, h("Main.i")));
  EXPECT_EQ("ok", set_text("Main.r", "1.5"));
  EXPECT_EQ(1.5, read_real(*m, h("Main.r")));
  EXPECT_EQ("ok", set_text("Main.lr", "-2"));
  EXPECT_EQ(-2.0, read_real(*m, h("Main.lr")));
  EXPECT_EQ("ok", set_text("Main.t", "T#1s500ms"));
  EXPECT_EQ(1'500'000'000, read_int(*m, h("Main.t")));
  EXPECT_EQ("ok", set_text("Main.str", "'abc'"));
  EXPECT_EQ("'abc'", format(*m, h("Main.str")));
  EXPECT_EQ("ok", set_text("Main.str10", "'abcdefghijklmnop'"));
  EXPECT_EQ("'abcdefghij'", format(*m, h("Main.str10")));  // cut to the declared length
  EXPECT_EQ("ok", set_text("Main.c", "Blue"));
  EXPECT_EQ(2, read_int(*m, h("Main.c")));
  EXPECT_EQ("ok", set_text("Main.c", "Color#Red"));
  EXPECT_EQ("Red", format(*m, h("Main.c")));
  EXPECT_EQ("ok", set_text("Main.w.5", "TRUE"));
  EXPECT_EQ(32, read_int(*m, h("Main.w")));
  EXPECT_EQ("ok", set_text("Main.pct", "100"));
  EXPECT_EQ(100, read_int(*m, h("Main.pct")));
}

TEST_F(Engine, WriteTextRejectsValuesThatDoNotFit) {
  EXPECT_EQ("40000 is outside the range of Main.i (INT: -32768..32767)", set_text("Main.i", "40000"));
  EXPECT_EQ("-1 is outside the range of Main.us (USINT: 0..255)", set_text("Main.us", "-1"));
  EXPECT_EQ("101 is outside the range of Main.pct (INT (0..100): 0..100)", set_text("Main.pct", "101"));
  EXPECT_EQ("'1.5' does not fit Main.i (INT)", set_text("Main.i", "1.5"));
  EXPECT_EQ("''abc'' does not fit Main.i (INT)", set_text("Main.i", "'abc'"));
  EXPECT_EQ("'42' does not fit Main.t (TIME)", set_text("Main.t", "42"));
  EXPECT_EQ("'2' does not fit Main.b (BOOL)", set_text("Main.b", "2"));
  EXPECT_EQ("'42' does not fit Main.str (STRING)", set_text("Main.str", "42"));
  EXPECT_EQ("'x + 1' is not a literal (expected e.g. TRUE, 42, 1.5, T#2s, 'text')", set_text("Main.i", "x + 1"));
  EXPECT_EQ("'Purple' is not a literal (expected e.g. TRUE, 42, 1.5, T#2s, 'text')", set_text("Main.c", "Purple"));
  EXPECT_EQ("'4 4' is not a valid ST literal for Main.i", set_text("Main.i", "4 4"));
  EXPECT_EQ("cannot set Main.s: Point is not an elementary type", set_text("Main.s", "1"));
  // nothing was written by the rejected texts
  EXPECT_EQ(0, read_int(*m, h("Main.i")));
  EXPECT_EQ(0, read_int(*m, h("Main.us")));
  EXPECT_EQ(0, read_int(*m, h("Main.pct")));
}

// ------------------------------------------------------------------ configuration and tasks

const char* kConfig = R"(PROGRAM Fast
VAR n : DINT; END_VAR
n := n + 1;
END_PROGRAM
PROGRAM Slow
VAR n : DINT; END_VAR
n := n + 10;
END_PROGRAM
CONFIGURATION Cell
VAR_GLOBAL speed : INT := 3; END_VAR
RESOURCE Cpu ON PLC
  TASK T10 (INTERVAL := T#10ms, PRIORITY := 1);
  TASK T100 (INTERVAL := T#100ms, PRIORITY := 5);
  PROGRAM f1 WITH T10 : Fast;
  PROGRAM s1 WITH T100 : Slow;
  PROGRAM s2 WITH T100 : Slow;
END_RESOURCE
END_CONFIGURATION
)";

TEST(EngineConfiguration, TasksAndProgramInstancesAreBound) {
  auto b = build_sources({{"cell.st", kConfig}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  const Application& app = *b->app;
  EXPECT_TRUE(app.has_configuration);
  ASSERT_EQ(2u, app.tasks.size());
  EXPECT_EQ("T10", app.tasks[0].name);
  EXPECT_EQ(10'000'000, app.tasks[0].interval_ns);
  EXPECT_EQ(1, app.tasks[0].priority);
  EXPECT_EQ("T100", app.tasks[1].name);
  EXPECT_EQ(100'000'000, app.tasks[1].interval_ns);
  EXPECT_EQ(5, app.tasks[1].priority);
  ASSERT_EQ(3u, app.programs.size());
  EXPECT_EQ("f1", app.programs[0].name);
  EXPECT_EQ("Fast", app.programs[0].pou->name);
  EXPECT_EQ("T10", app.programs[0].task);
  EXPECT_EQ("s1", app.programs[1].name);
  EXPECT_EQ("T100", app.programs[1].task);
  EXPECT_EQ("s2", app.programs[2].name);
  EXPECT_EQ("Slow", app.programs[2].pou->name);
  EXPECT_NE(app.programs[1].addr, app.programs[2].addr);  // two instances of one type
  EXPECT_EQ((std::vector<size_t>{0}), app.tasks[0].programs);
  EXPECT_EQ((std::vector<size_t>{1, 2}), app.tasks[1].programs);

  Machine m(app);
  ASSERT_TRUE(m.call(app.programs[1].pou->entry, app.programs[1].addr));
  ASSERT_TRUE(m.call(app.programs[1].pou->entry, app.programs[1].addr));
  ASSERT_TRUE(m.call(app.programs[2].pou->entry, app.programs[2].addr));
  std::string err;
  EXPECT_EQ(20, read_int(m, *resolve(app, "s1.n", &err)));
  EXPECT_EQ(10, read_int(m, *resolve(app, "s2.n", &err)));
  EXPECT_EQ(0, read_int(m, *resolve(app, "f1.n", &err)));
  auto speed = resolve(app, "speed", &err);
  ASSERT_TRUE(speed) << err;
  EXPECT_EQ(3, read_int(m, *speed));
}

TEST(EngineConfiguration, WithoutConfigurationEveryProgramGetsOneInstance) {
  auto b = build_sources({{"two.st", "PROGRAM A\nEND_PROGRAM\nPROGRAM B\nEND_PROGRAM\n"}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  EXPECT_FALSE(b->app->has_configuration);
  EXPECT_TRUE(b->app->tasks.empty());
  ASSERT_EQ(2u, b->app->programs.size());
  EXPECT_EQ("A", b->app->programs[0].name);
  EXPECT_EQ("", b->app->programs[0].task);
  EXPECT_EQ("B", b->app->programs[1].name);
}

// ------------------------------------------------------------------ restarts

const char* kRetain = R"(PROGRAM Main
VAR plain : DINT := 5; END_VAR
VAR RETAIN kept : DINT := 1; END_VAR
plain := plain + 1;
kept := kept + 1;
END_PROGRAM
)";

TEST(EngineRestart, WarmRestartKeepsOnlyRetainVariables) {
  auto b = build_sources({{"retain.st", kRetain}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  Machine m(*b->app);
  std::string err;
  VarHandle plain = *resolve(*b->app, "Main.plain", &err), kept = *resolve(*b->app, "Main.kept", &err);
  const auto& p = b->app->programs[0];
  EXPECT_EQ(5, read_int(m, plain));  // a new machine starts cold
  EXPECT_EQ(1, read_int(m, kept));
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(m.call(p.pou->entry, p.addr));
  EXPECT_EQ(8, read_int(m, plain));
  EXPECT_EQ(4, read_int(m, kept));

  m.warm_restart();
  EXPECT_EQ(5, read_int(m, plain));
  EXPECT_EQ(4, read_int(m, kept));
  ASSERT_TRUE(m.call(p.pou->entry, p.addr));
  EXPECT_EQ(6, read_int(m, plain));
  EXPECT_EQ(5, read_int(m, kept));

  m.cold_restart();
  EXPECT_EQ(5, read_int(m, plain));
  EXPECT_EQ(1, read_int(m, kept));
}


// FB_init and FB_exit (CODESYS): FB_init at every restart with bInitRetains TRUE on a cold
// start and FALSE on a warm one; FB_exit of the instances that ran before the next restart.
const char* kLifecycle = R"(VAR_GLOBAL RETAIN exits : INT; END_VAR
VAR_GLOBAL inits : INT; retains : BOOL; divisor : INT := 1; END_VAR
FUNCTION_BLOCK Counted
METHOD FB_init : BOOL
VAR_INPUT bInitRetains : BOOL; bInCopyCode : BOOL; END_VAR
inits := inits + 100 / divisor;
retains := bInitRetains;
END_METHOD
METHOD FB_exit : BOOL
VAR_INPUT bInCopyCode : BOOL; END_VAR
exits := exits + 1;
END_METHOD
END_FUNCTION_BLOCK
PROGRAM Main
VAR a, b : Counted; END_VAR
END_PROGRAM
)";

TEST(EngineRestart, FbInitAndFbExitRunAtEveryRestart) {
  CompileOptions opt;
  opt.dialect = Dialect::Codesys;
  auto b = build_sources({{"lifecycle.st", kLifecycle}}, opt);
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  Machine m(*b->app);
  std::string err;
  VarHandle inits = *resolve(*b->app, "inits", &err), exits = *resolve(*b->app, "exits", &err),
            retains = *resolve(*b->app, "retains", &err), divisor = *resolve(*b->app, "divisor", &err);
  EXPECT_EQ(0, read_int(m, inits)) << "a new machine holds the cold-start image";
  ASSERT_TRUE(m.cold_restart()) << m.trap().message;
  EXPECT_EQ(200, read_int(m, inits));
  EXPECT_EQ(0, read_int(m, exits)) << "nothing ran before the first restart";
  EXPECT_EQ(1, read_int(m, retains));

  ASSERT_TRUE(m.warm_restart()) << m.trap().message;
  EXPECT_EQ(200, read_int(m, inits)) << "reset, then initialised again";
  EXPECT_EQ(2, read_int(m, exits)) << "one FB_exit per instance, kept by the warm restart";
  EXPECT_EQ(0, read_int(m, retains));

  ASSERT_TRUE(m.warm_restart()) << m.trap().message;
  EXPECT_EQ(4, read_int(m, exits));
  ASSERT_TRUE(m.cold_restart()) << m.trap().message;
  EXPECT_EQ(0, read_int(m, exits));

  // A trap in FB_init: the restart says so and names the place.
  write_int(m, divisor, 0);
  ASSERT_TRUE(m.warm_restart()) << "divisor is reset to 1 before FB_init runs";
  EXPECT_EQ(200, read_int(m, inits));
}

TEST(EngineRestart, ATrapInFbInitFailsTheRestart) {
  CompileOptions opt;
  opt.dialect = Dialect::Codesys;
  std::string src = kLifecycle;
  src.replace(src.find("divisor : INT := 1"), 18, "divisor : INT := 0");
  auto b = build_sources({{"lifecycle.st", src}}, opt);
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  Machine m(*b->app);
  EXPECT_FALSE(m.cold_restart());
  EXPECT_EQ(TrapKind::DivisionByZero, m.trap().kind);
  EXPECT_EQ("lifecycle.st:6:", b->app->where(m.trap().loc).substr(0, 15)) << "the division in FB_init";
}

TEST(EngineRestart, FbInitIsCodesysOnly) {
  auto b = build_sources({{"lifecycle.st", kLifecycle}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  EXPECT_FALSE(b->app->has_init) << "under --dialect iec FB_init is a method like any other";
  Machine m(*b->app);
  ASSERT_TRUE(m.cold_restart());
  std::string err;
  EXPECT_EQ(0, read_int(m, *resolve(*b->app, "inits", &err)));
}

}  // namespace
}  // namespace plcfi::st
