// The report layer's outputs, checked exactly: JUnit XML (escaping, outcomes, properties),
// VCD and CSV traces (header, hierarchy, change-only values, number formats) and the
// PlantUML diagrams of a test case.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "engine.hpp"
#include "report/junit.hpp"
#include "report/puml.hpp"
#include "report/trace.hpp"

namespace plcfi::report {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string temp_path(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string("plcfi_report_") + std::to_string(::getpid()) + "_" + name)).string();
}

TEST(Junit, EveryOutcomeAndPropertyExactly) {
  JunitSuite s;
  s.name = "campaign.stamping";
  s.properties = {{"cycle_ms", "10"}, {"overruns", "0"}};
  JunitCase pass{"stamping", "TC1 path 1", 0.5, JunitCase::Outcome::Pass, "", "", {}};
  JunitCase fail{"stamping", "TC3 path 1", 0.25, JunitCase::Outcome::Fail, "deadline missed", "gStampStop not seen within 600 ms",
                 {{"rpn", "45"}}};
  JunitCase skip{"stamping", "TC9", 0, JunitCase::Outcome::Skipped, "NOT REACHED", "", {}};
  JunitCase error{"stamping", "TC10", 0, JunitCase::Outcome::Error, "trap", "division by zero", {}};
  s.cases = {pass, fail, skip, error};
  EXPECT_EQ(junit_xml({s}),
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<testsuites>\n"
            "  <testsuite name=\"campaign.stamping\" tests=\"4\" failures=\"1\" errors=\"1\" skipped=\"1\" time=\"0.750000\">\n"
            "    <properties>\n"
            "      <property name=\"cycle_ms\" value=\"10\"/>\n"
            "      <property name=\"overruns\" value=\"0\"/>\n"
            "    </properties>\n"
            "    <testcase classname=\"stamping\" name=\"TC1 path 1\" time=\"0.500000\"/>\n"
            "    <testcase classname=\"stamping\" name=\"TC3 path 1\" time=\"0.250000\">\n"
            "      <properties>\n"
            "        <property name=\"rpn\" value=\"45\"/>\n"
            "      </properties>\n"
            "      <failure message=\"deadline missed\">gStampStop not seen within 600 ms</failure>\n"
            "    </testcase>\n"
            "    <testcase classname=\"stamping\" name=\"TC9\" time=\"0.000000\">\n"
            "      <skipped message=\"NOT REACHED\"></skipped>\n"
            "    </testcase>\n"
            "    <testcase classname=\"stamping\" name=\"TC10\" time=\"0.000000\">\n"
            "      <error message=\"trap\">division by zero</error>\n"
            "    </testcase>\n"
            "  </testsuite>\n"
            "</testsuites>\n");
}

TEST(Junit, TextIsEscapedIntoWellFormedXml) {
  EXPECT_EQ(xml_escape("a<b & \"c\" > 'd'"), "a&lt;b &amp; &quot;c&quot; &gt; &apos;d&apos;");
  EXPECT_EQ(xml_escape("line1\nline2\ttab"), "line1\nline2\ttab");
  // XML 1.0 has no way to write other control characters (not even as &#1;), and a byte
  // that is not UTF-8 would make the whole report unreadable: both become visible text.
  EXPECT_EQ(xml_escape(std::string("nul\0bell\x07", 9)), "nul\\x00bell\\x07");
  EXPECT_EQ(xml_escape("bad \xff byte"), "bad \xEF\xBF\xBD byte");
  EXPECT_EQ(xml_escape("truncated \xC3"), "truncated \xEF\xBF\xBD");
  EXPECT_EQ(xml_escape("Stra\xC3\x9F" "e \xE2\x82\xAC"), "Stra\xC3\x9F" "e \xE2\x82\xAC");  // valid UTF-8 stays
}

TEST(Junit, WritesTheFileAndReportsAnUnwritablePath) {
  std::string path = temp_path("junit.xml"), err;
  JunitSuite s{"st", {JunitCase{"f.st", "t", 0, JunitCase::Outcome::Pass, "", "", {}}}, {}};
  ASSERT_TRUE(write_junit(path, {s}, &err)) << err;
  EXPECT_EQ(slurp(path), junit_xml({s}));
  std::filesystem::remove(path);
  EXPECT_FALSE(write_junit("/nonexistent-dir/x.xml", {s}, &err));
  EXPECT_EQ(err, "/nonexistent-dir/x.xml: cannot write");
}

class TraceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    b_ = st::build_sources({{"t.st", R"(
TYPE Pair : STRUCT a : INT; b : BOOL; END_STRUCT; END_TYPE
PROGRAM P
VAR
  run : BOOL;
  n : INT;
  u : UINT;
  level : REAL;
  t : TIME;
  pr : Pair;
  valve AT %QX0.1 : BOOL;
END_VAR
END_PROGRAM
)"}},
                           st::CompileOptions{});
    ASSERT_TRUE(b_->ok()) << b_->diags.render_all();
    m_ = std::make_unique<st::Machine>(*b_->app);
    for (const char* p : {"P.run", "P.n", "P.u", "P.level", "P.t", "P.pr.a", "P.pr.b"}) vars_.push_back(handle(p));
  }
  st::VarHandle handle(const char* path) {
    std::string err;
    auto h = st::resolve(*b_->app, path, &err);
    EXPECT_TRUE(h) << err;
    return *h;
  }
  void set(const char* path, const char* value) {
    std::string err;
    ASSERT_TRUE(st::write_text(*m_, handle(path), value, &err)) << err;
  }
  // Three samples: the initial values, a change of some, then no change at all.
  std::string record(std::unique_ptr<TraceWriter> w, const std::string& path) {
    std::string err;
    EXPECT_TRUE(w) << "could not open";
    if (!w) return "";
    w->sample(0, *m_);
    set("P.run", "TRUE");
    set("P.n", "-3");
    set("P.u", "65535");
    set("P.level", "2.5");
    set("P.t", "T#1.5s");
    set("P.pr.b", "TRUE");
    w->sample(10'000'000, *m_);
    w->sample(20'000'000, *m_);
    EXPECT_TRUE(w->close(&err)) << err;
    std::string text = slurp(path);
    std::filesystem::remove(path);
    return text;
  }

  std::unique_ptr<st::Build> b_;
  std::unique_ptr<st::Machine> m_;
  std::vector<st::VarHandle> vars_;
};

TEST_F(TraceTest, VcdHierarchyAndChangeOnlyValues) {
  std::string path = temp_path("t.vcd"), err;
  EXPECT_EQ(record(open_vcd(path, vars_, &err), path),
            "$version plcfi $end\n"
            "$timescale 1ns $end\n"
            "$scope module P $end\n"
            "$var wire 1 ! run $end\n"
            "$var integer 16 \" n $end\n"
            "$var reg 16 # u $end\n"
            "$var real 64 $ level $end\n"
            "$var integer 64 % t $end\n"
            "$scope module pr $end\n"
            "$var integer 16 & a $end\n"
            "$var wire 1 ' b $end\n"
            "$upscope $end\n"
            "$upscope $end\n"
            "$enddefinitions $end\n"
            "#0\n"
            "$dumpvars\n"
            "0!\n"
            "b0 \"\n"
            "b0 #\n"
            "r0 $\n"
            "b0 %\n"
            "b0 &\n"
            "0'\n"
            "$end\n"
            "#10000000\n"
            "1!\n"
            "b1111111111111101 \"\n"
            "b1111111111111111 #\n"
            "r2.5 $\n"
            "b1011001011010000010111100000000 %\n"
            "1'\n");
}

TEST_F(TraceTest, CsvRowsPerSample) {
  std::string path = temp_path("t.csv"), err;
  EXPECT_EQ(record(open_csv(path, vars_, &err), path),
            "time,P.run,P.n,P.u,P.level,P.t,P.pr.a,P.pr.b\n"
            "0,0,0,0,0,T#0s,0,0\n"
            "0.01,1,-3,65535,2.5,T#1s500ms,0,1\n"
            "0.02,1,-3,65535,2.5,T#1s500ms,0,1\n");
}

TEST_F(TraceTest, RefusesWhatATraceCannotHold) {
  std::string err;
  EXPECT_EQ(open_vcd(temp_path("s.vcd"), {handle("P.pr")}, &err), nullptr);
  EXPECT_EQ(err, "cannot trace 'P.pr' (Pair): name an elementary member or element");
  EXPECT_EQ(open_csv("/nonexistent-dir/t.csv", vars_, &err), nullptr);
  EXPECT_EQ(err.rfind("/nonexistent-dir/t.csv: cannot write (", 0), 0u) << err;
}

PumlCase stamping_case() {
  PumlCase c;
  c.id = "TC3";
  c.title = "init.ref_lower.StampLowered: reference stroke not completed";
  c.precondition = "Main.step = E_Step#InitRefLower";
  c.start = "";
  c.target = "StampLowered (%IX0.4)";
  c.fault = "stuck (pre-fault value)";
  c.reaction = "gStampCylError AND gStampStop";
  c.deadline_ns = 600'000'000;
  c.max_duration_ns = 30'000'000'000;
  c.fault_class = "1";
  c.restart = "cold";
  c.rpn = 45;
  c.transitions = {{"StampLower", "FALSE", "TRUE", -1, 100'000'000, 0, false},
                   {"StampLowered", "FALSE", "TRUE", 0, 500'000'000, 0.2, true}};
  return c;
}

TEST(Puml, SequenceDiagramOfATestCase) {
  EXPECT_EQ(sequence_diagram(stamping_case()),
            "@startuml TC3_sequence\n"
            "title TC3 (RPN 45, fault class 1)\\n"
            "init.ref_lower.StampLowered: reference stroke not completed\n"
            "participant \"Test system\\n"
            "(plcfi driver)\" as TS\n"
            "participant \"SUT\\n"
            "(PLC program)\" as SUT\n"
            "participant \"Plant\" as P\n"
            "== Start & init: wait for the precondition ==\n"
            "TS -> SUT : cold start, scan cycle running\n"
            "TS -> P : reset to the initial state\n"
            "loop every scan, before the program runs\n"
            "  TS -> TS : check precondition\\n"
            "Main.step = E_Step#InitRefLower\n"
            "end\n"
            "== Injection and monitoring ==\n"
            "TS -> SUT : inject fault on StampLowered (%IX0.4): stuck (pre-fault value)\n"
            "note right of TS : the fault acts on the I/O image overlay only\n"
            "P -> SUT : previous transition (start of the timing)\n"
            "P -> SUT : StampLower -> TRUE within 100 ms\n"
            "P -[#red]x SUT : StampLowered -> TRUE expected within 500 ms (suppressed by the fault)\n"
            "activate TS\n"
            "TS -> TS : monitor after each scan\\n"
            "gStampCylError AND gStampStop\n"
            "SUT -> TS : reaction within 600 ms of the start?\n"
            "note over TS : PASS: reaction in time\\n"
            "FAIL: deadline missed, forbidden reaction\\n"
            "or test longer than 30 s\n"
            "deactivate TS\n"
            "== Completion ==\n"
            "TS -> TS : log verdict (journal, JUnit, VCD)\n"
            "TS -> SUT : withdraw the fault\n"
            "TS -> SUT : stop, cold restart\n"
            "TS -> P : reset (re-initialize)\n"
            "TS -> TS : mark the case tested\n"
            "@enduml\n");
}

TEST(Puml, TimingDiagramOfATestCase) {
  EXPECT_EQ(timing_diagram(stamping_case()),
            "@startuml TC3_timing\n"
            "title TC3: expected transitions after the precondition\n"
            "robust \"StampLower\" as L0\n"
            "robust \"StampLowered (faulted)\" as L1\n"
            "concise \"Test\" as T\n"
            "@0\n"
            "T is \"start\"\n"
            "L0 is \"FALSE\"\n"
            "L1 is \"FALSE\"\n"
            "@100\n"
            "L0 is \"TRUE\"\n"
            "@500\n"
            "L1 is \"TRUE +/- 0.2\"\n"
            "@600\n"
            "T is \"deadline\"\n"
            "L0@0 <-> @100 : max 100 ms\n"
            "L1@0 <-> @500 : max 500 ms\n"
            "T@0 <-> @600 : reaction deadline 600 ms\n"
            "@enduml\n");
}

}  // namespace
}  // namespace plcfi::report
