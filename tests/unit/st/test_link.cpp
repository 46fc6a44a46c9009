// A second compilation unit linked onto a compiled program (link_generated/link_units):
// it sees the program's POUs, types, globals and instances through the program's own
// symbol table, runs against the same memory, and leaves the program as it was when it
// does not compile. The program's syntax tree may be gone inc then.
#include <gtest/gtest.h>

#include "engine.hpp"

namespace plcfi::st {
namespace {

const char* kProgram = R"(
TYPE Mode : (Idle, Busy, Done); END_TYPE
TYPE Pair : STRUCT a : INT; b : INT; END_STRUCT END_TYPE
VAR_GLOBAL
  limit : INT := 7;
END_VAR
FUNCTION Twice : INT
VAR_INPUT x : INT; END_VAR
Twice := 2 * x;
END_FUNCTION
FUNCTION_BLOCK Counter
VAR_OUTPUT n : INT; END_VAR
METHOD Add : INT
VAR_INPUT inc : INT := 3; END_VAR
n := n + inc;
Add := n;
END_METHOD
n := n + 1;
END_FUNCTION_BLOCK
PROGRAM Main
VAR
  step : INT;
  mode : Mode;
  p : Pair;
  c : Counter;
END_VAR
step := step + 1;
IF step > 2 THEN mode := Busy; END_IF
p.a := step;
c();
END_PROGRAM
)";

// Uses the program's function, FB type and method (with a default input), enumeration,
// STRUCT type, global and instance variables inc path.
const char* kProbe = R"(
PROGRAM Probe
VAR_OUTPUT
  doubled : INT;
  isbusy : BOOL;
  copy : Pair;
  over : BOOL;
  own : INT;
END_VAR
VAR
  mine : Counter;
END_VAR
doubled := Twice(Main.step);
isbusy := Main.mode = Busy;
copy := Main.p;
over := Main.step > limit;
own := mine.Add();
END_PROGRAM
)";

int16_t read16(Machine& m, const Application& app, const char* path) {
  std::string err;
  auto h = resolve(app, path, &err);
  EXPECT_TRUE(h) << err;
  return h ? static_cast<int16_t>(read_int(m, *h)) : 0;
}

TEST(Link, AUnitLinkedOntoAProgramSeesItsSymbolsAndMemory) {
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  const size_t program_pous = b->app->pous.size();
  const auto main_entry = b->app->programs.at(0).pou->entry;

  // The program's syntax tree is dropped: what the unit needs must be in the program.
  b->units.clear();
  ASSERT_TRUE(link_generated(*b, {{"<probe>", kProbe}}, CompileOptions{})) << b->diags.render_all();
  const Application& app = *b->app;
  ASSERT_EQ(app.observers.size(), 1u);
  EXPECT_EQ(app.observers[0].name, "Probe");
  EXPECT_EQ(app.pous.size(), program_pous + 1);
  EXPECT_EQ(app.programs.size(), 1u);  // the probe is no task's program
  EXPECT_EQ(app.programs[0].pou->entry, main_entry);

  Machine m(app);
  const ProgramInstance& main = app.programs[0];
  const ProgramInstance& probe = app.observers[0];
  for (int scan = 0; scan < 3; ++scan) ASSERT_TRUE(m.call(main.pou->entry, main.addr));
  ASSERT_TRUE(m.call(probe.pou->entry, probe.addr)) << describe_trap(app, m.trap());
  EXPECT_EQ(read16(m, app, "Probe.doubled"), 6);
  std::string err;
  auto busy = resolve(app, "Probe.isbusy", &err);
  ASSERT_TRUE(busy) << err;
  EXPECT_TRUE(read_bool(m, *busy));
  EXPECT_EQ(read16(m, app, "Probe.copy.a"), 3);
  EXPECT_EQ(read16(m, app, "Probe.own"), 3);  // Add() with its default input, 3
  auto over = resolve(app, "Probe.over", &err);
  ASSERT_TRUE(over) << err;
  EXPECT_FALSE(read_bool(m, *over));
  for (int scan = 0; scan < 5; ++scan) ASSERT_TRUE(m.call(main.pou->entry, main.addr));
  ASSERT_TRUE(m.call(probe.pou->entry, probe.addr));
  EXPECT_TRUE(read_bool(m, *over));  // step 8 > limit 7
  EXPECT_EQ(read16(m, app, "Probe.own"), 6);
  EXPECT_EQ(read16(m, app, "Main.c.n"), 8);  // the program's own instance is untouched
}

TEST(Link, AUnitThatDoesNotCompileLeavesTheProgramAsItWas) {
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  const Application& app = *b->app;
  const auto code = app.code;
  const auto image = app.init_image;
  const size_t pous = app.pous.size(), globals = app.globals.size(), types = app.type_names.size();
  const auto vtable = app.vtable;

  const char* bad = "TYPE Extra : INT; END_TYPE\nVAR_GLOBAL extra : INT; END_VAR\n"
                    "PROGRAM Broken\nVAR x : INT; END_VAR\nx := Main.nothing;\nEND_PROGRAM\n";
  EXPECT_FALSE(link_generated(*b, {{"<broken>", bad}}, CompileOptions{}));
  ASSERT_TRUE(b->app);
  EXPECT_NE(b->diags.render_all().find("<broken>:5:11: error[ST207]: 'Main' has no member 'nothing'"), std::string::npos)
      << b->diags.render_all();
  EXPECT_EQ(app.code, code);
  EXPECT_EQ(app.init_image, image);
  EXPECT_EQ(app.pous.size(), pous);
  EXPECT_EQ(app.globals.size(), globals);
  EXPECT_EQ(app.type_names.size(), types);
  EXPECT_EQ(app.vtable, vtable);
  EXPECT_TRUE(app.observers.empty());

  // The program still runs.
  Machine m(app);
  ASSERT_TRUE(m.call(app.programs[0].pou->entry, app.programs[0].addr));
  EXPECT_EQ(read16(m, app, "Main.step"), 1);
}

TEST(Link, ANewFunctionBlockWithMethodsGetsDispatchEntries) {
  auto b = build_sources({{"main.st", kProgram}}, CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  const char* unit = R"(
FUNCTION_BLOCK Faster EXTENDS Counter
METHOD Add : INT
VAR_INPUT inc : INT := 3; END_VAR
n := n + 10 * inc;
Add := n;
END_METHOD
END_FUNCTION_BLOCK
PROGRAM Probe2
VAR_OUTPUT r : INT; END_VAR
VAR f : Faster; END_VAR
r := f.Add(inc := 2);
END_PROGRAM
)";
  ASSERT_TRUE(link_generated(*b, {{"<unit>", unit}}, CompileOptions{})) << b->diags.render_all();
  const Application& app = *b->app;
  EXPECT_EQ(app.vtable.size() % app.n_types, 0u);
  Machine m(app);
  const ProgramInstance& probe = app.observers.at(0);
  ASSERT_TRUE(m.call(probe.pou->entry, probe.addr)) << describe_trap(app, m.trap());
  EXPECT_EQ(read16(m, app, "Probe2.r"), 20);
}

}  // namespace
}  // namespace plcfi::st
