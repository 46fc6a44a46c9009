// ST data types: elementary types, arrays, structs, enums, subranges, references and POU
// types, with their memory layout and the IEC 61131-3 implicit-conversion rules.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "syntax/kinds.hpp"
#include "syntax/source.hpp"

namespace plcfi::st {

enum class TypeKind : uint8_t {
  Bool,
  SInt, Int, DInt, LInt, USInt, UInt, UDInt, ULInt,
  Byte, Word, DWord, LWord,
  Real, LReal,
  Time, LTime, Date, TimeOfDay, DateTime,
  String, WString,
  Array, Struct, Enum, Ref,
  Pou,        // FUNCTION_BLOCK or PROGRAM instance
  Interface,  // interface reference (holds an instance address)
  Void,       // function without result
};

// Storage class of a value in VM memory; selects the typed opcode family.
enum class Storage : uint8_t { I8, I16, I32, I64, U8, U16, U32, U64, F32, F64, Block };

struct PouInfo;
struct Type;

struct Field {
  std::string name;   // spelling of the declaration
  const Type* type = nullptr;
  uint32_t offset = 0;
  SourceLoc loc;
};

struct Type {
  TypeKind kind = TypeKind::Void;
  std::string name;  // "INT", "STRING[20]", user name, "ARRAY [1..3] OF INT"
  uint32_t size = 0;
  uint32_t align = 1;
  // Subrange (on an integer kind): values outside [lo, hi] trap on assignment.
  bool ranged = false;
  int64_t lo = 0, hi = 0;
  // Array: element and dimensions (row-major).
  const Type* elem = nullptr;
  struct Dim {
    int64_t lo, hi;
  };
  std::vector<Dim> dims;
  // ARRAY[*] (only a VAR_IN_OUT's type): the bounds are the argument's, known at run time
  // from the in-out's slot (address, then LOWER/UPPER per dimension); dims holds zeros.
  bool open = false;
  // LTIME under --dialect codesys: unsigned 64-bit nanoseconds (CODESYS, TwinCAT); IEC's is
  // signed (negative durations exist).
  bool unsigned_count = false;
  // LDATE, LTOD, LDT: the values of DATE, TOD and DT (plcfi holds those in ns already),
  // counted in nanoseconds when converted to and from numbers (IEC 61131-3, CODESYS).
  bool long_date = false;
  // Struct: members.
  std::vector<Field> fields;
  bool is_union = false;  // UNION (CODESYS): every field at offset 0, the size of the largest
  // Enum: base integer type and values.
  const Type* base = nullptr;
  std::vector<std::pair<std::string, int64_t>> enum_values;
  // String: capacity in characters.
  uint32_t str_len = 0;
  // Ref: target type.
  const Type* target = nullptr;
  // Ref declared REFERENCE TO (CODESYS): every use of a variable of this type reaches
  // the target; only REF= and __ISVALIDREF see the reference itself.
  bool implicit_deref = false;
  // Pou / Interface:
  PouInfo* pou = nullptr;
  // Initial image of a value of this type (size bytes): defaults and declared initializers.
  std::vector<uint8_t> init;

  bool is_integer() const;   // SINT..ULINT (and subranges of them)
  bool is_signed() const { return kind >= TypeKind::SInt && kind <= TypeKind::LInt; }
  bool is_unsigned_int() const;
  bool is_bitstring() const;  // BYTE..LWORD
  bool is_real() const;       // REAL, LREAL
  bool is_numeric() const { return is_integer() || is_real(); }
  bool is_anybit() const { return kind == TypeKind::Bool || is_bitstring(); }
  bool is_time_like() const;  // TIME, LTIME, DATE, TOD, DT
  bool is_string() const { return kind == TypeKind::String || kind == TypeKind::WString; }
  bool is_elementary() const;  // fits in a scalar slot (<= 8 bytes, not a block)
  Storage storage() const;
  uint32_t bit_width() const;  // BOOL 1, BYTE 8, ...
  const Field* field(std::string_view name) const;  // case-insensitive
};

// Owns every type of one compilation; elementary types are created once.
class TypeTable {
 public:
  TypeTable();
  const Type* elementary(TypeKind k) const { return elementary_[static_cast<size_t>(k)]; }
  // LDATE, LTOD or LDT for k = Date, TimeOfDay or DateTime (see Type::long_date).
  const Type* long_date(TypeKind k) const;
  // LTIME counts unsigned (the CODESYS dialect); before any type uses it.
  void make_ltime_unsigned() {  // the table owns its elementary types: they are its to change
    const_cast<Type*>(elementary_[static_cast<size_t>(TypeKind::LTime)])->unsigned_count = true;
  }
  const Type* by_name(std::string_view name) const;  // elementary names only (INT, TIME, ...)
  const Type* string_type(uint32_t len, bool wide);
  const Type* ref_to(const Type* target);
  const Type* reference_to(const Type* target);  // REFERENCE TO target
  Type* make(TypeKind k, std::string name);  // a new user type, to be filled by the caller
  const Type* void_type() const { return elementary(TypeKind::Void); }
  const Type* null_ref() const { return null_; }  // the type of NULL: a reference to anything

 private:
  std::vector<std::unique_ptr<Type>> owned_;
  const Type* long_dates_[3] = {};  // LDATE, LTOD, LDT
  std::vector<const Type*> elementary_;
  const Type* null_ = nullptr;
};

// IEC 61131-3 implicit conversion (widening) from `from` to `to`; exact matches included.
bool implicitly_converts(const Type* from, const Type* to);
// The smallest type both operands widen to for arithmetic/comparison, or null.
const Type* common_type(const TypeTable& tt, const Type* a, const Type* b);
// Same type for assignment purposes (structural for strings of any length, arrays by shape).
bool same_type(const Type* a, const Type* b);

}  // namespace plcfi::st
