// The PLCopen XML importer (st/import/plcopen.cpp): snapshots of the ST it generates and
// of its diagnostics, which point at the line and column of the XML file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "engine.hpp"
#include "import/import.hpp"

namespace plcfi::st {
namespace {

// An XML file in the temporary directory, removed at the end of the test.
struct XmlFile {
  explicit XmlFile(const std::string& text) {
    static int serial = 0;
    path = (std::filesystem::temp_directory_path() /
            ("plcfi_plcopen_" + std::to_string(::getpid()) + "_" + std::to_string(serial++) + ".xml"))
               .string();
    std::ofstream(path, std::ios::binary) << text;
  }
  ~XmlFile() { std::filesystem::remove(path); }
  // `text` with the file's path written as X.xml.
  std::string named(std::string text) const {
    for (size_t at; (at = text.find(path)) != std::string::npos;) text.replace(at, path.size(), "X.xml");
    return text;
  }
  std::string path;
};

const std::string kHead = "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
                          "<project xmlns=\"http://www.plcopen.org/xml/tc6_0201\" xmlns:xhtml=\"http://www.w3.org/1999/xhtml\">\n";

std::string project(const std::string& pous, const std::string& rest = "") {
  return kHead + "<types><dataTypes/><pous>\n" + pous + "</pous></types>\n" + rest + "</project>\n";
}

// The importer alone: the generated units' text, in order, and the diagnostics.
struct Imported {
  std::string text;
  std::string diags;
  bool ok = false;
};
Imported import(const XmlFile& f) {
  SourceManager sm;
  DiagEngine diags(sm);
  std::vector<uint32_t> units;
  Imported out;
  out.ok = import_plcopen(f.path, sm, diags, &units);
  for (uint32_t u : units) out.text += "---- " + f.named(sm.file(u).path) + "\n" + sm.file(u).text;
  out.diags = f.named(diags.render_all());
  return out;
}

std::string build_diags(const XmlFile& f, bool* ok = nullptr) {
  auto b = build_files({f.path}, CompileOptions{});
  if (ok) *ok = b->ok();
  std::string out;
  for (const auto& e : b->io_errors) out += e + "\n";
  return f.named(out + b->diags.render_all());
}

TEST(PlcopenImport, StructuredFunctionBlockBecomesSt) {
  XmlFile f(project(R"(<pou name="FB_A" pouType="functionBlock">
  <interface>
    <inputVars retain="true">
      <variable name="In" address="%IX0.1"><type><BOOL/></type></variable>
      <variable name="Limit"><type><INT/></type><initialValue><simpleValue value="10"/></initialValue></variable>
    </inputVars>
    <localVars constant="true">
      <variable name="Buf"><type><array><dimension lower="1" upper="3"/><baseType><string length="4"/></baseType></array></type>
        <initialValue><arrayValue><value repetitionValue="2"><simpleValue value="'a'"/></value><value><simpleValue value="'b'"/></value></arrayValue></initialValue>
      </variable>
    </localVars>
  </interface>
  <body><ST><xhtml:p><![CDATA[IF In THEN
  Limit := Limit + 1;
END_IF;]]></xhtml:p></ST></body>
</pou>
)"));
  Imported r = import(f);
  EXPECT_TRUE(r.ok) << r.diags;
  EXPECT_EQ(r.diags, "");
  EXPECT_EQ(r.text, R"(---- X.xml(FB_A)
FUNCTION_BLOCK FB_A
VAR_INPUT RETAIN
In
AT %IX0.1
:
BOOL
;
Limit
:
INT
:=
10;
END_VAR
VAR CONSTANT
Buf
:
ARRAY [
1 ..
3
] OF
STRING[4]
:=
[
2(
'a'),
'b'
];
END_VAR
IF In THEN
  Limit := Limit + 1;
END_IF;
END_FUNCTION_BLOCK
)");
}

TEST(PlcopenImport, TypesConfigurationAndTaskInterval) {
  XmlFile f(kHead + R"(<types><dataTypes>
<dataType name="E"><baseType><enum><values><value name="A" value="1"/><value name="B"/></values><baseType><INT/></baseType></enum></baseType>
  <initialValue><simpleValue value="B"/></initialValue></dataType>
<dataType name="S"><baseType><struct><variable name="x"><type><derived name="E"/></type></variable></struct></baseType></dataType>
<dataType name="R"><baseType><subrangeUnsigned><range lower="1" upper="9"/><baseType><UINT/></baseType></subrangeUnsigned></baseType></dataType>
</dataTypes><pous/></types>
<instances><configurations><configuration name="C">
  <resource name="Res">
    <task name="T" interval="PT0.05S" priority="2"><pouInstance name="I" typeName="P"/></task>
    <pouInstance name="J" typeName="P"/>
  </resource>
  <globalVars constant="true"><variable name="g"><type><wstring/></type></variable></globalVars>
</configuration></configurations></instances>
</project>
)");
  Imported r = import(f);
  EXPECT_TRUE(r.ok) << r.diags;
  EXPECT_EQ(r.text, R"(---- X.xml(E)
TYPE
E :
(
A
:= 1,
B
)
INT
:=
B;
END_TYPE
---- X.xml(S)
TYPE
S :
STRUCT
x
:
E
;
END_STRUCT
;
END_TYPE
---- X.xml(R)
TYPE
R :
UINT
(1 ..
9)
;
END_TYPE
---- X.xml(C)
CONFIGURATION C
VAR_GLOBAL CONSTANT
g
:
WSTRING
;
END_VAR
RESOURCE Res ON PLC
TASK T (
INTERVAL := T#0.05s
, PRIORITY := 2
);
PROGRAM I WITH T
: P;
PROGRAM J
: P;
END_RESOURCE
END_CONFIGURATION
)");
}

TEST(PlcopenImport, PlainTextDeclarationIsPreferredAndMethodsPropertiesActionsFollow) {
  XmlFile f(project(R"(<pou name="FB_B" pouType="functionBlock">
  <interface>
    <localVars><variable name="ignored"><type><INT/></type></variable></localVars>
    <addData><data name="http://www.3s-software.com/plcopenxml/interfaceasplaintext" handleUnknown="implementation">
      <InterfaceAsPlainText><xhtml xmlns="http://www.w3.org/1999/xhtml">FUNCTION_BLOCK FB_B
VAR
  n : INT;
END_VAR
</xhtml></InterfaceAsPlainText></data></addData>
  </interface>
  <actions><action name="Act"><body><ST><xhtml xmlns="http://www.w3.org/1999/xhtml">n := 0;</xhtml></ST></body></action></actions>
  <body><ST><xhtml xmlns="http://www.w3.org/1999/xhtml">n := n + 1;</xhtml></ST></body>
  <addData>
    <data name="http://www.3s-software.com/plcopenxml/method" handleUnknown="implementation">
      <Method name="Get"><interface><returnType><INT/></returnType></interface>
        <body><ST><xhtml xmlns="http://www.w3.org/1999/xhtml">Get := n;</xhtml></ST></body></Method>
    </data>
    <data name="http://www.3s-software.com/plcopenxml/property" handleUnknown="implementation">
      <Property name="P"><interface><returnType><INT/></returnType></interface>
        <GetAccessor><interface/><body><ST><xhtml xmlns="http://www.w3.org/1999/xhtml">P := n;</xhtml></ST></body></GetAccessor>
        <SetAccessor><interface/><body><ST><xhtml xmlns="http://www.w3.org/1999/xhtml">n := P;</xhtml></ST></body></SetAccessor>
      </Property>
    </data>
  </addData>
</pou>
)"));
  Imported r = import(f);
  EXPECT_TRUE(r.ok) << r.diags;
  EXPECT_EQ(r.text, R"(---- X.xml(FB_B)
FUNCTION_BLOCK FB_B
VAR
  n : INT;
END_VAR
METHOD Get
:
INT
Get := n;
END_METHOD
PROPERTY P
:
INT
GET
P := n;
END_GET
SET
n := P;
END_SET
END_PROPERTY
METHOD Act
n := 0;
END_METHOD
n := n + 1;
END_FUNCTION_BLOCK
)");
  bool ok = false;
  EXPECT_EQ(build_diags(f, &ok), "");
  EXPECT_TRUE(ok);
}

TEST(PlcopenImport, CodesysGlobalVariableListAndPlainTextDataType) {
  XmlFile f(kHead + R"(<types><dataTypes>
<dataType name="S"><baseType><struct/></baseType>
  <addData><data name="http://www.3s-software.com/plcopenxml/interfaceasplaintext" handleUnknown="implementation">
    <InterfaceAsPlainText><xhtml xmlns="http://www.w3.org/1999/xhtml">TYPE S :
STRUCT
  a : INT := 1;
END_STRUCT
END_TYPE
</xhtml></InterfaceAsPlainText></data></addData></dataType>
</dataTypes><pous/></types>
<instances><configurations/></instances>
<addData><data name="http://www.3s-software.com/plcopenxml/globalvars" handleUnknown="implementation">
  <globalVars name="GVL"><variable name="s"><type><derived name="S"/></type></variable></globalVars>
  <globalVars name="GVL2"><addData><data name="http://www.3s-software.com/plcopenxml/interfaceasplaintext" handleUnknown="implementation">
    <InterfaceAsPlainText><xhtml xmlns="http://www.w3.org/1999/xhtml">VAR_GLOBAL
  n : INT := 3;
END_VAR</xhtml></InterfaceAsPlainText></data></addData></globalVars>
</data></addData>
</project>
)");
  Imported r = import(f);
  EXPECT_TRUE(r.ok) << r.diags;
  EXPECT_EQ(r.text, R"(---- X.xml(S)
TYPE S :
STRUCT
  a : INT := 1;
END_STRUCT
END_TYPE
---- X.xml(GVL)
VAR_GLOBAL
s
:
S
;
END_VAR
---- X.xml(GVL2)
VAR_GLOBAL
  n : INT := 3;
END_VAR
)");
  bool ok = false;
  EXPECT_EQ(build_diags(f, &ok), "");
  EXPECT_TRUE(ok);
}

// A type error in an ST body with entities before it on the line: reported at the XML
// line and column of the offending name, with the XML line shown.
TEST(PlcopenImport, ErrorInABodyPointsIntoTheXml) {
  XmlFile f(project(R"(<pou name="Main" pouType="program">
  <interface><localVars><variable name="x"><type><INT/></type></variable></localVars></interface>
  <body><ST><xhtml xmlns="http://www.w3.org/1999/xhtml">x := 1;
IF x &lt;&gt; 2 THEN x := nothing; END_IF;</xhtml></ST></body>
</pou>
)"));
  EXPECT_EQ(build_diags(f), "X.xml:7:27: error[ST200]: unknown identifier 'nothing'\n"
                            "  IF x &lt;&gt; 2 THEN x := nothing; END_IF;</xhtml></ST></body>\n"
                            "                            ^\n");
}

TEST(PlcopenImport, ErrorInAnAttributeValuePointsAtIt) {
  XmlFile f(project(R"(<pou name="Main" pouType="program">
  <interface><localVars><variable name="x"><type><derived name="NoSuchType"/></type>
    <initialValue><simpleValue value="1"/></initialValue></variable></localVars></interface>
</pou>
)"));
  EXPECT_EQ(build_diags(f), "X.xml:5:65: error[ST201]: unknown type 'NoSuchType'\n"
                            "    <interface><localVars><variable name=\"x\"><type><derived name=\"NoSuchType\"/></type>\n"
                            "                                                                  ^\n");
}

// A Ladder Diagram becomes ST: each contact and coil a BOOL of its own (the value at its
// right side), parallel connections ORed, an edge an R_TRIG instance, in the order of the
// connections (the coil of the first rung is written after the contacts that feed it,
// although the XML lists it first).
TEST(PlcopenImport, LadderDiagramBecomesSt) {
  XmlFile f(project(R"(<pou name="Rung" pouType="functionBlock">
  <interface/>
  <body>
    <LD>
      <leftPowerRail localId="1"><connectionPointOut/></leftPowerRail>
      <coil localId="4" storage="set"><connectionPointIn><connection refLocalId="3"/></connectionPointIn><variable>q</variable></coil>
      <contact localId="2"><connectionPointIn><connection refLocalId="1"/></connectionPointIn><variable>a</variable></contact>
      <contact localId="5" edge="rising"><connectionPointIn><connection refLocalId="1"/></connectionPointIn><variable>b</variable></contact>
      <contact localId="3" negated="true"><connectionPointIn><connection refLocalId="2"/><connection refLocalId="5"/></connectionPointIn><variable>c</variable></contact>
      <rightPowerRail localId="6"><connectionPointIn><connection refLocalId="4"/></connectionPointIn></rightPowerRail>
    </LD>
  </body>
</pou>
)"));
  Imported r = import(f);
  EXPECT_TRUE(r.ok) << r.diags;
  EXPECT_EQ(r.text,
            "---- X.xml(Rung)\n"
            "FUNCTION_BLOCK Rung\n"
            "VAR_TEMP\n"
            "  _ld2 : BOOL;\n"
            "  _ld5 : BOOL;\n"
            "  _ld3 : BOOL;\n"
            "  _ld4 : BOOL;\n"
            "END_VAR\n"
            "VAR\n"
            "  _lde5 : R_TRIG;\n"
            "END_VAR\n"
            "_ld2 := TRUE AND a;\n"
            "_lde5(CLK := b);\n"
            "_ld5 := TRUE AND _lde5.Q;\n"
            "_ld3 := (_ld2 OR _ld5) AND NOT c;\n"
            "_ld4 := _ld3;\n"
            "IF _ld4 THEN q := TRUE; END_IF;\n"
            "END_FUNCTION_BLOCK\n");
}

// A continuation without its connector, and function boxes whose value is used twice at
// every level (the ST written for it would double at every level): errors, not a crash
// or a run out of memory.
TEST(PlcopenImport, LadderDiagramLimits) {
  XmlFile orphan(project(R"(<pou name="Orphan" pouType="functionBlock">
  <interface/>
  <body><LD>
    <continuation localId="1" name="nowhere"><connectionPointOut/></continuation>
    <coil localId="2"><connectionPointIn><connection refLocalId="1"/></connectionPointIn><variable>q</variable></coil>
  </LD></body>
</pou>
)"));
  Imported r = import(orphan);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.diags.find("<continuation name=\"nowhere\"> has no <connector> of that name"), std::string::npos) << r.diags;

  std::string boxes = "<inVariable localId=\"1\"><connectionPointOut/><expression>x</expression></inVariable>\n";
  for (int k = 2; k <= 40; ++k)
    boxes += "<block localId=\"" + std::to_string(k) + "\" typeName=\"ADD\"><inputVariables>"
             "<variable formalParameter=\"IN1\"><connectionPointIn><connection refLocalId=\"" + std::to_string(k - 1) +
             "\"/></connectionPointIn></variable><variable formalParameter=\"IN2\"><connectionPointIn><connection refLocalId=\"" +
             std::to_string(k - 1) + "\"/></connectionPointIn></variable></inputVariables>"
             "<outputVariables><variable formalParameter=\"OUT\"><connectionPointOut/></variable></outputVariables></block>\n";
  XmlFile doubling(project("<pou name=\"Doubling\" pouType=\"functionBlock\">\n<interface/>\n<body><LD>\n" + boxes +
                           "</LD></body>\n</pou>\n"));
  r = import(doubling);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.diags.find("function boxes nest too deep"), std::string::npos) << r.diags;
}

TEST(PlcopenImport, GraphicalBodyIsOneErrorAtTheBody) {
  XmlFile f(project(R"(<pou name="Conveyor" pouType="program">
  <interface/>
  <actions><action name="Jog">
  <body>
    <FBD><inVariable localId="1"/></FBD>
  </body>
  </action></actions>
  <body><ST>;</ST></body>
</pou>
<pou name="Uses" pouType="program">
  <interface><localVars><variable name="c"><type><derived name="Conveyor"/></type></variable></localVars></interface>
</pou>
)"));
  bool ok = true;
  EXPECT_EQ(build_diags(f, &ok), "X.xml:7:3: error[ST604]: action 'Jog' of POU 'Conveyor' has an FBD body: plcfi reads "
                                 "LD, FBD and SFC bodies of POUs, not of methods, actions or property accessors (write this "
                                 "one in ST or IL)\n"
                                 "    <body>\n"
                                 "    ^\n");
  EXPECT_FALSE(ok);
}

TEST(PlcopenImport, NotWellFormedXmlAtPugixmlsPosition) {
  XmlFile f(kHead + "<types>\n  <pous>\n  </types>\n</project>\n");
  Imported r = import(f);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.text, "");
  EXPECT_EQ(r.diags, "X.xml:5:5: error[ST601]: not well-formed XML: Start-end tags mismatch\n"
                     "    </types>\n"
                     "      ^\n");
}

TEST(PlcopenImport, MissingAttributesAndBadNamesAtTheirElement) {
  XmlFile f(project(R"(<pou pouType="program"><interface/></pou>
<pou name="A" ><interface/></pou>
<pou name="B C" pouType="program"><interface/></pou>
<pou name="D" pouType="program"><interface><localVars><variable name="v"/></localVars></interface></pou>
)", R"(<instances><configurations><configuration name="Cfg"><resource name="R">
<task name="T" interval="10 ms"/></resource></configuration></configurations></instances>
)"));
  Imported r = import(f);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.diags, R"(X.xml:4:1: error[ST603]: <pou> has no 'name' attribute
  <pou pouType="program"><interface/></pou>
  ^
X.xml:5:1: error[ST603]: POU 'A' has no 'pouType' attribute
  <pou name="A" ><interface/></pou>
  ^
X.xml:6:1: error[ST605]: <pou>: 'B C' is not an IEC identifier
  <pou name="B C" pouType="program"><interface/></pou>
  ^
X.xml:7:55: error[ST603]: POU 'D', variable 'v' has no <type>
  <pou name="D" pouType="program"><interface><localVars><variable name="v"/></localVars></interface></pou>
                                                        ^
X.xml:10:1: error[ST605]: task 'T': interval '10 ms' is not a duration (PT0.01S or T#10ms)
  <task name="T" interval="10 ms"/></resource></configuration></configurations></instances>
  ^
)");
}

TEST(PlcopenImport, NotAProject) {
  XmlFile f("<?xml version=\"1.0\"?>\n<TcPlcObject/>\n");
  EXPECT_EQ(import(f).diags, "X.xml:2:1: error[ST602]: not a PLCopen XML project: the root element is <TcPlcObject>, expected <project>\n"
                             "  <TcPlcObject/>\n"
                             "  ^\n");
}

TEST(PlcopenImport, DeepTypesEndInAnErrorNotACrash) {
  std::string deep;
  for (int i = 0; i < 5000; ++i) deep += "<array><dimension lower=\"0\" upper=\"1\"/><baseType>";
  deep += "<INT/>";
  for (int i = 0; i < 5000; ++i) deep += "</baseType></array>";
  XmlFile f(project("<pou name=\"P\" pouType=\"program\"><interface><localVars><variable name=\"v\"><type>" + deep +
                    "</type></variable></localVars></interface></pou>\n"));
  Imported r = import(f);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.diags.find("error[ST605]: POU 'P', variable 'v': types nested too deep (more than 64)"), std::string::npos)
      << r.diags.substr(0, 300);
}

TEST(PlcopenImport, UnreadableFileIsAnIoError) {
  auto b = build_files({"/nonexistent-dir/p.xml"}, CompileOptions{});
  ASSERT_EQ(b->io_errors.size(), 1u);
  EXPECT_EQ(b->io_errors[0], "/nonexistent-dir/p.xml: cannot open (No such file or directory)");
}

}  // namespace
}  // namespace plcfi::st
