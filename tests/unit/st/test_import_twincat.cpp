// TwinCAT 3 importer (driver/st/import/twincat.cpp): the ST it assembles from .TcPOU,
// .TcIO, .TcDUT, .TcGVL, .TcTTO and .plcproj files, checked as exact snapshots, and its
// diagnostics, which point at the line and column of the XML file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "engine.hpp"
#include "import/import.hpp"

namespace plcfi::st {
namespace {

namespace fs = std::filesystem;

// A private directory of project files, removed afterwards.
struct Dir {
  Dir() {
    static int n = 0;
    path = (fs::temp_directory_path() / ("plcfi_twincat_" + std::to_string(::getpid()) + "_" + std::to_string(n++))).string();
    fs::create_directories(path);
  }
  ~Dir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& text) {
    fs::path p = fs::path(path) / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  std::string path;
};

struct Imported {
  SourceManager sm;
  DiagEngine diags{sm};
  std::vector<uint32_t> units;
  bool ok = false;

  std::string text(size_t i) const { return sm.file(units.at(i)).text; }
  // The generated unit's line `line`, resolved to "file-name:line:col".
  std::string origin(size_t i, uint32_t line, uint32_t col = 1) const {
    SourceLoc o = sm.origin(SourceLoc{units.at(i), line, col});
    return fs::path(sm.file(o.file).path).filename().string() + ":" + std::to_string(o.line) + ":" + std::to_string(o.col);
  }
  // Diagnostics with the directory taken out of the paths.
  std::string rendered(const std::string& dir) const {
    std::string out = diags.render_all();
    for (size_t p; (p = out.find(dir + "/")) != std::string::npos;) out.erase(p, dir.size() + 1);
    return out;
  }
};

std::unique_ptr<Imported> import(const std::string& path) {
  auto r = std::make_unique<Imported>();
  r->ok = import_twincat(path, r->sm, r->diags, &r->units);
  return r;
}

std::string strip_dir(std::string out, const std::string& dir) {
  for (size_t p; (p = out.find(dir + "/")) != std::string::npos;) out.erase(p, dir.size() + 1);
  return out;
}

const char* kMotor = R"(<?xml version="1.0" encoding="utf-8"?>
<TcPlcObject Version="1.1.0.1" ProductVersion="3.1.4024.12">
  <POU Name="FB_X" Id="{1}" SpecialFunc="None">
    <Declaration><![CDATA[FUNCTION_BLOCK FB_X
VAR
	n : INT;
END_VAR
]]></Declaration>
    <Implementation>
      <ST><![CDATA[n := n + 1;]]></ST>
    </Implementation>
    <Method Name="Twice" Id="{2}">
      <Declaration><![CDATA[METHOD Twice : INT
]]></Declaration>
      <Implementation>
        <ST><![CDATA[Twice := 2 * n;]]></ST>
      </Implementation>
    </Method>
    <Property Name="Count" Id="{3}">
      <Declaration><![CDATA[PROPERTY Count : INT]]></Declaration>
      <Get Name="Get" Id="{4}">
        <Declaration><![CDATA[VAR
END_VAR
]]></Declaration>
        <Implementation>
          <ST><![CDATA[Count := n;]]></ST>
        </Implementation>
      </Get>
      <Set Name="Set" Id="{5}">
        <Declaration><![CDATA[]]></Declaration>
        <Implementation>
          <ST><![CDATA[n := Count;]]></ST>
        </Implementation>
      </Set>
    </Property>
    <Action Name="Reset" Id="{6}">
      <Implementation>
        <ST><![CDATA[n := 0;]]></ST>
      </Implementation>
    </Action>
    <LineIds Name="FB_X">
      <LineId Id="9" Count="0" />
    </LineIds>
  </POU>
</TcPlcObject>
)";

TEST(ImportTwinCat, APouBecomesOneUnitWithItsMembers) {
  Dir d;
  auto r = import(d.write("FB_X.TcPOU", kMotor));
  ASSERT_TRUE(r->ok) << r->diags.render_all();
  ASSERT_EQ(r->units.size(), 1u);
  EXPECT_EQ(r->text(0),
            "FUNCTION_BLOCK FB_X\n"
            "VAR\n"
            "\tn : INT;\n"
            "END_VAR\n"
            "n := n + 1;\n"
            "METHOD Twice : INT\n"
            "Twice := 2 * n;\n"
            "END_METHOD\n"
            "PROPERTY Count : INT\n"
            "GET\n"
            "VAR\n"
            "END_VAR\n"
            "Count := n;\n"
            "END_GET\n"
            "SET\n"
            "n := Count;\n"
            "END_SET\n"
            "END_PROPERTY\n"
            "METHOD Reset\n"
            "n := 0;\n"
            "END_METHOD\n"
            "END_FUNCTION_BLOCK\n");
  // The unit is named as the object inside its file.
  EXPECT_EQ(strip_dir(r->sm.file(r->units[0]).path, d.path), "FB_X.TcPOU/FB_X.st");
}

TEST(ImportTwinCat, CopiedLinesPointIntoTheXmlAndSynthesizedOnesAtTheirElement) {
  Dir d;
  auto r = import(d.write("FB_X.TcPOU", kMotor));
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->origin(0, 1), "FB_X.TcPOU:4:27");       // FUNCTION_BLOCK, after <![CDATA[
  EXPECT_EQ(r->origin(0, 1, 16), "FB_X.TcPOU:4:42");   // FB_X
  EXPECT_EQ(r->origin(0, 3, 2), "FB_X.TcPOU:6:2");     // n, after the tab
  EXPECT_EQ(r->origin(0, 5, 6), "FB_X.TcPOU:10:25");   // the body's second n
  EXPECT_EQ(r->origin(0, 6), "FB_X.TcPOU:13:29");      // METHOD Twice
  EXPECT_EQ(r->origin(0, 8, 5), "FB_X.TcPOU:12:5");    // END_METHOD: <Method>
  EXPECT_EQ(r->origin(0, 10), "FB_X.TcPOU:21:7");      // GET: <Get>
  EXPECT_EQ(r->origin(0, 18), "FB_X.TcPOU:19:5");      // END_PROPERTY: <Property>
  EXPECT_EQ(r->origin(0, 19), "FB_X.TcPOU:36:5");      // METHOD Reset: <Action>
  EXPECT_EQ(r->origin(0, 20, 3), "FB_X.TcPOU:38:24");  // the action's body
  EXPECT_EQ(r->origin(0, 22), "FB_X.TcPOU:3:3");       // END_FUNCTION_BLOCK: <POU>
}

TEST(ImportTwinCat, ATypeErrorInAMethodIsReportedInTheTcPou) {
  Dir d;
  std::string pou = kMotor;
  pou.replace(pou.find("Twice := 2 * n;"), 15, "Twice := 'two';");
  std::string path = d.write("FB_X.TcPOU", pou);
  auto b = build_files({path}, CompileOptions{});
  ASSERT_FALSE(b->ok());
  EXPECT_EQ(strip_dir(b->diags.render_all(), d.path),
            "FB_X.TcPOU:16:22: error[ST203]: cannot convert STRING[3] to INT implicitly in assignment\n"
            "          <ST><![CDATA[Twice := 'two';]]></ST>\n"
            "                       ^\n");
}

TEST(ImportTwinCat, ByteOrderMarkAndCrlfKeepLinesAndColumns) {
  Dir d;
  std::string crlf;
  for (char c : std::string(kMotor)) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  std::string pou = "\xEF\xBB\xBF" + crlf;
  pou.replace(pou.find("Twice := 2 * n;"), 15, "Twice := 'two';");
  std::string path = d.write("FB_X.TcPOU", pou);
  auto b = build_files({path}, CompileOptions{});
  ASSERT_FALSE(b->ok());
  ASSERT_EQ(b->diags.all().size(), 1u) << b->diags.render_all();
  EXPECT_EQ(b->diags.all()[0].loc.line, 16u);
  EXPECT_EQ(b->diags.all()[0].loc.col, 22u);
}

TEST(ImportTwinCat, AnInterfaceHasPrototypesOnly) {
  Dir d;
  auto r = import(d.write("I_Counter.TcIO", R"(<?xml version="1.0" encoding="utf-8"?>
<TcPlcObject Version="1.1.0.1">
  <Itf Name="I_Counter" Id="{1}">
    <Declaration><![CDATA[INTERFACE I_Counter
]]></Declaration>
    <Method Name="Twice" Id="{2}">
      <Declaration><![CDATA[METHOD Twice : INT
VAR_INPUT
	k : INT;
END_VAR
]]></Declaration>
    </Method>
    <Property Name="Count" Id="{3}">
      <Declaration><![CDATA[PROPERTY Count : INT]]></Declaration>
      <Get Name="Get" Id="{4}">
        <Declaration><![CDATA[]]></Declaration>
      </Get>
    </Property>
  </Itf>
</TcPlcObject>
)"));
  ASSERT_TRUE(r->ok) << r->diags.render_all();
  ASSERT_EQ(r->units.size(), 1u);
  EXPECT_EQ(r->text(0),
            "INTERFACE I_Counter\n"
            "METHOD Twice : INT\n"
            "VAR_INPUT\n"
            "\tk : INT;\n"
            "END_VAR\n"
            "END_METHOD\n"
            "PROPERTY Count : INT\n"
            "GET\n"
            "END_GET\n"
            "END_PROPERTY\n"
            "END_INTERFACE\n");
}

TEST(ImportTwinCat, AGvlKeepsItsNameForQualifiedAccess) {
  Dir d;
  std::string gvl = d.write("GVLs/GVL_Plant.TcGVL", R"(<?xml version="1.0" encoding="utf-8"?>
<TcPlcObject Version="1.1.0.1">
  <GVL Name="GVL_Plant" Id="{1}">
    <Declaration><![CDATA[{attribute 'qualified_only'}
VAR_GLOBAL
	nLevel : INT := 7;
END_VAR
]]></Declaration>
  </GVL>
</TcPlcObject>
)");
  std::string dut = d.write("DUTs/E_Mode.TcDUT", R"(<?xml version="1.0" encoding="utf-8"?>
<TcPlcObject Version="1.1.0.1">
  <DUT Name="E_Mode" Id="{2}">
    <Declaration><![CDATA[TYPE E_Mode :
(
	Manual := 1,
	Auto := 2
);
END_TYPE
]]></Declaration>
  </DUT>
</TcPlcObject>
)");
  auto r = import(gvl);
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->text(0), "{attribute 'qualified_only'}\nVAR_GLOBAL\n\tnLevel : INT := 7;\nEND_VAR\n");
  EXPECT_EQ(strip_dir(r->sm.file(r->units[0]).path, d.path), "GVLs/GVL_Plant.TcGVL/GVL_Plant.st");
  std::string prog = d.write("main.st",
                             "PROGRAM P\nVAR m : E_Mode := Auto; n : INT; END_VAR\nn := GVL_Plant.nLevel + 1;\nEND_PROGRAM\n");
  auto built = build_files({gvl, dut, prog}, CompileOptions{});
  EXPECT_TRUE(built->ok()) << built->diags.render_all();
}

TEST(ImportTwinCat, TasksBecomeAConfiguration) {
  Dir d;
  std::string tto = d.write("PlcTask.TcTTO", R"(<?xml version="1.0" encoding="utf-8"?>
<TcPlcObject Version="1.1.0.1">
  <Task Name="PlcTask" Id="{1}">
    <!--CycleTime in micro seconds.-->
    <CycleTime>2500</CycleTime>
    <Priority>20</Priority>
    <PouCall>
      <Name>MAIN</Name>
    </PouCall>
  </Task>
</TcPlcObject>
)");
  auto r = import(tto);
  ASSERT_TRUE(r->ok) << r->diags.render_all();
  ASSERT_EQ(r->units.size(), 1u);
  EXPECT_EQ(r->text(0),
            "CONFIGURATION PlcTask_Config\n"
            "RESOURCE PLC ON PLC\n"
            "TASK PlcTask (INTERVAL := T#2500us, PRIORITY := 20);\n"
            "PROGRAM MAIN WITH PlcTask : MAIN;\n"
            "END_RESOURCE\n"
            "END_CONFIGURATION\n");
  EXPECT_EQ(r->origin(0, 3), "PlcTask.TcTTO:3:3");
  EXPECT_EQ(r->origin(0, 4), "PlcTask.TcTTO:8:7");
}

TEST(ImportTwinCat, ABadCycleTimeIsAnErrorAtItsElement) {
  Dir d;
  auto r = import(d.write("T.TcTTO", "<TcPlcObject>\n  <Task Name=\"T\">\n    <CycleTime>10 ms</CycleTime>\n"
                                     "    <Priority>1</Priority>\n  </Task>\n</TcPlcObject>\n"));
  EXPECT_FALSE(r->ok);
  EXPECT_EQ(r->rendered(d.path),
            "T.TcTTO:3:5: error[ST624]: task 'T': <CycleTime> '10 ms' is not a whole number from 0 to 86400000000\n"
            "      <CycleTime>10 ms</CycleTime>\n"
            "      ^\n");
}

TEST(ImportTwinCat, NotWellFormedXmlIsAnErrorAtPugixmlsPosition) {
  Dir d;
  auto r = import(d.write("Bad.TcPOU", "<TcPlcObject>\n  <POU Name=\"P\">\n  </PUO>\n</TcPlcObject>\n"));
  EXPECT_FALSE(r->ok);
  EXPECT_EQ(r->units.size(), 0u);
  EXPECT_EQ(r->rendered(d.path),
            "Bad.TcPOU:3:5: error[ST620]: not well-formed XML: Start-end tags mismatch\n"
            "    </PUO>\n"
            "      ^\n");
}

TEST(ImportTwinCat, ABodyInLadderIsAnErrorNamingThePou) {
  Dir d;
  auto r = import(d.write("LD.TcPOU", "<TcPlcObject>\n  <POU Name=\"Lamp\">\n"
                                      "    <Declaration><![CDATA[PROGRAM Lamp\n]]></Declaration>\n"
                                      "    <Implementation>\n      <LD></LD>\n    </Implementation>\n  </POU>\n</TcPlcObject>\n"));
  EXPECT_FALSE(r->ok);
  EXPECT_EQ(r->rendered(d.path),
            "LD.TcPOU:6:7: error[ST623]: POU 'Lamp' is written in LD: plcfi reads Structured Text (ST) bodies only\n"
            "        <LD></LD>\n"
            "        ^\n");
}

TEST(ImportTwinCat, AProjectFindsItsFilesIgnoringCaseAndReportsMissingOnes) {
  Dir d;
  d.write("POUs/MAIN.TcPOU", "<TcPlcObject>\n  <POU Name=\"MAIN\">\n"
                             "    <Declaration><![CDATA[PROGRAM MAIN\nVAR n : INT; END_VAR\n]]></Declaration>\n"
                             "    <Implementation><ST><![CDATA[n := n + 1;]]></ST></Implementation>\n  </POU>\n</TcPlcObject>\n");
  std::string proj = d.write("P.plcproj", R"(<?xml version="1.0" encoding="utf-8"?>
<Project xmlns="http://schemas.microsoft.com/developer/msbuild/2003">
  <ItemGroup>
    <Compile Include="pous\Main.TcPOU" />
    <Compile Include="POUs\Gone.TcPOU" />
    <Compile Include="Visu.TcVIS" />
  </ItemGroup>
  <ItemGroup>
    <PlaceholderReference Include="TcUnit" />
  </ItemGroup>
</Project>
)");
  auto r = import(proj);
  EXPECT_FALSE(r->ok);
  ASSERT_EQ(r->units.size(), 1u);
  EXPECT_EQ(strip_dir(r->sm.file(r->units[0]).path, d.path), "POUs/MAIN.TcPOU/MAIN.st");
  EXPECT_EQ(r->rendered(d.path),
            "P.plcproj:5:5: error[ST622]: Compile item 'POUs\\Gone.TcPOU': no file POUs/Gone.TcPOU (not even ignoring case)\n"
            "      <Compile Include=\"POUs\\Gone.TcPOU\" />\n"
            "      ^\n");
}

TEST(ImportTwinCat, TheDemoProjectCompilesWithItsTaskConfiguration) {
  const std::string dir = std::string(PLCFI_SOURCE_DIR) + "/tests/import/twincat/Demo";
  auto r = import(dir + "/Demo.plcproj");
  ASSERT_TRUE(r->ok) << r->diags.render_all();
  ASSERT_EQ(r->units.size(), 8u);
  EXPECT_EQ(r->text(7),
            "CONFIGURATION Demo\n"
            "RESOURCE PLC ON PLC\n"
            "TASK PlcTask (INTERVAL := T#10ms, PRIORITY := 20);\n"
            "PROGRAM MAIN WITH PlcTask : MAIN;\n"
            "END_RESOURCE\n"
            "END_CONFIGURATION\n");
  auto b = build_files({dir + "/Demo.plcproj"}, CompileOptions{});
  EXPECT_TRUE(b->ok()) << b->diags.render_all();
}

// Whatever the bytes, the importer reports and returns: no crash, no exception.
TEST(ImportTwinCat, HostileInputsAreErrorsNotCrashes) {
  Dir d;
  const std::vector<std::string> inputs = {
      "", "\xEF\xBB\xBF", std::string(100, '\0'), "<TcPlcObject/>", "<Other/>", "<TcPlcObject><POU/></TcPlcObject>",
      "<TcPlcObject><POU><Declaration>(* x</Declaration></POU></TcPlcObject>",
      "<TcPlcObject><Task Name='a b'/></TcPlcObject>",
      "<TcPlcObject><Task Name='T'><CycleTime>99999999999999999999999</CycleTime></Task></TcPlcObject>",
      "<TcPlcObject><POU Name='x/../y'><Declaration>FUNCTION_BLOCK F\nMETHOD</Declaration>"
      "<Action Name='A&#10;B'/></POU></TcPlcObject>",
      std::string(5000, '<'),
  };
  for (size_t i = 0; i < inputs.size(); ++i) {
    std::string path = d.write("in" + std::to_string(i) + ".TcPOU", inputs[i]);
    auto r = import(path);
    EXPECT_FALSE(r->ok) << i;
    EXPECT_GT(r->diags.error_count(), 0u) << i;
    auto b = build_files({path}, CompileOptions{});
    EXPECT_FALSE(b->ok()) << i;
  }
}

}  // namespace
}  // namespace plcfi::st
