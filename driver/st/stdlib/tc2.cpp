// Data types of Beckhoff's Tc2 libraries (Tc2_System, Tc2_Standard, Tc2_Utilities) that
// TwinCAT programs use without declaring them, written from their public descriptions.
// Under --dialect codesys an application gets the ones its sources name and do not
// declare themselves (st/build.cpp), as the library "<Tc2>".
#include "codegen/compiler.hpp"

namespace plcfi::st {

const std::vector<Tc2Type>& tc2_types() {
  static const std::vector<Tc2Type> types = {
      {"T_MaxString", "TYPE T_MaxString : STRING(255); END_TYPE\n"},
      {"T_AmsNetId", "TYPE T_AmsNetId : STRING(23); END_TYPE\n"},
      {"T_AmsPort", "TYPE T_AmsPort : UINT; END_TYPE\n"},
      {"T_IPv4Addr", "TYPE T_IPv4Addr : STRING(15); END_TYPE\n"},
      {"T_IPv4AddrArr", "TYPE T_IPv4AddrArr : ARRAY[0..3] OF BYTE; END_TYPE\n"},
      {"T_AmsNetIdArr", "TYPE T_AmsNetIdArr : ARRAY[0..5] OF BYTE; END_TYPE\n"},
      {"TIMESTRUCT",
       "TYPE TIMESTRUCT :\nSTRUCT\n  wYear : WORD;\n  wMonth : WORD;\n  wDayOfWeek : WORD;\n  wDay : WORD;\n"
       "  wHour : WORD;\n  wMinute : WORD;\n  wSecond : WORD;\n  wMilliseconds : WORD;\nEND_STRUCT\nEND_TYPE\n"},
      {"T_FILETIME", "TYPE T_FILETIME :\nSTRUCT\n  dwLowDateTime : DWORD;\n  dwHighDateTime : DWORD;\nEND_STRUCT\nEND_TYPE\n"},
      // Every library holds a global constant of this type with its version (stLibVersion_<lib>).
      {"ST_LibVersion",
       "TYPE ST_LibVersion :\nSTRUCT\n  iMajor : UINT;\n  iMinor : UINT;\n  iBuild : UINT;\n  iRevision : UINT;\n"
       "  nFlags : DWORD;\n  sVersion : STRING(23);\nEND_STRUCT\nEND_TYPE\n"},
      {"UXINT", "TYPE UXINT : ULINT; END_TYPE\n"},
      {"XINT", "TYPE XINT : LINT; END_TYPE\n"},
      {"XWORD", "TYPE XWORD : LWORD; END_TYPE\n"},
  };
  return types;
}

}  // namespace plcfi::st
