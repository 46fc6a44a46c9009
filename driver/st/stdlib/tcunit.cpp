// The TcUnit unit-test framework, written in ST from its public API (names and
// parameters) and compiled with an application whose sources use FB_TestSuite.
//
// How the parts meet:
// - A test suite is a FUNCTION_BLOCK that EXTENDS FB_TestSuite; its body calls its test
//   methods, each of which calls TEST('name') (or TEST_ORDERED), asserts, and
//   TEST_FINISHED() when done (possibly many cycles later).
// - RUN() (or RUN_IN_SEQUENCE()), called from the user's test program, counts its calls in
//   _TcUnitRun/_TcUnitMode; plcfi's TcUnit runner (runtime/tcunit.cpp) then calls the body
//   of every suite instance once per cycle, after raising the suite's _tcuCycle, until all
//   tests finished or the time-out, and reads the results from the _tcu* variables.
// - The compiler lowers AssertEquals (ANY) to AssertEquals_<type of Actual>, and
//   AssertArray*Equals_<T> to a comparison of the two arrays whose finding (a message, or
//   '' when equal) arrives in Expecteds; it fills the hidden input _tcuAt of every Assert
//   method with the call's location, so a failure points at the assertion.
// TcUnit's semantics: a test fails on its first failed assertion (later ones are not
// reported), assertions after TEST_FINISHED are ignored, a name used by two TESTs in one
// cycle of a suite is reported.
//
// The same file builds FB_ASSERT, the older assertion-FB style of TwinCAT unit tests (see
// fb_assert_source below): it shares the table of elementary types and their texts.
#include <string>
#include <vector>

#include "codegen/compiler.hpp"

namespace plcfi::st {

namespace {

struct Elementary {
  const char* name;     // as in AssertEquals_<name>
  const char* type;     // the ST type
  const char* text;     // ST expression of type STRING for the value @ (Expected/Actual)
  bool delta = false;   // REAL/LREAL: compared within Delta
};

const std::vector<Elementary>& elementary() {
  static const std::vector<Elementary> v = {
      {"BOOL", "BOOL", "BOOL_TO_STRING(@)"},
      {"BYTE", "BYTE", "_tcuHex(BYTE_TO_LWORD(@), 2)"},
      {"WORD", "WORD", "_tcuHex(WORD_TO_LWORD(@), 4)"},
      {"DWORD", "DWORD", "_tcuHex(DWORD_TO_LWORD(@), 8)"},
      {"LWORD", "LWORD", "_tcuHex(@, 16)"},
      {"SINT", "SINT", "SINT_TO_STRING(@)"},
      {"INT", "INT", "INT_TO_STRING(@)"},
      {"DINT", "DINT", "DINT_TO_STRING(@)"},
      {"LINT", "LINT", "LINT_TO_STRING(@)"},
      {"USINT", "USINT", "USINT_TO_STRING(@)"},
      {"UINT", "UINT", "UINT_TO_STRING(@)"},
      {"UDINT", "UDINT", "UDINT_TO_STRING(@)"},
      {"ULINT", "ULINT", "ULINT_TO_STRING(@)"},
      {"REAL", "REAL", "REAL_TO_STRING(@)", true},
      {"LREAL", "LREAL", "LREAL_TO_STRING(@)", true},
      {"TIME", "TIME", "TIME_TO_STRING(@)"},
      {"LTIME", "LTIME", "LTIME_TO_STRING(@)"},
      {"DATE", "DATE", "DATE_TO_STRING(@)"},
      {"TIME_OF_DAY", "TIME_OF_DAY", "TOD_TO_STRING(@)"},
      {"DATE_AND_TIME", "DATE_AND_TIME", "DT_TO_STRING(@)"},
      {"STRING", "STRING(255)", "@"},
      {"WSTRING", "WSTRING(255)", "WSTRING_TO_STRING(@)"},
  };
  return v;
}

// Element types of AssertArrayEquals_<T> (and the 2-d and 3-d forms).
const char* const kArrayTypes[] = {"BOOL", "BYTE", "WORD", "DWORD", "LWORD", "SINT", "INT", "DINT", "LINT",
                                   "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL", "STRING"};

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size())) s.replace(p, from.size(), to);
  return s;
}

std::string assert_equals(const Elementary& e) {
  std::string text = R"ST(
METHOD AssertEquals_@N
VAR_INPUT
  Expected : @T;
  Actual : @T;
@D  Message : STRING(255);
  _tcuAt : LINT;
END_VAR
IF @CMP THEN
  _tcuFail(CONCAT(CONCAT('EXP: ', @E), CONCAT(', ACT: ', @A)), Message, _tcuAt);
END_IF;
END_METHOD
)ST";
  text = replace_all(text, "@D", e.delta ? std::string("  Delta : ") + e.type + ";\n" : "");
  text = replace_all(text, "@CMP", e.delta ? "ABS(Expected - Actual) > Delta" : "Expected <> Actual");
  text = replace_all(text, "@E", replace_all(e.text, "@", "Expected"));
  text = replace_all(text, "@A", replace_all(e.text, "@", "Actual"));
  text = replace_all(text, "@N", e.name);
  return replace_all(text, "@T", e.type);
}

// The compiler compares the arrays (vm: array_difference) and passes what it found.
std::string assert_array_equals(const std::string& dims, const std::string& name) {
  bool delta = name == "REAL" || name == "LREAL";
  std::string text = R"ST(
METHOD AssertArray@MEquals_@N
VAR_INPUT
  Expecteds : STRING(255);  (* the difference found ('' when the arrays are equal) *)
  Actuals : BOOL;
@D  Message : STRING(255);
  _tcuAt : LINT;
END_VAR
IF Expecteds <> '' THEN
  _tcuFail(Expecteds, Message, _tcuAt);
END_IF;
END_METHOD
)ST";
  text = replace_all(text, "@D", delta ? "  Delta : " + name + ";\n" : "");
  text = replace_all(text, "@M", dims);
  return replace_all(text, "@N", name);
}

// FUNCTION <name> : the hexadecimal text of a bit string, as TcUnit shows it (0x0A).
std::string hex_function(const std::string& name) {
  std::string text = R"ST(
FUNCTION @F : STRING(20)
VAR_INPUT v : LWORD; digits : INT; END_VAR
VAR i : INT; s : STRING(20); END_VAR
s := '';
FOR i := 1 TO digits DO
  s := CONCAT(MID('0123456789ABCDEF', 1, LWORD_TO_INT(v AND 16#F) + 1), s);
  v := SHR(v, 4);
END_FOR;
@F := CONCAT('0x', s);
END_FUNCTION
)ST";
  return replace_all(text, "@F", name);
}

std::string build_tcunit() {
  std::string text = hex_function("_tcuHex") + R"ST(
VAR_GLOBAL
  _TcUnitRun : DINT;   (* calls of RUN / RUN_IN_SEQUENCE since the runner last looked *)
  _TcUnitMode : INT;   (* 1: RUN (suites side by side), 2: RUN_IN_SEQUENCE *)
END_VAR

FUNCTION RUN : BOOL
_TcUnitRun := _TcUnitRun + 1;
_TcUnitMode := 1;
RUN := TRUE;
END_FUNCTION

FUNCTION RUN_IN_SEQUENCE : BOOL
_TcUnitRun := _TcUnitRun + 1;
_TcUnitMode := 2;
RUN_IN_SEQUENCE := TRUE;
END_FUNCTION


FUNCTION_BLOCK FB_TestSuite
VAR
  _tcuCycle : DINT;      (* raised by the runner before each call of the body *)
  _tcuCount : INT;       (* tests registered *)
  _tcuCurrent : INT;     (* the test assertions count for; 0: none *)
  _tcuOverflow : BOOL;   (* a TEST beyond the 100 a suite holds *)
  _tcuName : ARRAY[1..100] OF STRING(255);
  _tcuOrdered : ARRAY[1..100] OF BOOL;
  _tcuSeen : ARRAY[1..100] OF DINT;      (* the cycle its TEST last ran in *)
  _tcuFinished : ARRAY[1..100] OF BOOL;
  _tcuFailed : ARRAY[1..100] OF BOOL;
  _tcuMessage : ARRAY[1..100] OF STRING(255);
  _tcuWhere : ARRAY[1..100] OF LINT;     (* the failed assertion's location *)
END_VAR

METHOD PRIVATE _tcuSelect : INT
VAR_INPUT TestName : STRING(255); Ordered : BOOL; END_VAR
VAR i : INT; END_VAR
_tcuCurrent := 0;
FOR i := 1 TO _tcuCount DO
  IF _tcuName[i] = TestName THEN
    IF _tcuSeen[i] = _tcuCycle THEN
      (* a second TEST of this name in one cycle: two tests share the name *)
      IF NOT _tcuFailed[i] THEN
        _tcuFailed[i] := TRUE;
        _tcuMessage[i] := CONCAT(CONCAT('duplicate test name: two tests in this suite are called ''', TestName), '''');
        _tcuWhere[i] := 0;
      END_IF;
      RETURN;
    END_IF;
    _tcuSeen[i] := _tcuCycle;
    _tcuCurrent := i;
    _tcuSelect := i;
    RETURN;
  END_IF;
END_FOR;
IF _tcuCount >= 100 THEN
  _tcuOverflow := TRUE;
  RETURN;
END_IF;
_tcuCount := _tcuCount + 1;
_tcuName[_tcuCount] := TestName;
_tcuOrdered[_tcuCount] := Ordered;
_tcuSeen[_tcuCount] := _tcuCycle;
_tcuCurrent := _tcuCount;
_tcuSelect := _tcuCount;
END_METHOD

METHOD PRIVATE _tcuFail
VAR_INPUT Detail : STRING(255); Message : STRING(255); Loc : LINT; END_VAR
IF _tcuCurrent = 0 THEN
  RETURN;
END_IF;
IF _tcuFinished[_tcuCurrent] OR _tcuFailed[_tcuCurrent] THEN
  RETURN;
END_IF;
_tcuFailed[_tcuCurrent] := TRUE;
IF Message <> '' THEN
  _tcuMessage[_tcuCurrent] := CONCAT(CONCAT(Detail, ', MSG: '), Message);
ELSE
  _tcuMessage[_tcuCurrent] := Detail;
END_IF;
_tcuWhere[_tcuCurrent] := Loc;
END_METHOD

METHOD TEST
VAR_INPUT TestName : STRING(255); END_VAR
_tcuSelect(TestName, FALSE);
END_METHOD

(* TRUE when it is this test's turn: every ordered test registered before it finished. *)
METHOD TEST_ORDERED : BOOL
VAR_INPUT TestName : STRING(255); END_VAR
VAR i, k : INT; END_VAR
i := _tcuSelect(TestName, TRUE);
IF i = 0 THEN
  RETURN;
END_IF;
FOR k := 1 TO i - 1 DO
  IF _tcuOrdered[k] AND NOT _tcuFinished[k] THEN
    _tcuCurrent := 0;
    RETURN;
  END_IF;
END_FOR;
TEST_ORDERED := NOT _tcuFinished[i];
END_METHOD

METHOD TEST_FINISHED : BOOL
IF _tcuCurrent > 0 THEN
  _tcuFinished[_tcuCurrent] := TRUE;
END_IF;
TEST_FINISHED := TRUE;
END_METHOD

METHOD TEST_FINISHED_NAMED : BOOL
VAR_INPUT TestName : STRING(255); END_VAR
VAR i : INT; END_VAR
FOR i := 1 TO _tcuCount DO
  IF _tcuName[i] = TestName THEN
    _tcuFinished[i] := TRUE;
    TEST_FINISHED_NAMED := TRUE;
  END_IF;
END_FOR;
END_METHOD

METHOD AssertTrue
VAR_INPUT Condition : BOOL; Message : STRING(255); _tcuAt : LINT; END_VAR
IF NOT Condition THEN
  _tcuFail('EXP: TRUE, ACT: FALSE', Message, _tcuAt);
END_IF;
END_METHOD

METHOD AssertFalse
VAR_INPUT Condition : BOOL; Message : STRING(255); _tcuAt : LINT; END_VAR
IF Condition THEN
  _tcuFail('EXP: FALSE, ACT: TRUE', Message, _tcuAt);
END_IF;
END_METHOD

(* AssertEquals (ANY): the compiler calls AssertEquals_<type of Actual> instead; two
   different types end here, with their names in Expected and Actual. *)
METHOD AssertEquals
VAR_INPUT Expected : STRING(255); Actual : STRING(255); Message : STRING(255); _tcuAt : LINT; END_VAR
_tcuFail(CONCAT(CONCAT(CONCAT('EXP and ACT differ in type: EXP is ', Expected), ', ACT is '), Actual), Message, _tcuAt);
END_METHOD
)ST";
  for (const auto& e : elementary()) text += assert_equals(e);
  for (const char* dims : {"", "2d", "3d"})
    for (const char* t : kArrayTypes) text += assert_array_equals(dims, t);
  text += "\nEND_FUNCTION_BLOCK\n";
  return text;
}

// FB_ASSERT's AreEqual<TYPE> (REAL and LREAL within an optional Delta, exact without).
std::string are_equal(const Elementary& e, const std::string& name) {
  std::string text = R"ST(
METHOD AreEqual@N : BOOL
VAR_INPUT
  Expected : @T;
  Actual : @T;
  Message : STRING(255);
@D  _tcuAt : LINT;
END_VAR
AreEqual@N := @CMP;
_faLog(AreEqual@N, CONCAT(CONCAT('EXP: ', @E), CONCAT(', ACT: ', @A)), Message, _tcuAt);
END_METHOD
)ST";
  text = replace_all(text, "@D", e.delta ? std::string("  Delta : ") + e.type + ";\n" : "");
  text = replace_all(text, "@CMP", e.delta ? "ABS(Expected - Actual) <= Delta" : "Expected = Actual");
  const std::string shown = replace_all(e.text, "_tcuHex", "_faHex");
  text = replace_all(text, "@E", replace_all(shown, "@", "Expected"));
  text = replace_all(text, "@A", replace_all(shown, "@", "Actual"));
  text = replace_all(text, "@N", name);
  return replace_all(text, "@T", e.type);
}

// FB_ASSERT: an instance per test FB (`Assert : FB_ASSERT('FB_Foo')`, the unit's name
// through FB_init). The test FB steps its own state machine through the State property;
// every failed assertion (and, with PrintPassed, every passed one) is logged in the global
// _fa* table, once per state and assertion unless MultipleLog is set; AbortAfterFail skips
// every assertion after the first failure. `plcfi test --until EXPR` scans the program
// and reads the log (runtime/fb_assert.cpp).
std::string build_fb_assert() {
  std::string text = hex_function("_faHex") + R"ST(
VAR_GLOBAL
  _faCount : INT;                          (* log entries *)
  _faOverflow : BOOL;                      (* more than the log holds were due *)
  _faChecks : DINT;                        (* assertions evaluated *)
  _faFailures : DINT;                      (* of them failed *)
  _faUnit : ARRAY[1..500] OF STRING(80);
  _faState : ARRAY[1..500] OF DINT;
  _faPassed : ARRAY[1..500] OF BOOL;
  _faText : ARRAY[1..500] OF STRING(255);
  _faWhere : ARRAY[1..500] OF LINT;
END_VAR

FUNCTION_BLOCK FB_ASSERT
VAR_INPUT
  AbortAfterFail : BOOL;   (* after the first failure, the later assertions are skipped *)
  MultipleLog : BOOL;      (* a message repeated within one state is logged each time *)
  PrintPassed : BOOL;      (* passed assertions are logged too *)
END_VAR
VAR
  _faName : STRING(80);
  _faStep : DINT;
  _faFailed : DINT;
  _faSeenCount : INT;
  _faSeenAt : ARRAY[1..32] OF LINT;
  _faSeenText : ARRAY[1..32] OF STRING(255);
END_VAR

METHOD FB_init : BOOL
VAR_INPUT
  bInitRetains : BOOL;
  bInCopyCode : BOOL;
  sName : STRING(80);
END_VAR
_faName := sName;
END_METHOD

PROPERTY State : DINT
GET
  State := _faStep;
END_GET
SET
  IF State <> _faStep THEN
    _faSeenCount := 0;
  END_IF;
  _faStep := State;
END_SET
END_PROPERTY

PROPERTY Failed : BOOL
GET
  Failed := _faFailed > 0;
END_GET
END_PROPERTY

PROPERTY Failures : DINT
GET
  Failures := _faFailed;
END_GET
END_PROPERTY

METHOD PRIVATE _faLog
VAR_INPUT Ok : BOOL; Detail : STRING(255); Message : STRING(255); Loc : LINT; Always : BOOL; END_VAR
VAR i : INT; text : STRING(255); END_VAR
IF AbortAfterFail AND _faFailed > 0 AND NOT Always THEN
  RETURN;
END_IF;
_faChecks := _faChecks + 1;
IF NOT Ok THEN
  _faFailed := _faFailed + 1;
  _faFailures := _faFailures + 1;
ELSIF NOT PrintPassed THEN
  RETURN;
END_IF;
IF Message <> '' THEN
  text := CONCAT(CONCAT(Detail, ', MSG: '), Message);
ELSE
  text := Detail;
END_IF;
IF NOT MultipleLog THEN
  FOR i := 1 TO _faSeenCount DO
    IF _faSeenAt[i] = Loc AND _faSeenText[i] = text THEN
      RETURN;
    END_IF;
  END_FOR;
  IF _faSeenCount < 32 THEN
    _faSeenCount := _faSeenCount + 1;
    _faSeenAt[_faSeenCount] := Loc;
    _faSeenText[_faSeenCount] := text;
  END_IF;
END_IF;
IF _faCount >= 500 THEN
  _faOverflow := TRUE;
  RETURN;
END_IF;
_faCount := _faCount + 1;
_faUnit[_faCount] := _faName;
_faState[_faCount] := _faStep;
_faPassed[_faCount] := Ok;
_faText[_faCount] := text;
_faWhere[_faCount] := Loc;
END_METHOD

(* CASE Assert.State OF ... ELSE Assert.StateMachineError(); END_CASE: logged even after
   AbortAfterFail stopped the assertions, as the test's own state machine went wrong. *)
METHOD StateMachineError
VAR_INPUT _tcuAt : LINT; END_VAR
_faLog(FALSE, CONCAT('state machine error: no step for state ', DINT_TO_STRING(_faStep)), '', _tcuAt, TRUE);
END_METHOD

(* The compiler compares the Size bytes at the two addresses and passes what it found
   in Expected ('' when they are equal). *)
METHOD AreEqualMEM : BOOL
VAR_INPUT
  Expected : STRING(255);
  Actual : BOOL;
  Size : UDINT;
  Message : STRING(255);
  _tcuAt : LINT;
END_VAR
AreEqualMEM := Expected = '';
_faLog(AreEqualMEM, Expected, Message, _tcuAt);
END_METHOD
)ST";
  for (const auto& e : elementary()) text += are_equal(e, e.name);
  for (const auto& e : elementary()) {  // the short names of the date and time types
    if (std::string(e.name) == "TIME_OF_DAY") text += are_equal(e, "TOD");
    if (std::string(e.name) == "DATE_AND_TIME") text += are_equal(e, "DT");
  }
  text += "\nEND_FUNCTION_BLOCK\n";
  return text;
}

}  // namespace

const char* fb_assert_source() {
  static const std::string text = build_fb_assert();
  return text.c_str();
}

const char* tcunit_source() {
  static const std::string text = build_tcunit();
  return text.c_str();
}

}  // namespace plcfi::st
