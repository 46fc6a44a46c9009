// The standard functions implemented in C++ (not open-coded by the compiler): their
// identifiers, called by the NATIVE instruction. Not to be confused with native/, the
// native tier, which translates whole programs to C++.
#pragma once

#include <cstdint>
#include <string>

namespace plcfi::st {

// Operand conventions (a, b, c, d are frame pointers; cap = result string capacity):
//   math:   a := f(b) on F32 or F64 (EXPT: a := b ** c)
//   string: see cpp_functions.cpp for each function's operands; integer operands are I64.
enum class Native : uint32_t {
#define PLCFI_NATIVE_MATH(X) X(SQRT) X(LN) X(LOG) X(EXP) X(SIN) X(COS) X(TAN) X(ASIN) X(ACOS) X(ATAN) X(EXPT)
#define X(n) n##_F32, n##_F64,
  PLCFI_NATIVE_MATH(X)
#undef X
  S_LEN, S_LEFT, S_RIGHT, S_MID, S_CONCAT, S_INSERT, S_DELETE, S_REPLACE, S_FIND,
  // The same on WSTRINGs (UTF-16 code units), in the same order (wide_native()).
  W_LEN, W_LEFT, W_RIGHT, W_MID, W_CONCAT, W_INSERT, W_DELETE, W_REPLACE, W_FIND,
  S_TO_W, W_TO_S,  // a (capacity cap) := b, STRING (UTF-8) to WSTRING (UTF-16) and back
  I64_TO_S, U64_TO_S, F32_TO_S, F64_TO_S, BOOL_TO_S, TIME_TO_S, DATE_TO_S, TOD_TO_S, DT_TO_S,
  S_TO_I64, S_TO_U64, S_TO_F64, S_TO_BOOL, S_TO_TIME,
  DT_TO_DATE, DT_TO_TOD,
  BCD_DECODE, BCD_ENCODE,  // a := f(b), both ULINT
  ARRAY_DIFF,              // a := the first difference of two arrays (vm.cpp: array_difference)
  // Tc2_System (Beckhoff), on addresses (UDINT): a := MEMCPY(dest = b, src = c, n = d),
  // MEMMOVE the same, MEMSET(dest = b, fill = c (USINT), n = d); a: UDINT. MEMCMP: a: DINT.
  // An area outside the memory traps (Machine::native_trap) and touches nothing.
  MEM_CPY, MEM_MOVE, MEM_SET, MEM_CMP,
  // ADSLOGSTR, ADSLOGDINT, ADSLOGLREAL: a: DINT := 0; b: the DWORD mask; c: the format
  // string; d: the argument (STRING, DINT, LREAL). The message goes to Machine::log().
  ADSLOG_STR, ADSLOG_DINT, ADSLOG_LREAL,
  TASK_INDEX,              // a: BYTE := the 1-based index of the running task
  LTIME_U_TO_S,            // LTIME_TO_STRING of an unsigned LTIME (--dialect codesys)
  // TcUnit's library calls its runner: a: DINT := the event's result; b: the event (DINT),
  // c: the suite instance's address (stdlib/tcunit_abi.hpp). Machine::hook() answers.
  TCUNIT,
  Count_
};

// The WSTRING variant of a string function's native (S_LEN .. S_FIND).
inline Native wide_native(Native n) {
  return static_cast<Native>(static_cast<uint32_t>(n) + (static_cast<uint32_t>(Native::W_LEN) - static_cast<uint32_t>(Native::S_LEN)));
}

// Whether the native can trap (the NATIVE instruction then checks for it).
inline bool native_traps(uint32_t id) {
  return id >= static_cast<uint32_t>(Native::MEM_CPY) && id <= static_cast<uint32_t>(Native::MEM_CMP);
}

// The literal text of a time-like value held in nanoseconds (TIME and LTIME durations,
// DATE, TIME_OF_DAY and DATE_AND_TIME since 1970-01-01 / midnight): T#1h2m, D#2024-03-01,
// TOD#01:00:00.250, DT#2024-03-01-01:00:00. What messages, --print and traces show.
std::string duration_literal(int64_t ns);
// An unsigned LTIME (CODESYS): T#... up to INT64_MAX, LTIME#... above (no TIME holds it).
std::string unsigned_duration_literal(uint64_t ns);
std::string date_literal(int64_t ns);
std::string tod_literal(int64_t ns);
std::string dt_literal(int64_t ns);

}  // namespace plcfi::st
