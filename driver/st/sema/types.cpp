// Elementary type table, layout helpers and the implicit-conversion lattice.
#include "types.hpp"

#include <array>

namespace plcfi::st {

namespace {
struct ElemSpec {
  TypeKind kind;
  const char* name;
  uint32_t size;
};
constexpr ElemSpec kElementary[] = {
    {TypeKind::Bool, "BOOL", 1},        {TypeKind::SInt, "SINT", 1},
    {TypeKind::Int, "INT", 2},          {TypeKind::DInt, "DINT", 4},
    {TypeKind::LInt, "LINT", 8},        {TypeKind::USInt, "USINT", 1},
    {TypeKind::UInt, "UINT", 2},        {TypeKind::UDInt, "UDINT", 4},
    {TypeKind::ULInt, "ULINT", 8},      {TypeKind::Byte, "BYTE", 1},
    {TypeKind::Word, "WORD", 2},        {TypeKind::DWord, "DWORD", 4},
    {TypeKind::LWord, "LWORD", 8},      {TypeKind::Real, "REAL", 4},
    {TypeKind::LReal, "LREAL", 8},      {TypeKind::Time, "TIME", 8},
    {TypeKind::LTime, "LTIME", 8},      {TypeKind::Date, "DATE", 8},
    {TypeKind::TimeOfDay, "TIME_OF_DAY", 8}, {TypeKind::DateTime, "DATE_AND_TIME", 8},
    {TypeKind::String, "STRING", 81},   {TypeKind::WString, "WSTRING", 162},
    {TypeKind::Array, "<array>", 0},    {TypeKind::Struct, "<struct>", 0},
    {TypeKind::Enum, "<enum>", 0},      {TypeKind::Ref, "<ref>", 4},
    {TypeKind::Pou, "<pou>", 0},        {TypeKind::Interface, "<interface>", 4},
    {TypeKind::Void, "VOID", 0},
};

struct Alias {
  const char* name;
  TypeKind kind;
};
constexpr Alias kAliases[] = {
    {"TOD", TypeKind::TimeOfDay}, {"DT", TypeKind::DateTime},   {"LTOD", TypeKind::TimeOfDay},
    {"LDT", TypeKind::DateTime},  {"LDATE", TypeKind::Date},    {"LTIME_OF_DAY", TypeKind::TimeOfDay},
    {"LDATE_AND_TIME", TypeKind::DateTime},
};
}  // namespace

TypeTable::TypeTable() {
  elementary_.resize(static_cast<size_t>(TypeKind::Void) + 1, nullptr);
  for (const auto& e : kElementary) {
    auto t = std::make_unique<Type>();
    t->kind = e.kind;
    t->name = e.name;
    t->size = e.size;
    // A WSTRING holds UTF-16 code units (as CODESYS and TwinCAT: WSTRING[N] takes 2*(N+1) bytes).
    t->align = e.kind == TypeKind::String ? 1 : e.kind == TypeKind::WString ? 2 : (e.size ? e.size : 1);
    if (t->is_string()) t->str_len = 80;
    t->init.assign(t->size, 0);
    elementary_[static_cast<size_t>(e.kind)] = t.get();
    owned_.push_back(std::move(t));
  }
  const std::pair<TypeKind, const char*> kLong[] = {{TypeKind::Date, "LDATE"}, {TypeKind::TimeOfDay, "LTOD"}, {TypeKind::DateTime, "LDT"}};
  for (size_t i = 0; i < 3; ++i) {
    auto t = std::make_unique<Type>(*elementary(kLong[i].first));
    t->name = kLong[i].second;
    t->long_date = true;
    long_dates_[i] = t.get();
    owned_.push_back(std::move(t));
  }
  Type* n = make(TypeKind::Ref, "NULL");
  n->size = 4;
  n->align = 4;
  n->target = elementary(TypeKind::Void);
  n->init.assign(4, 0);
  null_ = n;
}

const Type* TypeTable::by_name(std::string_view name) const {
  std::string c = canon(name);
  for (const auto& e : kElementary) {
    if (e.kind >= TypeKind::Array && e.kind != TypeKind::Void) continue;
    if (c == e.name) return elementary(e.kind);
  }
  for (const auto& a : kAliases)
    if (c == a.name) return c[0] == 'L' ? long_date(a.kind) : elementary(a.kind);
  return nullptr;
}

const Type* TypeTable::long_date(TypeKind k) const {
  switch (k) {
    case TypeKind::Date: return long_dates_[0];
    case TypeKind::TimeOfDay: return long_dates_[1];
    case TypeKind::DateTime: return long_dates_[2];
    default: return elementary(k);
  }
}

const Type* TypeTable::string_type(uint32_t len, bool wide) {
  if (len == 80) return elementary(wide ? TypeKind::WString : TypeKind::String);
  for (const auto& t : owned_)
    if (t->kind == (wide ? TypeKind::WString : TypeKind::String) && t->str_len == len) return t.get();
  Type* t = make(wide ? TypeKind::WString : TypeKind::String,
                 std::string(wide ? "WSTRING[" : "STRING[") + std::to_string(len) + "]");
  t->str_len = len;
  t->size = wide ? 2 * (len + 1) : len + 1;
  t->align = wide ? 2 : 1;
  t->init.assign(t->size, 0);
  return t;
}

const Type* TypeTable::ref_to(const Type* target) {
  for (const auto& t : owned_)
    if (t->kind == TypeKind::Ref && t->target == target && !t->implicit_deref) return t.get();
  Type* t = make(TypeKind::Ref, "REF_TO " + target->name);
  t->target = target;
  t->size = 4;
  t->align = 4;
  t->init.assign(4, 0);
  return t;
}

const Type* TypeTable::reference_to(const Type* target) {
  for (const auto& t : owned_)
    if (t->kind == TypeKind::Ref && t->target == target && t->implicit_deref) return t.get();
  Type* t = make(TypeKind::Ref, "REFERENCE TO " + target->name);
  t->target = target;
  t->implicit_deref = true;
  t->size = 4;
  t->align = 4;
  t->init.assign(4, 0);
  return t;
}

Type* TypeTable::make(TypeKind k, std::string name) {
  auto t = std::make_unique<Type>();
  t->kind = k;
  t->name = std::move(name);
  Type* raw = t.get();
  owned_.push_back(std::move(t));
  return raw;
}

bool Type::is_integer() const { return kind >= TypeKind::SInt && kind <= TypeKind::ULInt; }
bool Type::is_unsigned_int() const { return kind >= TypeKind::USInt && kind <= TypeKind::ULInt; }
bool Type::is_bitstring() const { return kind >= TypeKind::Byte && kind <= TypeKind::LWord; }
bool Type::is_real() const { return kind == TypeKind::Real || kind == TypeKind::LReal; }
bool Type::is_time_like() const { return kind >= TypeKind::Time && kind <= TypeKind::DateTime; }

bool Type::is_elementary() const {
  return kind <= TypeKind::DateTime || kind == TypeKind::Enum || kind == TypeKind::Ref ||
         kind == TypeKind::Interface;
}

Storage Type::storage() const {
  switch (kind) {
    case TypeKind::Bool: case TypeKind::USInt: case TypeKind::Byte: return Storage::U8;
    case TypeKind::SInt: return Storage::I8;
    case TypeKind::Int: return Storage::I16;
    case TypeKind::DInt: return Storage::I32;
    case TypeKind::LTime: return unsigned_count ? Storage::U64 : Storage::I64;
    case TypeKind::LInt: case TypeKind::Time: case TypeKind::Date:
    case TypeKind::TimeOfDay: case TypeKind::DateTime: return Storage::I64;
    case TypeKind::UInt: case TypeKind::Word: return Storage::U16;
    case TypeKind::UDInt: case TypeKind::DWord: case TypeKind::Ref: case TypeKind::Interface:
      return Storage::U32;
    case TypeKind::ULInt: case TypeKind::LWord: return Storage::U64;
    case TypeKind::Real: return Storage::F32;
    case TypeKind::LReal: return Storage::F64;
    case TypeKind::Enum: return base ? base->storage() : Storage::I16;
    default: return Storage::Block;
  }
}

uint32_t Type::bit_width() const {
  if (kind == TypeKind::Bool) return 1;
  return size * 8;
}

const Field* Type::field(std::string_view n) const {
  for (const auto& f : fields)
    if (iequals(f.name, n)) return &f;
  return nullptr;
}

namespace {
// Rank in the widening chains; -1 when not on that chain.
int signed_rank(TypeKind k) {
  switch (k) {
    case TypeKind::SInt: return 0;
    case TypeKind::Int: return 1;
    case TypeKind::DInt: return 2;
    case TypeKind::LInt: return 3;
    default: return -1;
  }
}
int unsigned_rank(TypeKind k) {
  switch (k) {
    case TypeKind::USInt: return 0;
    case TypeKind::UInt: return 1;
    case TypeKind::UDInt: return 2;
    case TypeKind::ULInt: return 3;
    default: return -1;
  }
}
int bits_rank(TypeKind k) {
  switch (k) {
    case TypeKind::Bool: return -1;
    case TypeKind::Byte: return 0;
    case TypeKind::Word: return 1;
    case TypeKind::DWord: return 2;
    case TypeKind::LWord: return 3;
    default: return -1;
  }
}

TypeKind plain(const Type* t) { return t->kind; }
}  // namespace

bool implicitly_converts(const Type* from, const Type* to) {
  if (!from || !to) return false;
  if (from == to) return true;
  TypeKind f = plain(from), t = plain(to);
  if (from->is_string() && to->is_string()) return f == t;
  if (f == TypeKind::Enum || t == TypeKind::Enum) return from == to || (f == t && from->name == to->name);
  if (f == TypeKind::Ref && t == TypeKind::Ref) return from->target == to->target || same_type(from->target, to->target);
  if (f == t && from->is_elementary()) return true;  // subrange <-> base, aliases
  int sf = signed_rank(f), st = signed_rank(t), uf = unsigned_rank(f), ut = unsigned_rank(t);
  if (sf >= 0 && st >= 0) return sf <= st;
  if (uf >= 0 && ut >= 0) return uf <= ut;
  if (uf >= 0 && st >= 0) return uf < st;  // USINT -> INT, UINT -> DINT, UDINT -> LINT
  // Same-width bit strings and unsigned integers are interchangeable (as CODESYS and
  // TwinCAT accept), and bit strings widen along their own chain.
  int bf = bits_rank(f), bt = bits_rank(t);
  if (bf >= 0 && bt >= 0) return bf <= bt;
  if (bf >= 0 && ut >= 0) return bf <= ut;
  if (uf >= 0 && bt >= 0) return uf <= bt;
  if (f == TypeKind::Bool && bt >= 0) return true;
  if (t == TypeKind::Real) return sf == 0 || sf == 1 || uf == 0 || uf == 1;
  if (t == TypeKind::LReal) return f == TypeKind::Real || (sf >= 0 && sf <= 2) || (uf >= 0 && uf <= 2);
  if (f == TypeKind::Time && t == TypeKind::LTime) return true;
  return false;
}

const Type* common_type(const TypeTable& tt, const Type* a, const Type* b) {
  if (implicitly_converts(a, b)) return b->ranged ? tt.elementary(b->kind) : (b->kind == TypeKind::Enum ? b : tt.elementary(b->kind));
  if (implicitly_converts(b, a)) return a->ranged ? tt.elementary(a->kind) : (a->kind == TypeKind::Enum ? a : tt.elementary(a->kind));
  static constexpr TypeKind kOrder[] = {TypeKind::SInt, TypeKind::Int,  TypeKind::DInt,
                                        TypeKind::LInt, TypeKind::Real, TypeKind::LReal};
  for (TypeKind k : kOrder) {
    const Type* t = tt.elementary(k);
    if (implicitly_converts(a, t) && implicitly_converts(b, t)) return t;
  }
  return nullptr;
}

bool same_type(const Type* a, const Type* b) {
  if (a == b) return true;
  if (!a || !b || a->kind != b->kind) return false;
  switch (a->kind) {
    case TypeKind::String: case TypeKind::WString: return true;
    case TypeKind::Array:
      if (a->dims.size() != b->dims.size()) return false;
      for (size_t i = 0; i < a->dims.size(); ++i)
        if (a->dims[i].hi - a->dims[i].lo != b->dims[i].hi - b->dims[i].lo) return false;
      return same_type(a->elem, b->elem);
    case TypeKind::Ref: return same_type(a->target, b->target);
    case TypeKind::Struct: case TypeKind::Enum: case TypeKind::Pou: case TypeKind::Interface:
      return false;
    default: return !a->ranged && !b->ranged ? true : a->kind == b->kind;
  }
}

}  // namespace plcfi::st
