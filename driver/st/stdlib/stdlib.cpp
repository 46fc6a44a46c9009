// The standard function blocks of IEC 61131-3, written in ST and compiled with every
// application. Timers read the scan clock through __NOW(), never the wall clock.
#include <string>

#include "codegen/compiler.hpp"

namespace plcfi::st {

namespace {
// CTU, CTD and CTUD for one count type; the standard names the INT ones plain
// (CTU) and the others by suffix (CTU_DINT, CTU_LINT, CTU_UDINT, CTU_ULINT).
std::string counters(const std::string& suffix, const std::string& type, const std::string& lo, const std::string& hi) {
  std::string text = R"ST(
FUNCTION_BLOCK CTU@S
VAR_INPUT CU : BOOL; R : BOOL; PV : @T; END_VAR
VAR_OUTPUT Q : BOOL; CV : @T; END_VAR
VAR prev : BOOL; END_VAR
IF R THEN
  CV := 0;
ELSIF CU AND NOT prev AND CV < @HI THEN
  CV := CV + 1;
END_IF;
prev := CU;
Q := CV >= PV;
END_FUNCTION_BLOCK

FUNCTION_BLOCK CTD@S
VAR_INPUT CD : BOOL; LD : BOOL; PV : @T; END_VAR
VAR_OUTPUT Q : BOOL; CV : @T; END_VAR
VAR prev : BOOL; END_VAR
IF LD THEN
  CV := PV;
ELSIF CD AND NOT prev AND CV > @LO THEN
  CV := CV - 1;
END_IF;
prev := CD;
Q := CV <= 0;
END_FUNCTION_BLOCK

FUNCTION_BLOCK CTUD@S
VAR_INPUT CU : BOOL; CD : BOOL; R : BOOL; LD : BOOL; PV : @T; END_VAR
VAR_OUTPUT QU : BOOL; QD : BOOL; CV : @T; END_VAR
VAR cu_prev : BOOL; cd_prev : BOOL; up : BOOL; down : BOOL; END_VAR
up := CU AND NOT cu_prev;
down := CD AND NOT cd_prev;
IF R THEN
  CV := 0;
ELSIF LD THEN
  CV := PV;
ELSIF NOT (up AND down) THEN
  IF up AND CV < @HI THEN
    CV := CV + 1;
  ELSIF down AND CV > @LO THEN
    CV := CV - 1;
  END_IF;
END_IF;
cu_prev := CU;
cd_prev := CD;
QU := CV >= PV;
QD := CV <= 0;
END_FUNCTION_BLOCK

)ST";
  for (auto [key, value] : {std::pair<std::string, std::string>{"@S", suffix}, {"@T", type}, {"@LO", lo}, {"@HI", hi}}) {
    for (size_t pos = text.find(key); pos != std::string::npos; pos = text.find(key, pos + value.size()))
      text.replace(pos, key.size(), value);
  }
  return text;
}

// F_TRIG as the dialect defines it. IEC 61131-3 (2nd edition on, and MATIEC): M holds NOT
// CLK, so a first call with CLK FALSE is a falling edge. CODESYS's and TwinCAT's standard
// libraries keep the 1st edition's: M holds CLK, and a first call gives no edge.
const char* f_trig(Dialect d) {
  return d == Dialect::Iec ? R"ST(FUNCTION_BLOCK F_TRIG
VAR_INPUT CLK : BOOL; END_VAR
VAR_OUTPUT Q : BOOL; END_VAR
VAR M : BOOL; END_VAR
Q := NOT CLK AND NOT M;
M := NOT CLK;
END_FUNCTION_BLOCK
)ST"
                           : R"ST(FUNCTION_BLOCK F_TRIG
VAR_INPUT CLK : BOOL; END_VAR
VAR_OUTPUT Q : BOOL; END_VAR
VAR M : BOOL; END_VAR
Q := NOT CLK AND M;
M := CLK;
END_FUNCTION_BLOCK
)ST";
}

std::string build_stdlib(Dialect d) {
  std::string text = R"ST(
(* The state of a textual SFC (syntax/sfc_lower.hpp): a step (X active, T time active), an
   action control (Q its output, A active including the final scan) and the chart's clock. *)
TYPE
  __SFC_STEP : STRUCT X : BOOL; T : TIME; END_STRUCT;
  __SFC_ACTION : STRUCT
    Q : BOOL; A : BOOL;
    __r : BOOL; __s : BOOL; __p : BOOL; __pm : BOOL; __p0 : BOOL; __p0m : BOOL;
    __ff : BOOL; __run : BOOL; __et : TIME; __tq : BOOL; __qprev : BOOL;
  END_STRUCT;
  __SFC_CHART : STRUCT started : BOOL; last : TIME; END_STRUCT;
END_TYPE

(* TON: Q rises when IN has been TRUE for PT; ET counts up to PT and resets with IN. *)
FUNCTION_BLOCK TON
VAR_INPUT IN : BOOL; PT : TIME; END_VAR
VAR_OUTPUT Q : BOOL; ET : TIME; END_VAR
VAR start : TIME; running : BOOL; END_VAR
IF IN THEN
  IF NOT running THEN
    running := TRUE;
    start := __NOW();
  END_IF;
  ET := __NOW() - start;
  IF ET >= PT THEN
    ET := PT;
    Q := TRUE;
  ELSE
    Q := FALSE;
  END_IF;
ELSE
  running := FALSE;
  Q := FALSE;
  ET := T#0s;
END_IF;
END_FUNCTION_BLOCK

(* TOF: Q follows IN up at once and falls PT after IN falls. *)
FUNCTION_BLOCK TOF
VAR_INPUT IN : BOOL; PT : TIME; END_VAR
VAR_OUTPUT Q : BOOL; ET : TIME; END_VAR
VAR start : TIME; running : BOOL; END_VAR
IF IN THEN
  Q := TRUE;
  ET := T#0s;
  running := FALSE;
ELSIF Q THEN
  IF NOT running THEN
    running := TRUE;
    start := __NOW();
  END_IF;
  ET := __NOW() - start;
  IF ET >= PT THEN
    ET := PT;
    Q := FALSE;
    running := FALSE;
  END_IF;
END_IF;
END_FUNCTION_BLOCK

(* TP: a pulse of length PT on a rising edge of IN; not retriggerable while it runs. *)
FUNCTION_BLOCK TP
VAR_INPUT IN : BOOL; PT : TIME; END_VAR
VAR_OUTPUT Q : BOOL; ET : TIME; END_VAR
VAR start : TIME; running : BOOL; prev_in : BOOL; END_VAR
IF running THEN
  ET := __NOW() - start;
  IF ET >= PT THEN
    ET := PT;
    Q := FALSE;
    running := FALSE;
  END_IF;
ELSIF IN AND NOT prev_in THEN
  start := __NOW();
  ET := T#0s;
  IF PT > T#0s THEN
    running := TRUE;
    Q := TRUE;
  ELSE
    Q := FALSE;
  END_IF;
ELSIF NOT IN THEN
  ET := T#0s;
END_IF;
prev_in := IN;
END_FUNCTION_BLOCK

FUNCTION_BLOCK R_TRIG
VAR_INPUT CLK : BOOL; END_VAR
VAR_OUTPUT Q : BOOL; END_VAR
VAR M : BOOL; END_VAR
Q := CLK AND NOT M;
M := CLK;
END_FUNCTION_BLOCK

@F_TRIG

(* SR: set dominant. RS: reset dominant. *)
FUNCTION_BLOCK SR
VAR_INPUT S1 : BOOL; R : BOOL; END_VAR
VAR_OUTPUT Q1 : BOOL; END_VAR
Q1 := S1 OR (NOT R AND Q1);
END_FUNCTION_BLOCK

FUNCTION_BLOCK RS
VAR_INPUT S : BOOL; R1 : BOOL; END_VAR
VAR_OUTPUT Q1 : BOOL; END_VAR
Q1 := NOT R1 AND (S OR Q1);
END_FUNCTION_BLOCK
)ST";
  text += counters("", "INT", "-32768", "32767");
  text += counters("_DINT", "DINT", "-2147483648", "2147483647");
  text += counters("_LINT", "LINT", "-9223372036854775807", "9223372036854775807");
  text += counters("_UDINT", "UDINT", "0", "4294967295");
  text += counters("_ULINT", "ULINT", "0", "18446744073709551615");
  text.replace(text.find("@F_TRIG"), 7, f_trig(d));
  return text;
}
}  // namespace

const char* stdlib_source(Dialect d) {
  static const std::string iec = build_stdlib(Dialect::Iec);
  static const std::string codesys = build_stdlib(Dialect::Codesys);
  return d == Dialect::Iec ? iec.c_str() : codesys.c_str();
}

}  // namespace plcfi::st
