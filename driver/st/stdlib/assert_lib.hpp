// The elementary types the assertion libraries (TcUnit, FB_ASSERT) have typed assertions
// for, with the ST expression of each value's text, and the helpers both libraries' ST
// generators use.
#pragma once

#include <string>
#include <vector>

namespace plcfi::st::assert_lib {

struct Elementary {
  const char* name;     // as in AssertEquals_<name>
  const char* type;     // the ST type
  const char* text;     // ST expression of type STRING for the value @ (Expected/Actual)
  bool delta = false;   // REAL/LREAL: compared within Delta
};

inline const std::vector<Elementary>& elementary() {
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
      {"REAL", "REAL", "_tcuReal(REAL_TO_STRING(@))", true},
      {"LREAL", "LREAL", "_tcuReal(LREAL_TO_STRING(@))", true},
      {"TIME", "TIME", "TIME_TO_STRING(@)"},
      {"LTIME", "LTIME", "LTIME_TO_STRING(@)"},
      {"DATE", "DATE", "DATE_TO_STRING(@)"},
      {"TIME_OF_DAY", "TIME_OF_DAY", "TOD_TO_STRING(@)"},
      {"DATE_AND_TIME", "DATE_AND_TIME", "DT_TO_STRING(@)"},
      {"STRING", "STRING(255)", "@"},
      // TcUnit does not print WSTRINGs (nor does FB_ASSERT here: the ASCII of one).
      {"WSTRING", "WSTRING(255)", "WSTRING_TO_STRING(@)"},
  };
  return v;
}

inline std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size())) s.replace(p, from.size(), to);
  return s;
}

// FUNCTION <name> : the hexadecimal text of a bit string, as TcUnit shows it (0x0A).
inline std::string hex_function(const std::string& name) {
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

}  // namespace plcfi::st::assert_lib
