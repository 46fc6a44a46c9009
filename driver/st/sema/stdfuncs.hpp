// Signatures of the IEC 61131-3 standard functions, the operator functions of
// requirement monitors and the test-file built-ins: their names, families, argument
// counts and what each one computes, and the rules of the type conversions (INT_TO_REAL,
// TO_DINT, TRUNC). Code generation (codegen/builtins.cpp) emits from these; nothing here
// depends on how a call is compiled.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "sema/types.hpp"
#include "syntax/ast.hpp"
#include "vm/cpp_functions.hpp"
#include "vm/vm.hpp"

namespace plcfi::st {

// How a standard function is compiled: one emitter per family.
enum class StdFamily : uint8_t {
  Math,           // SQRT, LN, ... on REAL or LREAL (native = the REAL variant)
  Expt,           // EXPT
  Abs,            // ABS
  Extremum,       // MIN, MAX, LIMIT (pick)
  Sel,            // SEL
  Mux,            // MUX
  Operator,       // ADD, GT, ADD_TIME, ...: the functional form of a binary operator (op)
  ConcatDateTod,  // CONCAT_DATE_TOD
  Move,           // MOVE
  Shift,          // SHL, SHR, ROL, ROR (shift)
  String,         // LEN, LEFT, ... (native, operands, int_result)
  Concat,         // CONCAT
  Replace,        // REPLACE
  AddressOf,      // ADR, REF
  SizeOf,         // SIZEOF
  Bound,          // LOWER_BOUND, UPPER_BOUND (of an array, ARRAY[*] too)
  IsValidRef,     // __ISVALIDREF (CODESYS): whether a REFERENCE TO is bound
  Now,            // __NOW: the virtual clock, in generated code only
  Temporal,       // RISING, CHANGES, PASSED, ... (temporal): requirement monitors only
  AdvanceTime,    // ADVANCE_TIME: test files only
  Assert,         // ASSERT_EQ, MOCK_VERIFY_CALLED, ... (assert_kind): test files only
  System,         // Tc2_System's MEMCPY, ADSLOGSTR, ... (native, operands, result): codesys only
  Count_
};

enum class Pick : uint8_t { Min, Max, Limit };
enum class Shift : uint8_t { Shl, Shr, Rol, Ror };
enum class Temporal : uint8_t { Rising, Falling, High, Low, Changes, Increases, Decreases, Passed };

// Flags of a StdFunc.
inline constexpr uint8_t kStdExtensible = 1;  // any number of arguments from min_args on
inline constexpr uint8_t kStdLateOnly = 2;    // only in units compiled late (monitors); elsewhere unknown
inline constexpr uint8_t kStdTestOnly = 4;    // only in TEST, SETUP and TEARDOWN blocks (error elsewhere)
inline constexpr uint8_t kStdCodesysOnly = 8; // a vendor library's, under --dialect codesys; elsewhere unknown
inline constexpr uint8_t kStdLibraryOnly = 16; // only in plcfi's built-in libraries' POUs (any dialect)

struct StdFunc {
  std::string_view name;  // canonical (upper case)
  StdFamily family = StdFamily::Math;
  uint8_t min_args = 0, max_args = 0;  // max_args is meaningless when extensible
  uint8_t flags = 0;
  // The formal parameter names, in order, for calls like LIMIT(MN := 0, IN := x, MX := 9).
  std::vector<const char*> params;
  // Payload: what the family needs to know of this member.
  Native native = Native::Count_;    // Math, String
  BinaryOp op = BinaryOp::Add;       // Operator
  AssertKind assert_kind = AssertKind::Eq;  // Assert
  Pick pick = Pick::Min;             // Extremum
  Shift shift = Shift::Shl;          // Shift
  Temporal temporal = Temporal::Rising;  // Temporal
  // String: one letter per argument, S = string, I = integer. System: A = an address
  // (UDINT, a pointer or ADR(x)), U = UDINT, Y = USINT, W = DWORD, D = DINT, F = LREAL,
  // S = STRING; `result` the same for the result.
  const char* operands = "";
  char result = 0;
  bool int_result = false;           // String: INT result (LEN, FIND) instead of a string

  bool extensible() const { return flags & kStdExtensible; }
  bool late_only() const { return flags & kStdLateOnly; }
  bool test_only() const { return flags & kStdTestOnly; }
  bool codesys_only() const { return flags & kStdCodesysOnly; }
  bool library_only() const { return flags & kStdLibraryOnly; }
  // The largest argument count, SIZE_MAX when extensible.
  size_t max_count() const { return extensible() ? SIZE_MAX : max_args; }
};

// Every standard function, in table order.
const std::vector<StdFunc>& std_functions();
// The standard function of that (canonical, upper-case) name, or null. Conversion
// functions are not in the table: see parse_conversion.
const StdFunc* find_std_function(std::string_view upper_name);

// ---- conversions

// A conversion function's name taken apart: X_TO_Y, TO_Y (from = null: the argument's
// own type), TRUNC (to DINT, from the argument's type), TRUNC_Y and X_TRUNC_Y, and the
// BCD forms.
struct ConversionName {
  const Type* from = nullptr;
  const Type* to = nullptr;
  bool trunc = false;
  // BCD: WORD_BCD_TO_UINT, BCD_TO_INT (decode the bit string's nibbles as decimal digits),
  // UINT_TO_BCD_WORD, INT_TO_BCD, TO_BCD_WORD (encode).
  enum class Bcd : uint8_t { None, Decode, Encode } bcd = Bcd::None;
  // TIME_TO_US, LTIME_TO_S, ...: a duration as a LINT count of this many nanoseconds
  // (NS 1, US 1000, MS 10^6, S 10^9), truncated toward zero; 0: not such a conversion.
  int64_t unit_ns = 0;
};
// Null when the name is no conversion (or names a type that does not exist).
std::optional<ConversionName> parse_conversion(const TypeTable& tt, std::string_view upper_name);

// What converting a value of one type to another does. Each kind is one way of emitting
// the conversion; None: the types do not convert.
enum class ConversionKind : uint8_t {
  None,
  Trunc,         // TRUNC: a REAL or LREAL toward zero, then to the target
  ToString,      // a BOOL, number, bit string, duration or date to its text
  StringCopy,    // a STRING to STRING: the value itself, keeping its own length
  FromString,    // a STRING parsed as a BOOL, number, bit string or duration
  DtToDate,      // DATE_AND_TIME to DATE: the day
  DtToTod,       // DATE_AND_TIME to TIME_OF_DAY: the time of the day
  Retype,        // same representation: between durations and dates, BOOL to BOOL
  ToBool,        // anything else to BOOL: nonzero is TRUE
  TimeToNumber,  // a duration (TIME in milliseconds) or date to a number
  NumberToTime,  // a number to a duration (TIME in milliseconds) or date
  Round,         // a REAL or LREAL to an integer or bit string, halves to even (IEC 60559)
  Numeric,       // between numbers and bit strings: widening or narrowing
};
// The kind of conversion from `from` (an enumeration converts as its base type) to `to`;
// `trunc` for TRUNC, which only converts REAL and LREAL.
ConversionKind conversion_kind(const Type* from, const Type* to, bool trunc = false);

// ---- argument classes checked by the emitters

// MIN, MAX and LIMIT: values with an order.
inline bool is_min_max_operand(const Type* t) { return t->is_numeric() || t->is_bitstring() || t->is_time_like(); }
// SHL, SHR, ROL, ROR: the shifted value, and the shift count.
inline bool is_shift_operand(const Type* t) { return t->is_bitstring() || t->is_integer(); }
// CHANGES: a value compared for equality between states.
inline bool is_change_operand(const Type* t) {
  return t->is_numeric() || t->is_bitstring() || t->is_time_like() || t->kind == TypeKind::Enum ||
         t->kind == TypeKind::Bool;
}
// INCREASES, DECREASES: a value with an order.
inline bool is_ordered_operand(const Type* t) { return t->is_numeric() || t->is_time_like() || t->is_bitstring(); }

}  // namespace plcfi::st
