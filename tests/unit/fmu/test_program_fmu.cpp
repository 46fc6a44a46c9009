// The program FMU's ports, manifest and model description (driver/fmu): which located
// variables become inputs and outputs and with which FMI type, what is refused, and the
// manifest the FMU binary reads back from its archive.
#include <gtest/gtest.h>

#include "engine.hpp"
#include "fmu/export.hpp"
#include "fmu/program_fmu.hpp"

namespace plcfi::fmu {
namespace {

std::unique_ptr<st::Build> build(const std::string& src) {
  st::CompileOptions opt;
  opt.warnings = false;
  auto b = st::build_sources({{"p.st", src}}, opt);
  EXPECT_TRUE(b->ok()) << b->diags.render_all();
  return b;
}

TEST(ProgramFmuPorts, GlobalsAndProgramVariablesInAddressOrderInputsFirst) {
  auto b = build(R"(
PROGRAM Main
VAR
  lamp AT %QX0.1 : BOOL;
  level AT %ID4 : REAL;
  count AT %QD1 : UDINT;
  local : INT;
END_VAR
lamp := start; count := count + 1;
END_PROGRAM
CONFIGURATION Cell
  VAR_GLOBAL
    start AT %IX0.0 : BOOL;
    speed AT %IW1 : INT;
    valve AT %QX0.0 : BOOL;
    plain : BOOL;
  END_VAR
  RESOURCE R ON PLC
    TASK T (INTERVAL := T#20ms, PRIORITY := 1);
    PROGRAM Main WITH T : Main;
  END_RESOURCE
END_CONFIGURATION
)");
  std::vector<Port> ports;
  std::string err;
  ASSERT_TRUE(list_ports(*b->app, &ports, &err)) << err;
  std::vector<std::string> got;
  for (const auto& p : ports)
    got.push_back(std::string(p.input ? "in " : "out ") + fmi_type_name(p.fmi) + " " + p.path + " " + p.address + " " +
                  p.type);
  EXPECT_EQ(got, (std::vector<std::string>{"in Boolean start %IX0.0 BOOL", "in Integer speed %IW1 INT",
                                           "in Real Main.level %ID4 REAL", "out Boolean valve %QX0.0 BOOL",
                                           "out Boolean Main.lamp %QX0.1 BOOL", "out Real Main.count %QD1 UDINT"}));
}

TEST(ProgramFmuPorts, RefusesWhatFmiCannotCarry) {
  auto b = build("PROGRAM Main\nVAR\n  t AT %IL0 : TIME;\n  q AT %QX0.0 : BOOL;\nEND_VAR\nq := t > T#1s;\nEND_PROGRAM\n");
  std::vector<Port> ports;
  std::string err;
  EXPECT_FALSE(list_ports(*b->app, &ports, &err));
  EXPECT_NE(err.find("p.st:3:3: Main.t at %IL0 is TIME: FMI 2.0 has no type"), std::string::npos) << err;
}

TEST(ProgramFmuManifest, WritesAndReadsBack) {
  Manifest m;
  m.guid = "plcfi-0123";
  m.model_identifier = m.model_name = "cell";
  m.dialect = st::Dialect::Codesys;
  m.strict = true;
  m.program = "Main";
  m.cycle_ns = 5'000'000;
  m.tick_ns = 5'000'000;
  m.libraries = {"lib/000_util.st"};
  m.sources = {"src/000_main.st", "src/001_gvl.TcGVL"};
  m.ports = {{true, FmiType::Real, "Main.level", "%ID1", "REAL"}, {false, FmiType::Integer, "valve", "%QW0", "WORD"}};
  const std::string text = write_manifest(m);
  Manifest r;
  std::string err;
  ASSERT_TRUE(read_manifest(text, &r, &err)) << err;
  EXPECT_EQ(write_manifest(r), text);
  EXPECT_EQ(r.dialect, st::Dialect::Codesys);
  EXPECT_TRUE(r.strict);
  EXPECT_EQ(r.ports[1].path, "valve");
  EXPECT_FALSE(r.ports[1].input);
}

TEST(ProgramFmuManifest, ErrorsNameTheLine) {
  const std::string head = "plcfi-program-fmu 1\nguid g\ntick_ns 1000\nsource src/000_a.st\n";
  const std::pair<std::string, std::string> cases[] = {
      {"plcfi-program-fmu 2\n", "line 1: not a plcfi program FMU manifest"},
      {head + "port input Boolean x\n", "line 5: a port is"},
      {head + "port sideways Boolean x %IX0.0 BOOL\n", "line 5: a port is"},
      {head + "port input Float x %IX0.0 BOOL\n", "line 5: unknown FMI type 'Float'"},
      {head + "source ../../etc/passwd\n", "line 5: '../../etc/passwd' is not a file inside resources/plcfi/"},
      {head + "library /etc/passwd\n", "line 5: '/etc/passwd' is not a file inside resources/plcfi/"},
      {head + "tick_ns -5\n", "line 5: tick_ns must be a positive number"},
      {head + "colour blue\n", "line 5: unknown key 'colour'"},
      {head, "incomplete manifest"},  // no port
  };
  for (const auto& [text, want] : cases) {
    Manifest m;
    std::string err;
    EXPECT_FALSE(read_manifest(text, &m, &err)) << text;
    EXPECT_NE(err.find(want), std::string::npos) << err;
  }
}

TEST(ProgramFmuModelDescription, PortsThenParametersAndTheOutputsInModelStructure) {
  Manifest m;
  m.guid = "plcfi-1";
  m.model_identifier = m.model_name = "cell";
  m.tick_ns = 20'000'000;
  m.sources = {"src/000_main.st"};
  m.ports = {{true, FmiType::Boolean, "start", "%IX0.0", "BOOL"}, {false, FmiType::Integer, "Main.out", "%QW0", "INT"}};
  const std::string md = model_description(m);
  EXPECT_NE(md.find("<ScalarVariable name=\"start\" valueReference=\"0\""), std::string::npos);
  EXPECT_NE(md.find("causality=\"input\" variability=\"discrete\">\n      <Boolean start=\"false\"/>"), std::string::npos);
  EXPECT_NE(md.find("<ScalarVariable name=\"Main.out\" valueReference=\"1\""), std::string::npos);
  EXPECT_NE(md.find("<ScalarVariable name=\"fault.start\" valueReference=\"1000000\""), std::string::npos);
  EXPECT_NE(md.find("<ScalarVariable name=\"fault_at.Main.out\" valueReference=\"2000001\""), std::string::npos);
  EXPECT_NE(md.find("<ScalarVariable name=\"seed\" valueReference=\"3000000\""), std::string::npos);
  EXPECT_NE(md.find("<Outputs>\n      <Unknown index=\"2\"/>\n    </Outputs>"), std::string::npos);
  EXPECT_NE(md.find("<DefaultExperiment startTime=\"0\" stepSize=\"0.02\"/>"), std::string::npos);
  EXPECT_NE(md.find("modelIdentifier=\"cell\""), std::string::npos);
}

}  // namespace
}  // namespace plcfi::fmu
