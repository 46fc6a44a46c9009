// FB_ASSERT, the older assertion-FB style of TwinCAT unit tests, written in ST (its runner
// is testing/fb_assert.cpp).
#include <string>

#include "assert_lib.hpp"
#include "codegen/compiler.hpp"

namespace plcfi::st {

namespace {

using namespace assert_lib;

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
_faLog(AreEqual@N, CONCAT(CONCAT('EXP: ', @E), CONCAT(', ACT: ', @A)), Message, _tcuAt, FALSE, FALSE);
END_METHOD
)ST";
  text = replace_all(text, "@D", e.delta ? std::string("  Delta : ") + e.type + ";\n" : "");
  text = replace_all(text, "@CMP", e.delta ? "ABS(Expected - Actual) <= Delta" : "Expected = Actual");
  // Plain REAL texts (TcUnit's trailing .0 is TcUnit's).
  const std::string shown = e.delta ? std::string(e.type) + "_TO_STRING(@)" : replace_all(e.text, "_tcuHex", "_faHex");
  text = replace_all(text, "@E", replace_all(shown, "@", "Expected"));
  text = replace_all(text, "@A", replace_all(shown, "@", "Actual"));
  text = replace_all(text, "@N", name);
  return replace_all(text, "@T", e.type);
}

// FB_ASSERT: an instance per test FB (`Assert : FB_ASSERT('FB_Foo')`, the unit's name
// through FB_init). The test FB steps its own state machine through the State property;
// every failed assertion (and, with LogPassed, every passed one) is logged in the global
// _fa* table, once per state and assertion unless MultipleLog is set; AbortAfterFail skips
// every assertion after the first failure. `plcfi test --until EXPR` scans the program
// and reads the log (testing/fb_assert.cpp).
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
  LogPassed : BOOL;        (* passed assertions are logged too *)
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

(* Notice: the test's own line (PrintPassed), logged whatever LogPassed says and not
   counted as an assertion. *)
METHOD PRIVATE _faLog
VAR_INPUT Ok : BOOL; Detail : STRING(255); Message : STRING(255); Loc : LINT; Always : BOOL; Notice : BOOL; END_VAR
VAR i : INT; text : STRING(255); END_VAR
IF AbortAfterFail AND _faFailed > 0 AND NOT Always THEN
  RETURN;
END_IF;
IF NOT Notice THEN
  _faChecks := _faChecks + 1;
END_IF;
IF NOT Ok THEN
  _faFailed := _faFailed + 1;
  _faFailures := _faFailures + 1;
ELSIF NOT LogPassed AND NOT Notice THEN
  RETURN;
END_IF;
IF Message <> '' AND Detail <> '' THEN
  text := CONCAT(CONCAT(Detail, ', MSG: '), Message);
ELSIF Detail <> '' THEN
  text := Detail;
ELSE
  text := Message;
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
_faLog(FALSE, CONCAT('state machine error: no step for state ', DINT_TO_STRING(_faStep)), '', _tcuAt, TRUE, FALSE);
END_METHOD

(* Assert.PrintPassed('Done'): when no assertion of this unit failed, the message is logged
   as passed (once per state unless MultipleLog); returns whether none failed. *)
METHOD PrintPassed : BOOL
VAR_INPUT Message : STRING(255); _tcuAt : LINT; END_VAR
PrintPassed := _faFailed = 0;
IF PrintPassed THEN
  _faLog(TRUE, '', Message, _tcuAt, TRUE, TRUE);
END_IF;
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
_faLog(AreEqualMEM, Expected, Message, _tcuAt, FALSE, FALSE);
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

}  // namespace plcfi::st
