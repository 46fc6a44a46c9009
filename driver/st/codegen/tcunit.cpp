// TcUnit calls the library (stdlib/tcunit.cpp) cannot express in ST: AssertEquals of ANY
// type, and AssertArray*Equals_<T> of arrays of any bounds.
#include <cstddef>
#include <cstring>

#include <fmt/format.h>

#include "compiler_impl.hpp"
#include "vm/cpp_functions.hpp"

namespace plcfi::st {

SourceLoc unpack_location(int64_t packed) {
  const auto v = static_cast<uint64_t>(packed);
  SourceLoc loc;
  loc.file = static_cast<uint32_t>(v >> 48);
  loc.line = static_cast<uint32_t>((v >> 16) & 0xffffffffu);
  loc.col = static_cast<uint32_t>(v & 0xffffu);
  return loc;
}

namespace detail {

namespace {

// The suffix of the typed AssertEquals_<T> (and array element types) for an elementary
// type; empty for the others.
std::string tcunit_suffix(const Type* t) {
  switch (t->kind) {
    case TypeKind::Bool: return "BOOL";
    case TypeKind::SInt: return "SINT";
    case TypeKind::Int: return "INT";
    case TypeKind::DInt: return "DINT";
    case TypeKind::LInt: return "LINT";
    case TypeKind::USInt: return "USINT";
    case TypeKind::UInt: return "UINT";
    case TypeKind::UDInt: return "UDINT";
    case TypeKind::ULInt: return "ULINT";
    case TypeKind::Byte: return "BYTE";
    case TypeKind::Word: return "WORD";
    case TypeKind::DWord: return "DWORD";
    case TypeKind::LWord: return "LWORD";
    case TypeKind::Real: return "REAL";
    case TypeKind::LReal: return "LREAL";
    case TypeKind::Time: return "TIME";
    case TypeKind::LTime: return "LTIME";
    case TypeKind::Date: return "DATE";
    case TypeKind::TimeOfDay: return "TIME_OF_DAY";
    case TypeKind::DateTime: return "DATE_AND_TIME";
    case TypeKind::String: return "STRING";
    case TypeKind::WString: return "WSTRING";
    default: return "";
  }
}

// The name TcUnit gives a value's type class in AssertEquals (ANY)'s type-mismatch message.
std::string tcunit_type_class(const Type* t) {
  switch (t->kind) {
    case TypeKind::DateTime: return "DATEANDTIME";
    case TypeKind::TimeOfDay: return "TIMEOFDAY";
    default: return tcunit_suffix(t);
  }
}

bool starts_with_ci(const std::string& s, std::string_view prefix) {
  return s.size() >= prefix.size() && iequals(std::string_view(s).substr(0, prefix.size()), prefix);
}

}  // namespace

bool Compiler::is_tcunit_method(const PouInfo* m) {
  return m->is_stdlib && m->owner && (iequals(m->owner->name, "FB_TestSuite") || iequals(m->owner->name, "FB_ASSERT"));
}

int64_t Compiler::pack_location(SourceLoc loc) {
  return static_cast<int64_t>((static_cast<uint64_t>(loc.file & 0xffffu) << 48) |
                              (static_cast<uint64_t>(loc.line) << 16) | (loc.col & 0xffffu));
}

PouInfo* Compiler::tcunit_lowering(const CallExpr& c, PouInfo* m) {
  const bool generic = iequals(m->name, "AssertEquals");
  const bool array = starts_with_ci(m->name, "AssertArray");
  const bool memory = iequals(m->name, "AreEqualMEM");
  if (!generic && !array && !memory) return m;
  declare_pou(m);  // its inputs, for arguments by position
  // The argument bound to input `name` (by name, or by position among the inputs).
  auto arg = [&](std::string_view name) -> const CallArg* {
    size_t pos = 0;
    for (const auto& a : c.args) {
      if (a.name) {
        if (iequals(a.name->text, name)) return &a;
        continue;
      }
      if (pos < m->inputs.size() && iequals(m->inputs[pos]->name, name)) return &a;
      ++pos;
    }
    return nullptr;
  };
  const char* first = generic || memory ? "Expected" : "Expecteds";
  const char* second = generic || memory ? "Actual" : "Actuals";
  const CallArg* e = arg(first);
  const CallArg* a = arg(second);
  if (!e || !e->value || !a || !a->value) {
    diags_.error("ST242", c.loc, fmt::format("{} needs {} and {}", m->name, first, second));
    return nullptr;
  }
  // Both are evaluated once, in the order they are written; the method's inputs then take
  // the values computed here (preset_).
  std::vector<const CallArg*> in_order;
  for (const auto& x : c.args)
    if (&x == e || &x == a) in_order.push_back(&x);

  if (generic) {
    Val ve, va;
    for (const CallArg* x : in_order) (x == e ? ve : va) = expr(*x->value, nullptr);
    if (!ve.ok || !va.ok) return nullptr;
    // An enumeration compares as its base integer.
    auto plain = [&](Val& v) {
      if (v.type && v.type->kind == TypeKind::Enum) v.type = v.type->base ? v.type->base : elem(TypeKind::Int);
    };
    plain(ve);
    plain(va);
    const Type* t = va.type ? va.type : ve.type;
    if (!t) t = default_type(va.c);  // two untyped literals
    const std::string suffix = tcunit_suffix(t);
    if (suffix.empty()) {
      diags_.error("ST242", a->loc, "AssertEquals compares elementary values; " + t->name +
                                        " is not one (compare its elements, or use AssertArrayEquals_<type>)");
      return nullptr;
    }
    if (ve.type && va.type && tcunit_suffix(ve.type) != suffix) {
      // TcUnit's AssertEquals (ANY) fails when the two differ in type: the generic method
      // reports it, with TcUnit's names of the type classes.
      auto name_of = [&](const Type* ty) {
        Val s;
        s.type = tt_->string_type(255, false);
        s.is_const = true;
        s.c.k = ConstV::K::Str;
        s.c.s = tcunit_type_class(ty);
        return s;
      };
      preset_[e->value.get()] = name_of(ve.type);
      preset_[a->value.get()] = name_of(va.type);
      return m;
    }
    // Two STRINGs: TcUnit's ANY compares their lengths first (its own message).
    PouInfo* typed = m->owner->find_method(suffix == "STRING" || suffix == "WSTRING" ? "_tcuAnyEquals_" + suffix
                                                                                     : "AssertEquals_" + suffix);
    if (!typed) {
      diags_.error("ST242", a->loc, "TcUnit has no AssertEquals_" + suffix);
      return nullptr;
    }
    preset_[e->value.get()] = ve;
    preset_[a->value.get()] = va;
    return typed;
  }

  if (memory) return memory_lowering(c, m, e, a, arg("Size"), in_order);

  // AssertArrayEquals_<T>, AssertArray2dEquals_<T>, AssertArray3dEquals_<T>.
  const std::string rest = m->name.substr(std::strlen("AssertArray"));
  const uint32_t ndims = starts_with_ci(rest, "2d") ? 2 : starts_with_ci(rest, "3d") ? 3 : 1;
  const std::string want = rest.substr(rest.find('_') + 1);
  Slot addr[2];
  const Type* arr[2] = {nullptr, nullptr};
  for (const CallArg* x : in_order) {
    const int i = x == e ? 0 : 1;
    Place p = place(*x->value, false);
    if (!p.ok) return nullptr;
    if (p.type->open) {
      diags_.error("ST242", x->value->loc, "plcfi's AssertArrayEquals takes arrays whose bounds are declared, not an ARRAY[*]");
      return nullptr;
    }
    if (p.type->kind != TypeKind::Array || p.type->dims.size() != ndims || !iequals(tcunit_suffix(p.type->elem), want)) {
      diags_.error("ST242", x->loc,
                   fmt::format("{} of {} must be an ARRAY {}OF {}, not {}", x == e ? first : second, m->name,
                               ndims == 1 ? "" : fmt::format("of {} dimensions ", ndims), want, p.type->name));
      return nullptr;
    }
    arr[i] = p.type;
    addr[i] = addr_of(p, x->loc);
  }
  Val delta;
  delta.type = elem(TypeKind::LReal);
  delta.is_const = true;
  delta.c.k = ConstV::K::Real;
  const CallArg* d = arg("Delta");
  if (d && d->value) {
    delta = expr(*d->value, nullptr);
    if (!delta.ok) return nullptr;
  }
  Slot block = temp(16, 8);
  store(frame_place(block, elem(TypeKind::UDInt)), addr[0]);
  store(frame_place(block.plus(4), elem(TypeKind::UDInt)), addr[1]);
  assign(frame_place(block.plus(8), elem(TypeKind::LReal)), delta, c.loc);
  ArrayDiffShape shape{};
  auto count = [](const Type* t) {
    uint64_t n = 1;
    for (const auto& dim : t->dims) n *= static_cast<uint64_t>(dim.hi - dim.lo + 1);
    return static_cast<uint32_t>(n);
  };
  shape.count_e = count(arr[0]);
  shape.count_a = count(arr[1]);
  shape.elem_size = arr[0]->elem->size;
  shape.kind = static_cast<uint32_t>(value_kind(arr[0]->elem));
  shape.ndims = ndims;
  for (uint32_t k = 0; k < ndims; ++k) {
    shape.lo[k] = static_cast<int32_t>(arr[0]->dims[k].lo);
    shape.extent[k] = static_cast<uint32_t>(arr[0]->dims[k].hi - arr[0]->dims[k].lo + 1);
  }
  shape.elem_size_a = arr[1]->elem->size;
  shape.style = 1;  // TcUnit's record, indices in each array's own bounds
  switch (arr[0]->elem->kind) {
    case TypeKind::Byte: case TypeKind::Word: case TypeKind::DWord: case TypeKind::LWord:
      shape.hex_digits = arr[0]->elem->size * 2;
      break;
    default: break;
  }
  for (uint32_t k = 0; k < ndims; ++k) {
    shape.lo_a[k] = static_cast<int32_t>(arr[1]->dims[k].lo);
    shape.extent_a[k] = static_cast<uint32_t>(arr[1]->dims[k].hi - arr[1]->dims[k].lo + 1);
  }
  Slot shape_slot = konst_bytes(&shape, sizeof shape, 4);
  Val diff = native(Native::ARRAY_DIFF, tt_->string_type(255, false), {block, shape_slot}, 255);
  Val unused;
  unused.type = elem(TypeKind::Bool);
  unused.is_const = true;
  unused.c.k = ConstV::K::Bool;
  preset_[e->value.get()] = diff;
  preset_[a->value.get()] = unused;
  if (d && d->value) preset_[d->value.get()] = delta;
  return m;
}

// FB_ASSERT's AreEqualMEM(Expected, Actual, Size, Message): the Size bytes at two
// addresses (ADR(x), a pointer or reference), compared by ARRAY_DIFF as arrays of BYTE
// indexed from 0; the shape's counts are Size's value at run time.
PouInfo* Compiler::memory_lowering(const CallExpr& c, PouInfo* m, const CallArg* e, const CallArg* a, const CallArg* size,
                                   const std::vector<const CallArg*>& in_order) {
  if (!size || !size->value) {
    diags_.error("ST242", c.loc, "AreEqualMEM needs Size, the number of bytes to compare");
    return nullptr;
  }
  Slot addr[2];
  for (const CallArg* x : in_order) {
    Val v = expr(*x->value, nullptr);
    if (!v.ok) return nullptr;
    if (!v.type || v.type->kind != TypeKind::Ref) {
      diags_.error("ST242", x->loc, fmt::format("{} of AreEqualMEM is an address (ADR(x), a pointer), not {}",
                                                x == e ? "Expected" : "Actual", v.type ? v.type->name : "a literal"));
      return nullptr;
    }
    addr[x == e ? 0 : 1] = to_slot(v, v.type, x->loc);
  }
  const Type* udint = elem(TypeKind::UDInt);
  Val bytes = expr_for(*size->value, udint);
  if (!bytes.ok) return nullptr;
  Slot n = to_slot(bytes, udint, size->loc);
  Slot block = temp(16, 8);
  store(frame_place(block, udint), addr[0]);
  store(frame_place(block.plus(4), udint), addr[1]);
  Val zero;
  zero.type = elem(TypeKind::LReal);
  zero.is_const = true;
  zero.c.k = ConstV::K::Real;
  assign(frame_place(block.plus(8), elem(TypeKind::LReal)), zero, c.loc);
  ArrayDiffShape shape{};
  shape.elem_size = shape.elem_size_a = 1;
  shape.kind = static_cast<uint32_t>(ValueKind::U8);
  shape.ndims = 1;
  Slot shape_slot = temp(sizeof shape, 4);
  emit(Op::MOVN, {shape_slot, konst_bytes(&shape, sizeof shape, 4), static_cast<uint32_t>(sizeof shape)});
  for (size_t off : {offsetof(ArrayDiffShape, count_e), offsetof(ArrayDiffShape, count_a), offsetof(ArrayDiffShape, extent)})
    store(frame_place(shape_slot.plus(static_cast<uint32_t>(off)), udint), n);
  preset_[e->value.get()] = native(Native::ARRAY_DIFF, tt_->string_type(255, false), {block, shape_slot}, 255);
  Val unused;
  unused.type = elem(TypeKind::Bool);
  unused.is_const = true;
  unused.c.k = ConstV::K::Bool;
  preset_[a->value.get()] = unused;
  bytes.slot = n;
  bytes.is_const = false;
  bytes.type = udint;
  preset_[size->value.get()] = bytes;
  return m;
}

}  // namespace detail
}  // namespace plcfi::st
