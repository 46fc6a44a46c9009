// The TcUnit unit-test framework, written in ST from its public API (names and
// parameters) and compiled with an application whose sources use FB_TestSuite.
//
// How the parts meet:
// - A test suite is a FUNCTION_BLOCK that EXTENDS FB_TestSuite; its body calls its test
//   methods, each of which calls TEST('name') (or TEST_ORDERED), asserts, and
//   TEST_FINISHED() when done (possibly many cycles later).
// - RUN() (or RUN_IN_SEQUENCE()), called from the user's test program, counts its calls in
//   _TcUnitRun/_TcUnitMode; plcfi's TcUnit runner (testing/tcunit.cpp) then calls the body
//   of every suite instance once per cycle until all tests finished or the time-out.
// - The library keeps no bookkeeping: each call fills the suite's mailbox and hands it to
//   the runner through __TCUNIT (stdlib/tcunit_abi.hpp), which applies TcUnit's rules.
//   An assertion computes its verdict and TcUnit's texts of EXP and ACT here, in ST.
// - The compiler lowers AssertEquals (ANY) to AssertEquals_<type of Actual>, and
//   AssertArray*Equals_<T> to a comparison of the two arrays (of any bounds) whose record
//   arrives in Expecteds; it fills the hidden input _tcuAt of every Assert method with the
//   call's location, so a failure points at the assertion.
//
// FB_ASSERT (stdlib/fb_assert.cpp) shares the table of elementary types and their texts
// (stdlib/assert_lib.hpp).
#include <cctype>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "assert_lib.hpp"
#include "codegen/compiler.hpp"

namespace plcfi::st {

namespace {

using namespace assert_lib;

// Element types of AssertArrayEquals_<T>.
// TcUnit has these 1-dimensional ones, and 2- and 3-dimensional ones of REAL and LREAL.
const char* const kArrayTypes[] = {"BOOL", "BYTE", "WORD", "DWORD", "LWORD", "SINT", "INT", "DINT", "LINT",
                                   "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL"};


std::string assert_equals(const Elementary& e) {
  if (std::string(e.name) == "WSTRING")  // TcUnit's words; the values tell assertions apart
    return R"ST(
METHOD AssertEquals_WSTRING
VAR_INPUT
  Expected : WSTRING(255);
  Actual : WSTRING(255);
  Message : STRING(255);
  _tcuAt : LINT;
END_VAR
IF _tcuActive() THEN
  _tcuReportKeyed(Expected = Actual, 'Not possible to print EXP unicode WSTRING value',
                  'Not possible to print ACT unicode WSTRING value', Message, 'WSTRING', _tcuAt,
                  CONCAT(CONCAT(WSTRING_TO_STRING(Expected), '$R'), WSTRING_TO_STRING(Actual)));
END_IF;
END_METHOD
)ST";
  std::string text = R"ST(
METHOD AssertEquals_@N
VAR_INPUT
  Expected : @T;
  Actual : @T;
@D  Message : STRING(255);
  _tcuAt : LINT;
END_VAR
IF _tcuActive() THEN
  _tcuReport(@CMP, @E, @A, Message, '@N', _tcuAt);
END_IF;
END_METHOD
)ST";
  text = replace_all(text, "@D", e.delta ? std::string("  Delta : ") + e.type + ";\n" : "");
  text = replace_all(text, "@CMP", e.delta ? "ABS(Expected - Actual) <= Delta" : "Expected = Actual");
  text = replace_all(text, "@E", replace_all(e.text, "@", "Expected"));
  text = replace_all(text, "@A", replace_all(e.text, "@", "Actual"));
  text = replace_all(text, "@N", e.name);
  return replace_all(text, "@T", e.type);
}

// AssertArray<M>Equals_<N>: the compiler compares the arrays (vm: array_difference, in
// TcUnit's style) and passes its record (tcunit_abi::kSep-separated) in Expecteds.
std::string assert_array_equals(const std::string& dims, const std::string& name) {
  bool delta = name == "REAL" || name == "LREAL";
  std::string text = R"ST(
METHOD AssertArray@MEquals_@N
VAR_INPUT
  Expecteds : STRING(255);  (* the comparison's record *)
  Actuals : BOOL;
@D  Message : STRING(255);
  _tcuAt : LINT;
END_VAR
IF NOT _tcuActive() THEN
  RETURN;
END_IF;
_tcuExp := Expecteds;
_tcuMsg := Message;
_tcuType := 'Array@T_@N';
_tcuLoc := _tcuAt;
__TCUNIT(7, ADR(THIS^));
END_METHOD
)ST";
  text = replace_all(text, "@D", delta ? "  Delta : " + name + ";\n" : "");
  text = replace_all(text, "@M", dims);
  text = replace_all(text, "@T", dims == "2d" ? "2D" : dims == "3d" ? "3D" : "");
  return replace_all(text, "@N", name);
}


// WRITE_PROTECTED_<T>(Ptr, Value): a test writes a variable its program cannot (an input
// AT %I*), through its address.
std::string write_protected(const Elementary& e) {
  std::string text = R"ST(
FUNCTION WRITE_PROTECTED_@N : BOOL
VAR_INPUT Ptr : POINTER TO @T; Value : @T; END_VAR
Ptr^ := Value;
END_FUNCTION
)ST";
  text = replace_all(text, "@N", e.name);
  // TcUnit's strings here are of the default length (STRING is STRING(80)), as the inputs
  // they write are: a longer type would write past them.
  const std::string n = e.name;
  return replace_all(text, "@T", n == "STRING" || n == "WSTRING" ? n : e.type);
}

std::string build_tcunit() {
  std::string text = hex_function("_tcuHex") + R"ST(
VAR_GLOBAL
  _TcUnitRun : DINT;   (* calls of RUN / RUN_IN_SEQUENCE since the runner last looked *)
  _TcUnitMode : INT;   (* 1: RUN (suites side by side), 2: RUN_IN_SEQUENCE *)
  _TcUnitPause : TIME; (* RUN_IN_SEQUENCE's TimeBetweenTestSuitesExecution *)
END_VAR

FUNCTION RUN : BOOL
_TcUnitRun := _TcUnitRun + 1;
_TcUnitMode := 1;
RUN := TRUE;
END_FUNCTION

(* TcUnit's pause between one suite's end and the next one's start. *)
FUNCTION RUN_IN_SEQUENCE : BOOL
VAR_INPUT TimeBetweenTestSuitesExecution : TIME := T#0MS; END_VAR
_TcUnitRun := _TcUnitRun + 1;
_TcUnitPause := TimeBetweenTestSuitesExecution;
_TcUnitMode := 2;
RUN_IN_SEQUENCE := TRUE;
END_FUNCTION

(* A message in TcUnit's log, in order with its own (plcfi prints both). *)
FUNCTION TCUNIT_ADSLOGSTR : DINT
VAR_INPUT msgCtrlMask : DWORD; msgFmtStr : STRING(255); strArg : STRING(255); END_VAR
TCUNIT_ADSLOGSTR := __TCUNIT_LOG(msgCtrlMask, msgFmtStr, strArg);
END_FUNCTION

(* TcUnit's REAL and LREAL texts: the shortest that reads back, with a decimal point
   (-23.0, 0.0, 1234.5), as TcUnit prints them. *)
FUNCTION _tcuReal : STRING(40)
VAR_INPUT text : STRING(40); END_VAR
_tcuReal := text;
IF FIND(text, '.') = 0 AND FIND(text, 'E') = 0 AND FIND(text, 'e') = 0 AND FIND(text, 'N') = 0 AND FIND(text, 'n') = 0 THEN
  _tcuReal := CONCAT(text, '.0');
END_IF;
END_FUNCTION

FUNCTION_BLOCK FB_TestSuite
VAR
  (* The mailbox the runner reads at each __TCUNIT call (stdlib/tcunit_abi.hpp). *)
  _tcuOk : BOOL;
  _tcuExp : STRING(255);
  _tcuAct : STRING(255);
  _tcuMsg : STRING(255);
  _tcuKey : STRING(255);
  _tcuType : STRING(40);
  _tcuName : STRING(255);
  _tcuLoc : LINT;
END_VAR

METHOD PRIVATE _tcuActive : BOOL
_tcuActive := __TCUNIT(0, ADR(THIS^)) <> 0;
END_METHOD

METHOD PRIVATE _tcuReport
VAR_INPUT Ok : BOOL; Exp : STRING(255); Act : STRING(255); Msg : STRING(255); Typ : STRING(40); Loc : LINT; END_VAR
_tcuOk := Ok;
_tcuExp := Exp;
_tcuAct := Act;
_tcuMsg := Msg;
_tcuKey := '';
_tcuType := Typ;
_tcuLoc := Loc;
__TCUNIT(6, ADR(THIS^));
END_METHOD

METHOD PRIVATE _tcuReportKeyed
VAR_INPUT Ok : BOOL; Exp : STRING(255); Act : STRING(255); Msg : STRING(255); Typ : STRING(40); Loc : LINT; Key : STRING(255); END_VAR
_tcuOk := Ok;
_tcuExp := Exp;
_tcuAct := Act;
_tcuMsg := Msg;
_tcuKey := Key;
_tcuType := Typ;
_tcuLoc := Loc;
__TCUNIT(6, ADR(THIS^));
END_METHOD

METHOD TEST
VAR_INPUT TestName : STRING(255); END_VAR
_tcuName := TestName;
__TCUNIT(1, ADR(THIS^));
END_METHOD

(* TRUE when it is this test's turn: every ordered test registered before it finished. *)
METHOD TEST_ORDERED : BOOL
VAR_INPUT TestName : STRING(255); END_VAR
_tcuName := TestName;
TEST_ORDERED := __TCUNIT(2, ADR(THIS^)) <> 0;
END_METHOD

METHOD TEST_FINISHED : BOOL
TEST_FINISHED := __TCUNIT(3, ADR(THIS^)) <> 0;
END_METHOD

METHOD TEST_FINISHED_NAMED : BOOL
VAR_INPUT TestName : STRING(255); END_VAR
_tcuName := TestName;
TEST_FINISHED_NAMED := __TCUNIT(4, ADR(THIS^)) <> 0;
END_METHOD

METHOD IS_TEST_FINISHED : BOOL
VAR_INPUT TestName : STRING(255); END_VAR
_tcuName := TestName;
IS_TEST_FINISHED := __TCUNIT(5, ADR(THIS^)) <> 0;
END_METHOD

METHOD AssertTrue
VAR_INPUT Condition : BOOL; Message : STRING(255); _tcuAt : LINT; END_VAR
IF _tcuActive() THEN
  _tcuReport(Condition, 'TRUE', BOOL_TO_STRING(Condition), Message, 'BOOL', _tcuAt);
END_IF;
END_METHOD

METHOD AssertFalse
VAR_INPUT Condition : BOOL; Message : STRING(255); _tcuAt : LINT; END_VAR
IF _tcuActive() THEN
  _tcuReport(NOT Condition, 'FALSE', BOOL_TO_STRING(Condition), Message, 'BOOL', _tcuAt);
END_IF;
END_METHOD

(* AssertEquals (ANY): the compiler calls AssertEquals_<type> when both are of one
   elementary type; two different types end here, with TcUnit's names of their type
   classes in Expected and Actual. *)
METHOD AssertEquals
VAR_INPUT Expected : STRING(255); Actual : STRING(255); Message : STRING(255); _tcuAt : LINT; END_VAR
IF _tcuActive() THEN
  _tcuReport(FALSE, CONCAT(CONCAT('(Type class = ', Expected), ')'), CONCAT(CONCAT('(Type class = ', Actual), ')'),
             Message, 'ANY', _tcuAt);
END_IF;
END_METHOD

(* AssertEquals (ANY) of two STRINGs: TcUnit compares their lengths first. *)
METHOD _tcuAnyEquals_STRING
VAR_INPUT Expected : STRING(255); Actual : STRING(255); Message : STRING(255); _tcuAt : LINT; END_VAR
IF NOT _tcuActive() THEN
  RETURN;
END_IF;
IF LEN(Expected) <> LEN(Actual) THEN
  _tcuReport(FALSE, CONCAT(CONCAT('(Data size (LEN) = ', INT_TO_STRING(LEN(Expected))), ')'),
             CONCAT(CONCAT('(Data size (LEN) = ', INT_TO_STRING(LEN(Actual))), ')'), Message, 'ANY', _tcuAt);
ELSE
  _tcuReport(Expected = Actual, Expected, Actual, Message, 'STRING', _tcuAt);
END_IF;
END_METHOD

METHOD _tcuAnyEquals_WSTRING
VAR_INPUT Expected : WSTRING(255); Actual : WSTRING(255); Message : STRING(255); _tcuAt : LINT; END_VAR
IF NOT _tcuActive() THEN
  RETURN;
END_IF;
(* WLEN: the UTF-16 code units of a WSTRING, as LEN counts them on one. *)
IF LEN(Expected) <> LEN(Actual) THEN
  _tcuReport(FALSE, CONCAT(CONCAT('(Data size (WLEN) = ', INT_TO_STRING(LEN(Expected))), ')'),
             CONCAT(CONCAT('(Data size (WLEN) = ', INT_TO_STRING(LEN(Actual))), ')'), Message, 'ANY', _tcuAt);
ELSE
  AssertEquals_WSTRING(Expected, Actual, Message, _tcuAt);
END_IF;
END_METHOD
)ST";
  for (const auto& e : elementary()) text += assert_equals(e);
  for (const char* t : kArrayTypes) text += assert_array_equals("", t);
  for (const char* dims : {"2d", "3d"})
    for (const char* t : {"REAL", "LREAL"}) text += assert_array_equals(dims, t);
  text += "\nEND_FUNCTION_BLOCK\n";
  for (const auto& e : elementary()) text += write_protected(e);
  return text;
}

}  // namespace

namespace {

// GVL_Param_TcUnit: TcUnit's parameters, their types and defaults (ST literals).
struct Param {
  const char* name;
  char kind;  // U: UINT, D: UDINT, B: BOOL, S: STRING, T: TIME
  const char* value;
};
const Param kParams[] = {
    {"MaxNumberOfTestSuites", 'U', "1000"},
    {"MaxNumberOfTestsForEachTestSuite", 'U', "100"},
    {"MaxNumberOfAssertsForEachTestSuite", 'U', "1000"},
    {"LogExtendedResults", 'B', "TRUE"},
    {"xUnitEnablePublish", 'B', "FALSE"},
    {"xUnitBufferSize", 'D', "65535"},
    {"xUnitFilePath", 'S', "'%TC_BOOTPRJPATH%tcunit_xunit_testresults.xml'"},
    {"AdsLogMessageFifoRingBufferSize", 'U', "2000"},
    {"TimeBetweenTestSuitesExecution", 'T', "T#0MS"},
};

const Param* find_param(const std::string& key) {
  for (const auto& p : kParams)
    if (iequals(p.name, key)) return &p;
  return nullptr;
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The value's ST literal (its text checked by tcunit_param_error).
std::string literal(const Param& p, const std::string& v) {
  switch (p.kind) {
    case 'B': return upper(v) == "TRUE" || v == "1" ? "TRUE" : "FALSE";
    case 'S': {
      std::string out = "'";
      for (char c : v) out += c == '\'' ? std::string("$'") : c == '$' ? std::string("$$") : std::string(1, c);
      return out + "'";
    }
    default: return v;
  }
}

}  // namespace

std::string tcunit_param_error(const std::string& key, const std::string& value) {
  const Param* p = find_param(key);
  if (!p) {
    std::string names;
    for (const auto& q : kParams) names += (names.empty() ? "" : ", ") + std::string(q.name);
    return "TcUnit has no parameter '" + key + "' in GVL_Param_TcUnit (it has " + names + ")";
  }
  auto bad = [&](const char* what) { return "TcUnit's parameter " + std::string(p->name) + " takes " + what + ", not '" + value + "'"; };
  switch (p->kind) {
    case 'U':
    case 'D': {
      if (value.empty() || value.size() > 10 || value.find_first_not_of("0123456789") != std::string::npos) return bad("a whole number");
      const uint64_t n = std::stoull(value);
      if (n == 0 || n > (p->kind == 'U' ? 65535u : 4294967295u)) return bad(p->kind == 'U' ? "a number from 1 to 65535" : "a number from 1 to 4294967295");
      return "";
    }
    case 'B': {
      const std::string u = upper(value);
      return u == "TRUE" || u == "FALSE" || u == "1" || u == "0" ? "" : bad("TRUE or FALSE");
    }
    case 'T': {
      const std::string u = upper(value);
      const size_t hash = u.find('#');
      const std::string prefix = hash == std::string::npos ? "" : u.substr(0, hash);
      if ((prefix != "T" && prefix != "TIME") || hash + 1 >= u.size() ||
          u.find_first_not_of("0123456789DHMSU_.", hash + 1) != std::string::npos)
        return bad("a TIME literal (T#500MS)");
      return "";
    }
    default: return value.size() > 255 ? bad("a text of at most 255 characters") : "";
  }
}

std::string tcunit_params_source(const std::vector<std::pair<std::string, std::string>>& values) {
  // The runner reads the maximum counts; the xUnit file is written with --xunit FILE (or
  // where xUnitFilePath says, when a project enables xUnitEnablePublish); messages are
  // printed as they come (no ADS queue).
  std::string text = "{attribute 'qualified_only'}\nVAR_GLOBAL CONSTANT\n";
  for (const auto& p : kParams) {
    std::string v = p.value;
    for (const auto& [key, value] : values)  // the last setting wins
      if (iequals(key, p.name)) v = literal(p, value);
    static const char* const types[] = {"UINT", "UDINT", "BOOL", "STRING(255)", "TIME"};
    const char* type = p.kind == 'U' ? types[0] : p.kind == 'D' ? types[1] : p.kind == 'B' ? types[2] : p.kind == 'S' ? types[3] : types[4];
    text += "  " + std::string(p.name) + " : " + type + " := " + v + ";\n";
  }
  return text + "END_VAR\n";
}

const char* tcunit_source() {
  static const std::string text = build_tcunit();
  return text.c_str();
}

}  // namespace plcfi::st
