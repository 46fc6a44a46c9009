// Rvalues: type checking with IEC implicit widening and conversions, constant folding,
// and translation of expressions to typed VM instructions. Places (lvalues) are in places.cpp.
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "compiler_impl.hpp"
#include "vm/ops.hpp"

namespace plcfi::st::detail {

namespace {
bool is_logic(BinaryOp op) { return op == BinaryOp::And || op == BinaryOp::Or || op == BinaryOp::Xor; }
// The six comparisons on two folded operands of one kind; nullopt for other operators.
template <class T>
std::optional<bool> compare(BinaryOp op, T x, T y) {
  switch (op) {
    case BinaryOp::Lt: return x < y;
    case BinaryOp::Gt: return x > y;
    case BinaryOp::Le: return x <= y;
    case BinaryOp::Ge: return x >= y;
    case BinaryOp::Eq: return x == y;
    case BinaryOp::Ne: return x != y;
    default: return std::nullopt;
  }
}
ConstV bool_const(bool b) {
  ConstV c;
  c.k = ConstV::K::Bool;
  c.i = b;
  return c;
}
}  // namespace

std::optional<ConstV> fold_binary(BinaryOp op, const ConstV& l, const ConstV& r, std::string* err) {
  if (l.k == ConstV::K::Str || r.k == ConstV::K::Str) {
    if (l.k == r.k && (op == BinaryOp::Eq || op == BinaryOp::Ne)) return bool_const((l.s == r.s) == (op == BinaryOp::Eq));
    *err = "string constants cannot be combined with " + std::string(op_text(op));
    return std::nullopt;
  }
  bool real = l.k == ConstV::K::Real || r.k == ConstV::K::Real || op == BinaryOp::Pow;
  ConstV c;
  if (real) {
    double x = l.k == ConstV::K::Real ? l.r : static_cast<double>(l.i);
    double y = r.k == ConstV::K::Real ? r.r : static_cast<double>(r.i);
    c.k = ConstV::K::Real;
    switch (op) {
      case BinaryOp::Add: c.r = x + y; return c;
      case BinaryOp::Sub: c.r = x - y; return c;
      case BinaryOp::Mul: c.r = x * y; return c;
      case BinaryOp::Div: c.r = x / y; return c;
      case BinaryOp::Pow: c.r = std::pow(x, y); return c;
      default: break;
    }
    if (auto b = compare(op, x, y)) return bool_const(*b);
    *err = std::string(op_text(op)) + " is not applicable to REAL values";
    return std::nullopt;
  }
  int64_t x = l.i, y = r.i;
  auto ux = static_cast<uint64_t>(x), uy = static_cast<uint64_t>(y);
  c.k = (l.k == ConstV::K::Bool && r.k == ConstV::K::Bool) ? ConstV::K::Bool : ConstV::K::Int;
  switch (op) {
    case BinaryOp::Add: c.i = static_cast<int64_t>(ux + uy); return c;
    case BinaryOp::Sub: c.i = static_cast<int64_t>(ux - uy); return c;
    case BinaryOp::Mul: c.i = static_cast<int64_t>(ux * uy); return c;
    case BinaryOp::Div:
    case BinaryOp::Mod:
      if (y == 0) {
        *err = "division by zero in a constant expression";
        return std::nullopt;
      }
      if (y == -1) c.i = op == BinaryOp::Div ? static_cast<int64_t>(0ULL - ux) : 0;
      else c.i = op == BinaryOp::Div ? x / y : x % y;
      return c;
    case BinaryOp::And: c.i = x & y; return c;
    case BinaryOp::Or: c.i = x | y; return c;
    case BinaryOp::Xor: c.i = x ^ y; return c;
    default: break;
  }
  if (auto b = compare(op, x, y)) return bool_const(*b);
  *err = "operator not applicable in a constant expression";
  return std::nullopt;
}

const Type* Compiler::default_type(const ConstV& c) const {
  switch (c.k) {
    case ConstV::K::Int: return (c.i >= INT32_MIN && c.i <= INT32_MAX) ? elem(TypeKind::DInt) : elem(TypeKind::LInt);
    case ConstV::K::Real: return elem(TypeKind::LReal);
    case ConstV::K::Bool: return elem(TypeKind::Bool);
    case ConstV::K::Str: return tt_->string_type(std::max<uint32_t>(1, static_cast<uint32_t>(c.s.size())), false);
    default: return elem(TypeKind::DInt);
  }
}

// ------------------------------------------------------------------ conversions

Val Compiler::coerce(const Val& v, const Type* to, SourceLoc loc, const char* what) {
  if (!v.ok || !to) return bad();
  if (v.nominal && !v.is_const && v.type != to) {
    // A register value (see Val::nominal): to its own type or wider it keeps every bit (as
    // CODESYS's `dwVar := wVar + 1` gives 65536), to a narrower type it is cut, without a
    // warning where its IEC type converts implicitly.
    if (to->is_elementary() && (to == v.nominal || implicitly_converts(v.nominal, to) || implicitly_converts(v.type, to))) {
      Val out;
      out.type = to;
      out.slot = convert(v.slot, v.type, to);
      return out;
    }
    Val n;
    n.type = v.nominal;
    n.slot = convert(v.slot, v.type, v.nominal);
    return coerce(n, to, loc, what);
  }
  Val out = v;
  if (v.is_const && !v.type) {
    // Untyped literal: must be representable in the target.
    bool fits = false;
    if (v.c.k == ConstV::K::Int) fits = to->is_integer() || to->is_bitstring() || to->is_real() || to->kind == TypeKind::Enum ||
                                        (to->kind == TypeKind::Bool && (v.c.i == 0 || v.c.i == 1));
    else if (v.c.k == ConstV::K::Real) fits = to->is_real();
    if (!fits) {
      diags_.error("ST203", loc, std::string("cannot use ") + (v.c.k == ConstV::K::Real ? "a REAL literal" : "an integer literal") +
                                     " as " + to->name + (what ? std::string(" in ") + what : ""));
      return bad();
    }
    if (to->kind == TypeKind::Enum) {
      if (opt_.dialect == Dialect::Codesys && to->base) {  // CODESYS: an integer is an enumeration's value
        if (opt_.warnings)
          diags_.warning("ST405", loc, "implicit conversion from an integer to enumeration " + to->name +
                                           (what ? std::string(" in ") + what : std::string()) + "; write " + to->name + "#Value");
        Val as_base = coerce(v, to->base, loc, what);
        if (as_base.ok) as_base.type = to;
        return as_base;
      }
      diags_.error("ST203", loc, "cannot use an integer as enumeration " + to->name + "; use " + to->name + "#Value");
      return bad();
    }
    std::vector<uint8_t> buf(to->size ? to->size : 1);
    if (!write_const(buf.data(), to, v.c, loc)) return bad();
    out.type = to;
    return out;
  }
  if (v.type == null_type_ && (to->kind == TypeKind::Ref || to->kind == TypeKind::Interface)) {
    out.type = to;
    return out;
  }
  if (v.type == to || implicitly_converts(v.type, to) || (v.type->is_string() && to->is_string()) ||
      (v.type->kind == TypeKind::Ref && to->kind == TypeKind::Ref && (same_type(v.type, to) || derives(v.type->target, to->target)))) {
    // A constant takes the target type; a computed value keeps its own type so that
    // to_slot() knows what to convert from.
    if (v.is_const && to->is_elementary()) {
      std::vector<uint8_t> buf(to->size ? to->size : 1);
      if (!write_const(buf.data(), to, v.c, loc)) return bad();
      out.type = to;
    }
    return out;
  }
  if (v.type->kind == TypeKind::Interface && to->kind == TypeKind::Interface && v.type->pou && to->pou &&
      implements(v.type->pou, to->pou)) {
    out.type = to;
    return out;
  }
  if (same_type(v.type, to) && !to->is_elementary()) {
    out.type = to;
    return out;
  }
  if (opt_.dialect == Dialect::Codesys) {
    // CODESYS converts between an enumeration and integers implicitly: through its base type.
    bool enum_to_number = v.type->kind == TypeKind::Enum && v.type->base && (to->is_integer() || to->is_bitstring());
    bool number_to_enum = to->kind == TypeKind::Enum && to->base && (v.type->is_integer() || v.type->is_bitstring());
    if (enum_to_number || number_to_enum) {
      if (opt_.warnings)
        diags_.warning("ST405", loc, "implicit conversion from " + v.type->name + " to " + to->name +
                                         (what ? std::string(" in ") + what : std::string()) +
                                         (enum_to_number ? " (the enumeration's value)" : "; write TO_" + canon(to->base->name) + " or an enumeration value"));
      Val w = v;
      if (enum_to_number) {
        w.type = v.type->base;
        return coerce(w, to, loc, what);
      }
      w = coerce(w, to->base, loc, what);
      if (w.ok) w.type = to;
      return w;
    }
    if (std::optional<Val> p = pointer_conversion(v, to, loc)) return *p;
    if (dialect_converts(v.type, to)) return implicit_conversion(v, to, loc, what);
  }
  std::string hint;
  if (v.type->is_elementary() && to->is_elementary() && v.type->kind != TypeKind::Enum && to->kind != TypeKind::Enum &&
      v.type->kind != TypeKind::Ref && to->kind != TypeKind::Ref)
    hint = "; use " + canon(v.type->name) + "_TO_" + canon(to->name) + "()";
  diags_.error("ST203", loc, "cannot convert " + v.type->name + " to " + to->name + " implicitly" +
                                 (what ? std::string(" in ") + what : "") + hint);
  return bad();
}

// CODESYS pointers: a POINTER TO (or REF_TO) one type is taken for one to any other (as
// `pt := ADR(buffer)` does), and an address converts to and from an integer or bit string
// (DWORD, UDINT, LWORD, ...). Addresses are 32-bit numbers here. Nullopt: not such a case.
std::optional<Val> Compiler::pointer_conversion(const Val& v, const Type* to, SourceLoc loc) {
  const Type* udint = elem(TypeKind::UDInt);
  const bool from_ref = v.type->kind == TypeKind::Ref && !v.type->implicit_deref;
  const bool to_ref = to->kind == TypeKind::Ref && !to->implicit_deref;
  auto address_number = [](const Type* t) { return t->is_integer() || t->is_bitstring(); };
  if (from_ref && to_ref) {
    Val out = v;
    out.type = to;
    return out;
  }
  if (from_ref && address_number(to)) {
    Val out;
    out.type = to;
    out.slot = convert(to_slot(v, v.type, loc), udint, to);
    return out;
  }
  if (to_ref && address_number(v.type)) {
    Val out;
    out.type = to;
    out.slot = convert(to_slot(v, v.type, loc), v.type, udint);
    return out;
  }
  return std::nullopt;
}

// CODESYS and TwinCAT convert between any two numbers, bit strings and BOOL implicitly.
bool Compiler::dialect_converts(const Type* from, const Type* to) const {
  auto number = [](const Type* t) {
    return t->is_numeric() || t->is_bitstring() || (t->kind == TypeKind::Bool);
  };
  return from->is_elementary() && to->is_elementary() && number(from) && number(to);
}

// A conversion IEC 61131-3 wants written out, done implicitly as the dialect does: a
// warning naming the conversion (an error with --strict), and the conversion the function
// of that name would do (a REAL to an integer rounds).
Val Compiler::implicit_conversion(const Val& v, const Type* to, SourceLoc loc, const char* what) {
  const Type* from = v.type;
  // Narrowing: some value of the source has no equal in the target.
  auto is_signed = [](const Type* t) { return t->is_integer() && !t->is_unsigned_int(); };
  bool narrowing;
  if (to->kind == TypeKind::Bool) narrowing = true;
  else if (from->kind == TypeKind::Bool) narrowing = false;
  else if (from->is_real()) narrowing = !to->is_real() || to->size < from->size;
  else if (to->is_real()) narrowing = from->size >= to->size;  // REAL holds 24 bits exactly, LREAL 53
  else narrowing = to->size < from->size || (is_signed(from) && !is_signed(to)) ||
                   (!is_signed(from) && is_signed(to) && to->size == from->size);
  std::string fn = canon(from->name) + "_TO_" + canon(to->name);
  std::string msg = fmt::format("implicit conversion from {} to {}{} ({}){}", from->name, to->name,
                                what ? std::string(" in ") + what : std::string(), fn,
                                narrowing ? ": values outside the target's range or precision change" : "");
  if (opt_.strict) {
    diags_.error("ST203", loc, msg + "; write " + fn + "() (--strict)");
    return bad();
  }
  if (opt_.warnings) diags_.warning("ST405", loc, msg);
  Val out = v;
  out.type = to;
  if (v.is_const) {
    if (from->is_real() && !to->is_real()) {
      out.c.k = ConstV::K::Int;
      out.c.i = static_cast<int64_t>(std::nearbyint(v.c.r));
    } else if (!from->is_real() && to->is_real() && v.c.k == ConstV::K::Int) {
      out.c.k = ConstV::K::Real;
      out.c.r = static_cast<double>(v.c.i);
    }
    // Wrap to the target's width, as a run-time conversion would.
    if (out.c.k == ConstV::K::Int && to->size < 8) {
      uint64_t mask = (uint64_t(1) << (to->size * 8)) - 1;
      uint64_t bits = static_cast<uint64_t>(out.c.i) & mask;
      if (to->kind == TypeKind::Bool) bits = out.c.i != 0;
      else if (to->is_integer() && !to->is_unsigned_int() && (bits >> (to->size * 8 - 1)))
        bits |= ~mask;
      out.c.i = static_cast<int64_t>(bits);
    }
    return out;
  }
  Slot s = v.slot;
  if (to->kind == TypeKind::Bool) {
    Slot t = temp(1, 1);
    if (from->is_real()) emit(num_op(Op::NE_I8, from->storage()), {t, s, konst(from, ConstV{ConstV::K::Real, 0, 0.0, {}}, loc)});
    else emit(from->size == 1 ? Op::TOBOOL8 : from->size == 2 ? Op::TOBOOL16 : from->size == 4 ? Op::TOBOOL32 : Op::TOBOOL64, {t, s});
    def(t);
    out.slot = t;
    return out;
  }
  if (from->is_real() && !to->is_real()) {
    Slot r = temp_for(from);
    emit(from->kind == TypeKind::Real ? Op::ROUND_F32 : Op::ROUND_F64, {r, s});
    def(r);
    s = r;
  }
  out.slot = convert(s, from, to);
  return out;
}

Slot Compiler::to_slot(const Val& v, const Type* t, SourceLoc loc) {
  if (v.is_const) return konst(t, v.c, loc);
  return convert(v.slot, v.type, t);
}

Slot Compiler::convert(Slot s, const Type* from, const Type* to) {
  if (!from || !to || from == to) return s;
  if (from->is_string() && to->is_string() && from->kind != to->kind) return restring(s, from, to->kind == TypeKind::WString).slot;
  Storage a = from->storage(), b = to->storage();
  if (a == b || a == Storage::Block || b == Storage::Block) return s;
  // Between integers of one width a conversion only reinterprets the bits (two's
  // complement), so the value can stay where it is.
  auto is_int = [](Storage x) { return x != Storage::F32 && x != Storage::F64; };
  static constexpr uint32_t kWidth[] = {1, 2, 4, 8, 1, 2, 4, 8, 4, 8};
  if (is_int(a) && is_int(b) && kWidth[storage_index(a)] == kWidth[storage_index(b)]) return s;
  auto key = std::make_tuple(s.off, s.kind, a, b);
  if (s.kind == SK::Var) {
    auto it = b_->cvt_cache.find(key);
    if (it != b_->cvt_cache.end()) return it->second;
  }
  Slot t = temp_for(to);
  emit(cvt_op(a, b), {t, s});
  def(t);
  if (s.kind == SK::Var) b_->cvt_cache[key] = t;
  return t;
}

Val Compiler::restring(Slot s, const Type* from, bool wide) {
  Val out;
  out.type = from;
  out.slot = s;
  if ((from->kind == TypeKind::WString) == wide) return out;
  // Room for the whole source (a code unit takes up to 3 bytes of UTF-8): the
  // destination's own capacity truncates when the result is stored.
  const uint32_t cap = wide ? from->str_len : std::min<uint32_t>(3 * from->str_len, 0xFFFF);
  return native(wide ? Native::S_TO_W : Native::W_TO_S, tt_->string_type(cap, wide), {s}, cap);
}

Slot Compiler::string_slot(const Val& v, bool wide, SourceLoc loc) {
  const Type* t = v.type ? v.type : default_type(v.c);
  if (v.is_const) return konst(tt_->string_type(t->str_len, wide), v.c, loc);  // a unit per byte at most
  return restring(v.slot, t, wide).slot;
}

// ------------------------------------------------------------------ expressions

Val Compiler::literal(const LiteralExpr& l, const Type* expected) {
  Val v;
  v.is_const = true;
  auto c = const_eval(l, file_);
  if (!c) return bad();
  v.c = *c;
  switch (l.lit) {
    case LiteralKind::Int:
    case LiteralKind::Real:
      if (!l.type_prefix.empty()) {
        Ident id{l.type_prefix, l.loc};
        const Type* t = named_type(id, file_);
        if (!t) return bad();
        if (t->kind == TypeKind::Enum) {
          diags_.error("ST230", l.loc, "use " + t->name + "#ValueName for enumeration values");
          return bad();
        }
        Val u = v;
        u.type = nullptr;
        return coerce(u, t, l.loc, nullptr);
      }
      return v;  // untyped
    case LiteralKind::Bool:
      if (!l.type_prefix.empty() && tt_->by_name(l.type_prefix) && tt_->by_name(l.type_prefix)->kind != TypeKind::Bool) {
        Ident id{l.type_prefix, l.loc};
        Val u = v;
        u.c.k = ConstV::K::Int;
        return coerce(u, named_type(id, file_), l.loc, nullptr);
      }
      v.type = elem(TypeKind::Bool);
      return v;
    case LiteralKind::String:
    case LiteralKind::WString:
      v.type = l.lit == LiteralKind::WString
                   ? tt_->string_type(std::max<uint32_t>(1, static_cast<uint32_t>(utf8_to_utf16(l.str_value).size())), true)
                   : tt_->string_type(std::max<uint32_t>(1, static_cast<uint32_t>(l.str_value.size())), false);
      return v;
    case LiteralKind::Time: v.type = elem(l.is_long ? TypeKind::LTime : TypeKind::Time); return v;
    case LiteralKind::Date: v.type = l.is_long ? tt_->long_date(TypeKind::Date) : elem(TypeKind::Date); return v;
    case LiteralKind::TimeOfDay: v.type = l.is_long ? tt_->long_date(TypeKind::TimeOfDay) : elem(TypeKind::TimeOfDay); return v;
    case LiteralKind::DateTime: v.type = l.is_long ? tt_->long_date(TypeKind::DateTime) : elem(TypeKind::DateTime); return v;
  }
  (void)expected;
  return v;
}

Val Compiler::expr_for(const Expr& e, const Type* target) {
  if (target && target->kind == TypeKind::Interface &&
      (e.kind == ExprKind::Name || e.kind == ExprKind::Member || e.kind == ExprKind::Index || e.kind == ExprKind::Deref)) {
    if (e.kind == ExprKind::Name && iequals(static_cast<const NameExpr&>(e).name.text, "NULL")) return expr(e, target);
    Place p = place(e, false);
    if (!p.ok) return bad();
    if (p.type->kind == TypeKind::Pou) {
      if (!p.type->pou || !implements(p.type->pou, target->pou)) {
        diags_.error("ST225", e.loc, p.type->name + " does not implement interface " + target->name);
        return bad();
      }
      Val v;
      v.type = target;
      v.slot = addr_of(p, e.loc);
      return v;
    }
    return load(p);
  }
  return expr(e, target);
}

Val Compiler::expr(const Expr& e, const Type* expected) {
  if (!preset_.empty()) {
    if (auto it = preset_.find(&e); it != preset_.end()) {
      Val v = it->second;
      preset_.erase(it);
      return v;
    }
  }
  Val r = [&]() -> Val {
    switch (e.kind) {
      case ExprKind::Literal: return literal(static_cast<const LiteralExpr&>(e), expected);
      case ExprKind::EnumLiteral: {
        const auto& el = static_cast<const EnumLiteralExpr&>(e);
        const Type* t = named_type(el.type_name, file_);
        if (!t) return bad();
        if (t->kind != TypeKind::Enum) {
          // INT#x with an identifier: a typed constant name.
          diags_.error("ST230", e.loc, "'" + el.type_name.text + "' is not an enumeration type");
          return bad();
        }
        for (const auto& [n, v] : t->enum_values)
          if (iequals(n, el.value.text)) {
            Val out;
            out.is_const = true;
            out.type = t;
            out.c = ConstV{ConstV::K::Int, v, 0, {}};
            return out;
          }
        diags_.error("ST230", el.value.loc, "'" + el.value.text + "' is not a value of " + t->name);
        return bad();
      }
      case ExprKind::Name: {
        const auto& n = static_cast<const NameExpr&>(e);
        std::string key = canon(n.name.text);
        if (key == "NULL" && !lookup(key)) {
          Val v;
          v.is_const = true;
          v.type = null_type_;
          v.c = ConstV{ConstV::K::Int, 0, 0, {}};
          return v;
        }
        // Enumeration values: the expected enum decides between equal names.
        if (expected && expected->kind == TypeKind::Enum) {
          for (const auto& [vn, vv] : expected->enum_values)
            if (iequals(vn, n.name.text) && !(b_ && b_->locals.count(key))) {
              Val v;
              v.is_const = true;
              v.type = expected;
              v.c = ConstV{ConstV::K::Int, vv, 0, {}};
              return v;
            }
        }
        const Symbol* s = lookup(key);
        if (s && s->kind == SymKind::EnumValue) {
          Val v;
          v.is_const = true;
          v.type = s->type;
          v.c = ConstV{ConstV::K::Int, s->enum_value, 0, {}};
          return v;
        }
        if (!s && enum_values_.count(key) && enum_values_[key].size() > 1) {
          diags_.error("ST230", e.loc, "'" + n.name.text + "' is a value of several enumerations; write Type#" + n.name.text);
          return bad();
        }
        // A VAR_INPUT CONSTANT (VAR_IN_OUT CONSTANT) is read-only in its POU but takes the
        // value each call or instance gives it: never folded to its default.
        const VarDecl* sd = s && s->constant && !is_parameter(*s) ? decl_of(s) : nullptr;
        if (sd && sd->init && s->type && s->type->is_elementary() && sd->init->kind != ExprKind::ArrayInit &&
            sd->init->kind != ExprKind::StructInit) {
          auto c = const_eval(*sd->init, file_, false);
          if (c) {
            ++sym_src(s).reads;
            Val v;
            v.is_const = true;
            v.c = *c;
            v.type = s->type;
            if (s->type->is_real() && v.c.k == ConstV::K::Int) {
              v.c.k = ConstV::K::Real;
              v.c.r = static_cast<double>(v.c.i);
            }
            return v;
          }
        }
        bool is_result = b_ && b_->pou && ((!b_->pou->property.empty() && iequals(b_->pou->property, key)) ||
                                           ((b_->pou->kind == PouKind::Function || b_->pou->kind == PouKind::Method) &&
                                            iequals(b_->pou->name, key)));
        if (!s && !is_result && b_ && b_->this_type && b_->this_type->pou) {
          // A property of the instance itself, read by its bare name.
          if (PouInfo* g = b_->this_type->pou->find_method("__GET_" + key)) {
            Place self = this_place(e.loc);
            return property_get(self, g, addr_of(self, e.loc), e.loc);
          }
        }
        return load(place(e, false));
      }
      case ExprKind::Member: {
        const auto& m = static_cast<const MemberExpr&>(e);
        bool reported = false;
        if (auto ev = qualified_enum(m, file_, true, &reported)) {
          Val out;
          out.is_const = true;
          out.type = ev->type;
          out.c = ConstV{ConstV::K::Int, ev->value, 0, {}};
          return out;
        }
        if (reported) return bad();
        // Properties: obj.Prop reads call the getter.
        auto try_property = [&]() -> std::optional<Val> {
          if (m.base->kind == ExprKind::Name) {
            const auto& bn = static_cast<const NameExpr&>(*m.base);
            const Symbol* s = lookup(canon(bn.name.text));
            if (!s) return std::nullopt;  // maybe GVL.x
            if (s->type && s->type->kind == TypeKind::Interface) {
              PouInfo* g = s->type->pou->find_method("__GET_" + canon(m.member.text));
              if (!g) return std::nullopt;
              Val itf = expr(*m.base);
              return property_get(Place{}, g, itf.slot, e.loc);
            }
          }
          return std::nullopt;
        };
        if (auto pv = try_property()) return *pv;
        if (m.base->kind == ExprKind::Name && !lookup(canon(static_cast<const NameExpr&>(*m.base).name.text)))
          return load(place(e, false));  // GVL.x, or Main.x in a monitor
        Place base = place(*m.base, false);
        if (!base.ok) return bad();
        if (base.type->kind == TypeKind::Pou && !base.type->field(m.member.text) && base.type->pou) {
          if (PouInfo* g = base.type->pou->find_method("__GET_" + canon(m.member.text)))
            return property_get(base, g, addr_of(base, e.loc), e.loc);
        }
        if (base.type->kind == TypeKind::Interface && base.type->pou) {
          if (PouInfo* g = base.type->pou->find_method("__GET_" + canon(m.member.text))) {
            Val itf = load(base);
            return property_get(Place{}, g, itf.slot, e.loc);
          }
        }
        return load_once(implicit_deref(member_place(base, m.member, e.loc), e.loc));
      }
      case ExprKind::Index: return load_once(place(e, false));
      case ExprKind::DirectAddr:
      case ExprKind::Deref:
      case ExprKind::BitAccess: return load(place(e, false));
      case ExprKind::Call: {
        // Generic standard functions of untyped literals (MAX(10, 20)) take their type
        // from the context, as 10 + 20 does; the hint lasts for this call only.
        const Type* saved = call_expected_;
        call_expected_ = expected;
        Val v = call(static_cast<const CallExpr&>(e), false);
        call_expected_ = saved;
        return v;
      }
      case ExprKind::Unary: return unary(static_cast<const UnaryExpr&>(e), expected);
      case ExprKind::Binary: return binary(static_cast<const BinaryExpr&>(e), expected);
      case ExprKind::This: {
        Place p = this_place(e.loc);
        if (!p.ok) return bad();
        Val v;
        v.type = tt_->ref_to(p.type);
        v.slot = b_->is_method ? Slot{8, SK::Var} : addr_of(p, e.loc);
        return v;
      }
      case ExprKind::Super:
        diags_.error("ST231", e.loc, "SUPER must be dereferenced: SUPER^.Method() or SUPER^()");
        return bad();
      case ExprKind::ArrayInit:
      case ExprKind::StructInit:
        diags_.error("ST215", e.loc, "an initializer list is only allowed in a declaration");
        return bad();
    }
    return bad();
  }();
  // Rule 27: which element the instruction just emitted loaded into which temporary.
  if ((e.kind == ExprKind::Index || e.kind == ExprKind::Member) && r.ok && !r.is_const && r.slot.kind == SK::Temp && b_ &&
      b_->last_instr + 1 < b_->code.size() && b_->last_def_pos == b_->last_instr &&
      b_->code[b_->last_instr + 1] == r.slot.off && kind_at(b_->last_instr + 1) == SK::Temp) {
    b_->elem_loads[1] = b_->elem_loads[0];
    b_->elem_loads[0] = {&e, b_->last_instr};
  }
  return r;
}

Val Compiler::unary(const UnaryExpr& u, const Type* expected) {
  Val v = expr(*u.operand, expected);
  if (!v.ok) return v;
  if (u.op == UnaryOp::Plus) return v;
  if (v.is_const && (!v.type || v.type->is_elementary())) {
    Val out = v;
    if (u.op == UnaryOp::Neg) {
      if (v.c.k == ConstV::K::Int) out.c.i = static_cast<int64_t>(0ULL - static_cast<uint64_t>(v.c.i));
      else if (v.c.k == ConstV::K::Real) out.c.r = -v.c.r;
      else {
        diags_.error("ST204", u.loc, "'-' is not applicable to " + tname(v.type));
        return bad();
      }
      if (v.type && (v.type->is_unsigned_int() || v.type->is_bitstring())) {
        diags_.error("ST204", u.loc, "cannot negate a value of unsigned type " + v.type->name);
        return bad();
      }
      return out;
    }
    // NOT of an untyped literal takes its width from the context (b := NOT 16#99 with b
    // a BYTE), as the standard types a literal where it is used.
    const Type* width = v.type;
    if (!width && v.c.k == ConstV::K::Int && expected && (expected->is_bitstring() || expected->is_integer()))
      width = expected;
    if (v.c.k == ConstV::K::Bool) out.c.i = !v.c.i;
    else if (v.c.k == ConstV::K::Int && width) {
      // NOT on a bit string: complement within its width.
      uint64_t mask = width->size >= 8 ? ~0ULL : ((1ULL << (width->size * 8)) - 1);
      out.c.i = static_cast<int64_t>(~static_cast<uint64_t>(v.c.i) & mask);
      if (width->is_integer() && !width->is_unsigned_int()) out.c.i = ~v.c.i;
      out.type = v.type ? v.type : (width->ranged ? elem(width->kind) : width);
    } else {
      diags_.error("ST204", u.loc, "NOT needs a BOOL or bit-string value");
      return bad();
    }
    return out;
  }
  const Type* t = v.type;
  if (!t) return bad();
  Slot s = v.is_const ? to_slot(v, t, u.loc) : v.slot;
  Slot d = temp_for(t);
  if (u.op == UnaryOp::Neg && opt_.dialect == Dialect::Codesys && (t->is_unsigned_int() || t->is_bitstring()) &&
      t->kind != TypeKind::Bool) {
    // CODESYS negates an unsigned value (OSCAT's `-step` with step : BYTE) in its wider
    // signed arithmetic: the result is the negative number, in the next wider signed type.
    const Type* wide = elem(t->size == 1 ? TypeKind::Int : t->size == 2 ? TypeKind::DInt : TypeKind::LInt);
    if (opt_.warnings)
      diags_.warning("ST405", u.loc, "implicit conversion from " + t->name + " to " + wide->name + " to negate it (" +
                                         canon(t->name) + "_TO_" + canon(wide->name) + ")" +
                                         (t->size == 8 ? ": values above LINT's range change" : ""));
    Slot w = temp_for(wide);
    emit(num_op(Op::NEG_I8, wide->storage()), {w, convert(s, t, wide)});
    def(w);
    Val out;
    out.type = wide;
    out.slot = w;
    return out;
  }
  if (u.op == UnaryOp::Neg) {
    if (!(t->is_numeric() || t->kind == TypeKind::Time || t->kind == TypeKind::LTime) || t->is_unsigned_int()) {
      diags_.error("ST204", u.loc, "'-' is not applicable to " + t->name);
      return bad();
    }
    emit(num_op(Op::NEG_I8, t->storage()), {d, s});
  } else {
    if (t->kind == TypeKind::Bool) emit(Op::BNOT, {d, s});
    else if (t->is_bitstring() || t->is_integer()) emit(int_op(Op::NOT_I8, t->storage()), {d, s});
    else {
      diags_.error("ST204", u.loc, "NOT is not applicable to " + t->name);
      return bad();
    }
  }
  def(d);
  Val out;
  out.type = t->ranged ? elem(t->kind) : t;
  out.slot = d;
  out.nominal = v.nominal;  // -(a + b) stays in the register
  return out;
}

// A left-associative chain (1 + 1 + ... + 1, a AND b AND ...) is a left spine as deep as
// it is long: it is walked in a loop, so that only true nesting (parentheses, operators of
// higher precedence on the right) costs stack, and that is bounded by the parser.
Val Compiler::binary(const BinaryExpr& e, const Type* expected) {
  std::vector<const BinaryExpr*> spine{&e};  // top first
  std::vector<const Type*> want{expected};   // the type each spine node's context expects
  while (spine.back()->lhs->kind == ExprKind::Binary) {
    const BinaryExpr* n = spine.back();
    want.push_back(is_cmp(n->op) ? nullptr : want.back());
    spine.push_back(static_cast<const BinaryExpr*>(n->lhs.get()));
  }
  const BinaryExpr* bottom = spine.back();
  Val l = expr(*bottom->lhs, is_cmp(bottom->op) ? nullptr : want.back());
  for (size_t k = spine.size(); k-- > 0;) {
    const BinaryExpr& n = *spine[k];
    if (!l.ok) return bad();
    if (n.op == BinaryOp::AndThen || n.op == BinaryOp::OrElse) {
      l = short_circuit(n, l);
      continue;
    }
    Val r = expr(*n.rhs, l.type && l.type->kind == TypeKind::Enum ? l.type : (is_cmp(n.op) ? nullptr : want[k]));
    if (!r.ok) return bad();
    l = combine(n.op, l, r, n.loc);
    if (l.ok && (n.op == BinaryOp::Eq || n.op == BinaryOp::Ne))
      if (auto bit = bit_of_shift(static_cast<const Expr*>(&n) == cond_top_)) l = *bit;
  }
  return l;
}

// a AND_THEN b, a OR_ELSE b (CODESYS): b is evaluated only when a does not decide the
// result, so `p <> 0 AND_THEN p^ > 0` never reads through a null pointer. `l` is a's value.
Val Compiler::short_circuit(const BinaryExpr& e, const Val& l) {
  const char* name = e.op == BinaryOp::AndThen ? "AND_THEN" : "OR_ELSE";
  if (opt_.dialect == Dialect::Iec) {
    diags_.error("ST241", e.loc, std::string(name) + " is CODESYS, not IEC 61131-3: use --dialect codesys (or AND/OR)");
    return bad();
  }
  const Type* boolean = elem(TypeKind::Bool);
  if (!l.type || l.type->kind != TypeKind::Bool) {
    diags_.error("ST204", e.lhs->loc, std::string(name) + " needs BOOL operands, not " + tname(l.type));
    return bad();
  }
  Slot d = temp(1, 1);
  Place dst = frame_place(d, boolean);
  assign(dst, l, e.lhs->loc);
  Label done = new_label();
  branch_on(l, e.lhs->loc, done, e.op == BinaryOp::OrElse);
  Val r = expr(*e.rhs, boolean);
  if (!r.ok) return bad();
  if (!r.type || r.type->kind != TypeKind::Bool) {
    diags_.error("ST204", e.rhs->loc, std::string(name) + " needs BOOL operands, not " + tname(r.type));
    return bad();
  }
  assign(dst, r, e.rhs->loc);
  bind(done);
  Val v;
  v.type = boolean;
  v.slot = d;
  return v;
}

namespace {
// Whether an integer value lies in an integer type's range (types of 1 to 4 bytes).
bool int_fits(const Type* t, int64_t v) {
  const int bits = static_cast<int>(t->size) * 8;
  if (t->is_unsigned_int()) return v >= 0 && v < (int64_t{1} << bits);
  return v >= -(int64_t{1} << (bits - 1)) && v < (int64_t{1} << (bits - 1));
}
}  // namespace

Val Compiler::combine(BinaryOp op, const Val& l, const Val& r, SourceLoc loc) {
  // The operator and where it stands (named time functions pass their call's location).
  const struct {
    BinaryOp op;
    SourceLoc loc;
  } e{op, loc};
  if (l.is_const && !l.type && r.type && r.type->kind == TypeKind::Enum) {
    diags_.error("ST204", e.loc, "cannot compare an integer with enumeration " + r.type->name);
    return bad();
  }
  auto op_error = [&]() {
    diags_.error("ST204", e.loc, std::string("operator ") + op_text(e.op) + " is not applicable to " + tname(l.type) + " and " + tname(r.type));
    return bad();
  };
  // Constant folding (untyped or typed elementary constants).
  if (l.is_const && r.is_const && l.c.k != ConstV::K::Str && r.c.k != ConstV::K::Str &&
      (!l.type || (l.type->is_elementary() && !l.type->is_time_like())) &&
      (!r.type || (r.type->is_elementary() && !r.type->is_time_like()))) {
    const Type* t = nullptr;
    if (l.type && r.type) {
      t = common_type(*tt_, l.type, r.type);
      if (!t && !(l.type->is_time_like() || r.type->is_time_like())) return op_error();
    } else {
      t = l.type ? l.type : r.type;
    }
    if (e.op == BinaryOp::Pow && (l.c.k == ConstV::K::Str)) return op_error();
    std::string err;
    auto c = fold_binary(e.op, l.c, r.c, &err);
    if (!c) {
      diags_.error(err.find("zero") != std::string::npos ? "ST217" : "ST204", e.loc, err);
      return bad();
    }
    Val v;
    v.is_const = true;
    v.c = *c;
    if (c->k == ConstV::K::Bool) v.type = elem(TypeKind::Bool);
    else if (e.op == BinaryOp::Pow) v.type = (t && t->kind == TypeKind::Real) ? t : (t ? elem(TypeKind::LReal) : nullptr);
    else if (c->k == ConstV::K::Real && t && !t->is_real()) v.type = elem(TypeKind::LReal);
    else v.type = t;
    if (v.type && v.type->is_elementary() && !v.type->is_real() && v.c.k == ConstV::K::Int) {
      std::vector<uint8_t> buf(v.type->size);
      if (!write_const(buf.data(), v.type, v.c, e.loc)) return bad();
    }
    return v;
  }
  // Types of the operation.
  const Type* lt = l.type ? l.type : nullptr;
  const Type* rt = r.type ? r.type : nullptr;
  if (lt && lt->kind == TypeKind::Enum && rt && rt->kind == TypeKind::Enum && lt != rt) return op_error();
  // CODESYS computes integers in at least 32 bits: `x * 60000` with x an INT is done in
  // DINT, where IEC 61131-3 types the literal as INT and it does not fit.
  if (opt_.dialect == Dialect::Codesys && !is_logic(e.op)) {
    const bool l_lit = !l.type && l.is_const && l.c.k == ConstV::K::Int;
    const bool r_lit = !r.type && r.is_const && r.c.k == ConstV::K::Int;
    const Type* other = l_lit ? rt : r_lit ? lt : nullptr;
    const int64_t value = l_lit ? l.c.i : r.c.i;
    if (other && other->is_integer() && other->size < 8 && !int_fits(other, value)) {
      const Type* wide = elem(int_fits(elem(TypeKind::DInt), value) ? TypeKind::DInt : TypeKind::LInt);
      if (opt_.warnings)
        diags_.warning("ST405", e.loc, fmt::format("implicit conversion from {} to {}: the literal {} does not fit {}, so the "
                                                   "operation is done in {} ({}_TO_{})",
                                                   other->name, wide->name, value, other->name, wide->name, canon(other->name),
                                                   canon(wide->name)));
      (l_lit ? lt : rt) = wide;
    }
  }
  if (!lt) lt = (rt && (rt->is_numeric() || rt->is_bitstring())) ? rt : (rt && rt->is_time_like() ? elem(TypeKind::LInt) : default_type(l.c));
  if (!rt) rt = (lt->is_numeric() || lt->is_bitstring()) ? lt : (lt->is_time_like() ? elem(TypeKind::LInt) : default_type(r.c));
  if (l.is_const && !l.type && l.c.k == ConstV::K::Real && !lt->is_real()) lt = elem(TypeKind::LReal);
  if (r.is_const && !r.type && r.c.k == ConstV::K::Real && !rt->is_real()) rt = elem(TypeKind::LReal);

  auto emit_bin = [&](Op i8op, const Type* t, Slot a, Slot b, const Type* result) {
    Slot d = temp_for(result);
    if (e.op == BinaryOp::Div || e.op == BinaryOp::Mod) mark(e.loc);
    emit(num_op(i8op, t->storage()), {d, a, b});
    def(d);
    Val v;
    v.type = result;
    v.slot = d;
    return v;
  };
  auto operand = [&](const Val& v, const Type* t) -> Slot {
    if (v.is_const && v.type && v.type->is_time_like()) return konst(t, v.c, e.loc);
    if (v.is_const) {
      Val c = coerce(v.type ? v : Val{nullptr, true, true, v.c, {}}, t, e.loc, nullptr);
      if (!c.ok) return Slot{};
      return konst(t, v.c.k == ConstV::K::Real && !t->is_real() ? v.c : v.c, e.loc);
    }
    return convert(v.slot, v.type, t);
  };

  // Time arithmetic.
  if (lt->is_time_like() || rt->is_time_like()) {
    TypeKind lk = lt->kind, rk = rt->kind;
    auto is_dur = [](TypeKind k) { return k == TypeKind::Time || k == TypeKind::LTime; };
    const Type* result = nullptr;
    // CODESYS's LTIME counts unsigned: compared and divided as a ULINT (sums are the same bits).
    const Type* wide = lt->unsigned_count || rt->unsigned_count ? elem(TypeKind::ULInt) : elem(TypeKind::LInt);
    if (is_cmp(e.op)) {
      if (lk != rk && !(is_dur(lk) && is_dur(rk))) return op_error();
      Slot a = operand(l, wide->kind == TypeKind::ULInt ? wide : lt), b = operand(r, wide->kind == TypeKind::ULInt ? wide : lt);
      static const Op kCmp[] = {Op::LT_I8, Op::GT_I8, Op::LE_I8, Op::GE_I8, Op::EQ_I8, Op::NE_I8};
      return emit_bin(kCmp[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)], wide, a, b, elem(TypeKind::Bool));
    }
    if (e.op == BinaryOp::Add) {
      if (is_dur(lk) && is_dur(rk)) result = lk == TypeKind::LTime || rk == TypeKind::LTime ? elem(TypeKind::LTime) : elem(TypeKind::Time);
      else if ((lk == TypeKind::TimeOfDay || lk == TypeKind::DateTime) && is_dur(rk)) result = lt;
      else return op_error();
      return emit_bin(Op::ADD_I8, elem(TypeKind::LInt), operand(l, elem(TypeKind::LInt)), operand(r, elem(TypeKind::LInt)), result);
    }
    if (e.op == BinaryOp::Sub) {
      if (is_dur(lk) && is_dur(rk)) result = lk == TypeKind::LTime || rk == TypeKind::LTime ? elem(TypeKind::LTime) : elem(TypeKind::Time);
      else if ((lk == TypeKind::TimeOfDay || lk == TypeKind::DateTime) && is_dur(rk)) result = lt;
      else if (lk == rk && (lk == TypeKind::TimeOfDay || lk == TypeKind::DateTime || lk == TypeKind::Date)) result = elem(TypeKind::Time);
      else return op_error();
      return emit_bin(Op::SUB_I8, elem(TypeKind::LInt), operand(l, elem(TypeKind::LInt)), operand(r, elem(TypeKind::LInt)), result);
    }
    if ((e.op == BinaryOp::Mul || e.op == BinaryOp::Div) && is_dur(lk) && (rt->is_numeric() || (!r.type && r.is_const))) {
      if (rt->is_real() || (r.is_const && r.c.k == ConstV::K::Real)) {
        Slot a = convert(operand(l, wide), wide, elem(TypeKind::LReal));
        Slot b = operand(r, elem(TypeKind::LReal));
        Val x = emit_bin(e.op == BinaryOp::Mul ? Op::MUL_I8 : Op::DIV_I8, elem(TypeKind::LReal), a, b, elem(TypeKind::LReal));
        Val out;
        out.type = lt;
        out.slot = convert(x.slot, elem(TypeKind::LReal), wide);
        return out;
      }
      Slot a = operand(l, wide), b = operand(r, wide);
      return emit_bin(e.op == BinaryOp::Mul ? Op::MUL_I8 : Op::DIV_I8, wide, a, b, lt);
    }
    if (e.op == BinaryOp::Mul && is_dur(rk) && lt->is_integer()) {
      return emit_bin(Op::MUL_I8, elem(TypeKind::LInt), operand(l, elem(TypeKind::LInt)), operand(r, elem(TypeKind::LInt)), rt);
    }
    return op_error();
  }

  // Strings: comparisons only.
  if (lt->is_string() || rt->is_string()) {
    if (!lt->is_string() || !rt->is_string() || !is_cmp(e.op)) return op_error();
    // A STRING compared with a WSTRING is converted to one (as the assignment would).
    const bool wide = lt->kind == TypeKind::WString || rt->kind == TypeKind::WString;
    Slot a = string_slot(l, wide, e.loc);
    Slot b = string_slot(r, wide, e.loc);
    Slot d = temp(1, 1);
    static const uint32_t kRel[] = {2, 4, 3, 5, 0, 1};  // Lt Gt Le Ge Eq Ne -> SCMP relation
    emit(wide ? Op::WSCMP : Op::SCMP, {d, a, b, kRel[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)]});
    def(d);
    Val v;
    v.type = elem(TypeKind::Bool);
    v.slot = d;
    return v;
  }

  // CODESYS pointer arithmetic: a POINTER plus or minus a number of bytes is a POINTER.
  if (opt_.dialect == Dialect::Codesys && (e.op == BinaryOp::Add || e.op == BinaryOp::Sub)) {
    auto pointer = [&](const Type* t) { return t && t->kind == TypeKind::Ref && !t->implicit_deref; };
    auto number = [&](const Val& v) { return v.type ? v.type->is_integer() || v.type->is_bitstring() : v.c.k == ConstV::K::Int; };
    const bool left = pointer(lt) && number(r), right = e.op == BinaryOp::Add && pointer(rt) && number(l);
    if (left || right) {
      const Type* udint = elem(TypeKind::UDInt);
      Val p = left ? l : r, n = left ? r : l;
      p.type = udint;  // the address, as the number it is
      Slot a = operand(p, udint), b = operand(n, udint);
      return emit_bin(e.op == BinaryOp::Add ? Op::ADD_I8 : Op::SUB_I8, udint, a, b, left ? lt : rt);
    }
  }
  // CODESYS orders pointers as the addresses they are: with another pointer or a number.
  if (opt_.dialect == Dialect::Codesys && is_cmp(e.op)) {
    auto pointer = [&](const Type* t) { return t && t->kind == TypeKind::Ref && !t->implicit_deref; };
    auto number = [&](const Val& v) { return v.type ? v.type->is_integer() || v.type->is_bitstring() : v.c.k == ConstV::K::Int; };
    if ((pointer(lt) && (pointer(rt) || number(r))) || (pointer(rt) && number(l))) {
      const Type* udint = elem(TypeKind::UDInt);
      if (opt_.warnings && e.op != BinaryOp::Eq && e.op != BinaryOp::Ne)
        diags_.warning("ST405", e.loc, std::string("pointer compared as an address (UDINT) with ") + op_text(e.op));
      Val a = l, b = r;
      if (pointer(lt)) a.type = udint;
      if (pointer(rt)) b.type = udint;
      Slot x = operand(a, udint), y = operand(b, udint);
      static const Op kCmp[] = {Op::LT_I8, Op::GT_I8, Op::LE_I8, Op::GE_I8, Op::EQ_I8, Op::NE_I8};
      return emit_bin(kCmp[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)], udint, x, y, elem(TypeKind::Bool));
    }
  }
  // References and interfaces: equality only.
  if (lt->kind == TypeKind::Ref || rt->kind == TypeKind::Ref || lt->kind == TypeKind::Interface || rt->kind == TypeKind::Interface ||
      lt == null_type_ || rt == null_type_) {
    if (e.op != BinaryOp::Eq && e.op != BinaryOp::Ne) return op_error();
    Slot a = l.is_const ? konst_u32(0) : l.slot;
    Slot b = r.is_const ? konst_u32(0) : r.slot;
    return emit_bin(e.op == BinaryOp::Eq ? Op::EQ_I8 : Op::NE_I8, elem(TypeKind::UDInt), a, b, elem(TypeKind::Bool));
  }

  // Enumerations: comparisons.
  if (lt->kind == TypeKind::Enum || rt->kind == TypeKind::Enum) {
    if (lt != rt || !is_cmp(e.op)) return op_error();
    Slot a = l.is_const ? konst(lt, l.c, e.loc) : l.slot;
    Slot b = r.is_const ? konst(rt, r.c, e.loc) : r.slot;
    static const Op kCmp[] = {Op::LT_I8, Op::GT_I8, Op::LE_I8, Op::GE_I8, Op::EQ_I8, Op::NE_I8};
    return emit_bin(kCmp[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)], lt, a, b, elem(TypeKind::Bool));
  }

  if (lt->kind == TypeKind::Bool && rt->kind == TypeKind::Bool) {
    Slot a = operand(l, lt), b = operand(r, rt);
    if (is_logic(e.op)) {
      Slot d = temp(1, 1);
      emit(e.op == BinaryOp::And ? Op::BAND : e.op == BinaryOp::Or ? Op::BOR : Op::BXOR, {d, a, b});
      def(d);
      Val v;
      v.type = lt;
      v.slot = d;
      return v;
    }
    if (is_cmp(e.op)) {
      static const Op kCmp[] = {Op::LT_I8, Op::GT_I8, Op::LE_I8, Op::GE_I8, Op::EQ_I8, Op::NE_I8};
      return emit_bin(kCmp[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)], elem(TypeKind::USInt), a, b, elem(TypeKind::Bool));
    }
    return op_error();
  }

  const Type* t = common_type(*tt_, lt, rt);
  if (!t && opt_.dialect == Dialect::Codesys) t = dialect_common_type(lt, rt);
  if (!t) {
    // IEC forbids mixing, say, DINT and REAL implicitly; say what to write instead.
    diags_.error("ST204", e.loc, std::string("operator ") + op_text(e.op) + " mixes " + lt->name + " and " + rt->name +
                                     " which have no common type; convert one side explicitly");
    return bad();
  }
  if (t->kind == TypeKind::Bool) t = elem(TypeKind::Byte);
  // CODESYS computes integers in registers of at least 32 bits and cuts a result only when
  // it is stored (or converted): `usi - 1 <> 255` is TRUE for usi = 0, `SHR(m - 4, 1)` shifts
  // the 32-bit -1. An operation on narrower types is done in DINT (UDINT when unsigned) and
  // its result remembers its IEC type (Val::nominal).
  const Type* nominal = nullptr;
  if (opt_.dialect == Dialect::Codesys && (t->is_integer() || t->is_bitstring())) {
    // An untyped literal takes the IEC type of the other side (`b * 10 - 48` stays a BYTE).
    const Type* ln = l.nominal ? l.nominal : (!l.type && l.is_const ? nullptr : lt);
    const Type* rn = r.nominal ? r.nominal : (!r.type && r.is_const ? nullptr : rt);
    if (!ln) ln = rn;
    if (!rn) rn = ln;
    const Type* iec = ln && rn ? common_type(*tt_, ln, rn) : nullptr;
    if (!iec && ln && rn) iec = dialect_common_type(ln, rn);
    // AND, OR and XOR cannot overflow: only an operand already in a register widens them.
    const bool widen = !is_logic(e.op) || l.nominal || r.nominal;
    if (iec && (iec->is_integer() || iec->is_bitstring()) && iec->size >= 4 && (l.nominal || r.nominal)) {
      t = iec;  // a register met a 32/64-bit operand: its bits are read in that type
    } else if (widen && !is_cmp(e.op) && iec && (iec->is_integer() || iec->is_bitstring()) && iec->size < 4) {
      nominal = iec;
      if (t->size < 4) t = elem(iec->is_unsigned_int() || iec->is_bitstring() ? TypeKind::UDInt : TypeKind::DInt);
    }
  }
  auto in_register = [&](Val v) {
    v.nominal = nominal;
    return v;
  };
  // Division by a constant (below) reads the divisor from its operands: no pool slot for it
  // (a FUNCTION copies its pool into its frame on every call).
  const bool by_const = (e.op == BinaryOp::Div || e.op == BinaryOp::Mod) && r.is_const && r.c.k == ConstV::K::Int &&
                        (t->storage() == Storage::I16 || t->storage() == Storage::I32) && r.c.i != 0 && r.c.i != 1 &&
                        r.c.i != -1 && r.c.i >= INT32_MIN + 1 && r.c.i <= INT32_MAX;
  Slot a = operand(l, t), b;
  if (by_const) (void)coerce(r.type ? r : Val{nullptr, true, true, r.c, {}}, t, e.loc, nullptr);  // its diagnostics
  else b = operand(r, t);
  if (is_cmp(e.op)) {
    static const Op kCmp[] = {Op::LT_I8, Op::GT_I8, Op::LE_I8, Op::GE_I8, Op::EQ_I8, Op::NE_I8};
    return emit_bin(kCmp[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)], t, a, b, elem(TypeKind::Bool));
  }
  if (is_logic(e.op)) {
    if (t->is_real()) return op_error();
    Op bitop = e.op == BinaryOp::And ? Op::AND_I8 : e.op == BinaryOp::Or ? Op::OR_I8 : Op::XOR_I8;
    if (auto v = shifted_operand(bitop, a, b, t)) return in_register(*v);
    Slot d = temp_for(t);
    emit(int_op(bitop, t->storage()), {d, a, b});
    def(d);
    Val v;
    v.type = t;
    v.slot = d;
    return in_register(v);
  }
  if (e.op == BinaryOp::Pow) {
    const Type* rt2 = t->kind == TypeKind::Real ? t : elem(TypeKind::LReal);
    Slot x = convert(a, t, rt2), y = convert(b, t, rt2);
    return native(rt2->kind == TypeKind::Real ? Native::EXPT_F32 : Native::EXPT_F64, rt2, {x, y});
  }
  if (!t->is_numeric() && !t->is_bitstring()) return op_error();
  // Division by a constant: multiply by a precomputed reciprocal instead of dividing.
  if (by_const) {
    const uint64_t m = ops::divk_constants(r.c.i);
    bool i16 = t->storage() == Storage::I16;
    Op divop = e.op == BinaryOp::Div ? (i16 ? Op::DIVK_I16 : Op::DIVK_I32) : (i16 ? Op::MODK_I16 : Op::MODK_I32);
    Slot d = temp_for(t);
    emit(divop, {d, a, static_cast<uint32_t>(m), static_cast<uint32_t>(m >> 32), static_cast<uint32_t>(static_cast<int32_t>(r.c.i))});
    def(d);
    Val v;
    v.type = t;
    v.slot = d;
    return in_register(v);
  }
  switch (e.op) {
    case BinaryOp::Add:
      if (t->storage() == Storage::I32)
        if (auto v = multiply_add(a, b, t)) return in_register(*v);
      return in_register(emit_bin(Op::ADD_I8, t, a, b, t));
    case BinaryOp::Sub: return in_register(emit_bin(Op::SUB_I8, t, a, b, t));
    case BinaryOp::Mul: return in_register(emit_bin(Op::MUL_I8, t, a, b, t));
    case BinaryOp::Div: return in_register(emit_bin(Op::DIV_I8, t, a, b, t));
    case BinaryOp::Mod: {
      if (t->is_real()) return op_error();
      Slot d = temp_for(t);
      mark(e.loc);
      // x MOD 0: IEC 61131-3 defines 0; CODESYS and TwinCAT stop the task with a
      // division-by-zero exception, which the VM's trap reproduces.
      Op mod = opt_.dialect == Dialect::Iec ? Op::MODZ_I8 : Op::MOD_I8;
      emit(int_op(mod, t->storage()), {d, a, b});
      def(d);
      Val v;
      v.type = t;
      v.slot = d;
      return in_register(v);
    }
    default: return op_error();
  }
}

// One bit of a word as a BOOL: "SHRD s, x, n; AND m, s, 1; EQ/NE c, m, K" (K 0 or 1, the
// three instructions just emitted one after the other, in the same line and block, each
// reading the temporary the one before defined, all on the same integer type) is one
// GETBITD c, x, n, inverted for "= 0" and "<> 1". The bit is what SHR and AND give: 0
// when n is negative or not below the width. Nothing changed when it does not apply. (A
// comparison with 0 that is a whole IF/WHILE condition is left to test_bits: SHRD and
// one JTZ, two instructions as well.)
std::optional<Val> Compiler::bit_of_shift(bool whole_condition) {
  auto& code = b_->code;
  const uint32_t cmp_at = b_->last_instr, and_at = b_->prev_instr, shr_at = b_->prev2_instr;
  if (cmp_at >= code.size() || and_at == UINT32_MAX || shr_at == UINT32_MAX || shr_at + 4 != and_at ||
      and_at + 4 != cmp_at || cmp_at + 4 != code.size() || shr_at < b_->last_label_pos)
    return std::nullopt;
  if (!b_->lines.empty() && b_->lines.back().first > shr_at) return std::nullopt;
  // The type, from the comparison: EQ_T or NE_T over an integer storage type T.
  constexpr uint32_t num_stride = static_cast<uint32_t>(Op::ADD_I16) - static_cast<uint32_t>(Op::ADD_I8);
  constexpr uint32_t int_stride = static_cast<uint32_t>(Op::MOD_I16) - static_cast<uint32_t>(Op::MOD_I8);
  const uint32_t cmp = code[cmp_at];
  uint32_t ti = 8;
  bool eq = false;
  for (uint32_t k = 0; k < 8; ++k) {
    if (cmp == static_cast<uint32_t>(Op::EQ_I8) + k * num_stride) ti = k, eq = true;
    if (cmp == static_cast<uint32_t>(Op::NE_I8) + k * num_stride) ti = k;
  }
  if (ti == 8 || code[and_at] != static_cast<uint32_t>(Op::AND_I8) + ti * int_stride ||
      code[shr_at] != static_cast<uint32_t>(Op::SHRD_I8) + ti * int_stride)
    return std::nullopt;
  static constexpr uint32_t kWidth[] = {1, 2, 4, 8, 1, 2, 4, 8};
  // The value of the constant at an operand word (nullopt: not a constant 0 or 1).
  auto bit_const = [&](uint32_t word) -> std::optional<uint32_t> {
    std::optional<uint64_t> v = const_at(word, kWidth[ti]);
    if (!v || *v > 1) return std::nullopt;
    return static_cast<uint32_t>(*v);
  };
  auto temp_at = [&](uint32_t word, uint32_t def_word) {
    return kind_at(word) == SK::Temp && kind_at(def_word) == SK::Temp && code[word] == code[def_word];
  };
  // AND m, s, 1 (either order) reading SHRD's s; the comparison reading m and K (either order).
  const bool s_first = temp_at(and_at + 2, shr_at + 1) && bit_const(and_at + 3) == 1u;
  const bool s_second = temp_at(and_at + 3, shr_at + 1) && bit_const(and_at + 2) == 1u;
  if (!s_first && !s_second) return std::nullopt;
  std::optional<uint32_t> k;
  if (temp_at(cmp_at + 2, and_at + 1)) k = bit_const(cmp_at + 3);
  else if (temp_at(cmp_at + 3, and_at + 1)) k = bit_const(cmp_at + 2);
  if (!k || (whole_condition && *k == 0)) return std::nullopt;
  // "= 1" and "<> 0" are the bit itself; "= 0" and "<> 1" its inverse.
  const uint32_t invert = (eq ? 1u : 0u) ^ *k;
  auto [x, n] = unemit(shr_at);
  Slot d = temp(1, 1);
  emit(int_op(Op::GETBITD_I8, static_cast<Storage>(ti)), {d, x, n, invert});
  def(d);
  Val v;
  v.type = elem(TypeKind::Bool);
  v.slot = d;
  return v;
}

// A DINT sum one of whose operands is the product just computed ("MUL_I32 p, x, y" the
// last instruction, in the same line and block, defining the temporary p): one MADD_I32
// computes x * y + z, wrapping as the two do. Nothing changed when it does not apply.
std::optional<Val> Compiler::multiply_add(Slot a, Slot b, const Type* t) {
  auto& code = b_->code;
  const uint32_t at = b_->last_instr;
  if (at >= code.size() || code[at] != static_cast<uint32_t>(Op::MUL_I32) || b_->last_def_pos != at || b_->last_label_pos > at)
    return std::nullopt;
  if (!b_->lines.empty() && b_->lines.back().first > at) return std::nullopt;
  const Slot p = b_->last_def;
  auto is_p = [&](Slot s) { return s.kind == SK::Temp && p.kind == SK::Temp && s.off == p.off; };
  if (is_p(a) == is_p(b)) return std::nullopt;
  const Slot z = is_p(a) ? b : a;
  auto [x, y] = unemit(at);
  Slot d = temp_for(t);
  emit(Op::MADD_I32, {d, x, y, z});
  def(d);
  Val v;
  v.type = t;
  v.slot = d;
  return v;
}

// A bitwise AND, OR or XOR one of whose operands is the shift just computed ("SHL_T s, x,
// n" or SHR_T the last instruction, in the same line and block, defining the temporary s,
// with a constant count 0 < n < width and T the operation's own type): one instruction
// computes "other OP (x << n)" (ANDSHL_T, ..., XORSHR_T, the count an immediate), as a
// barrel shifter does. CRCs, LFSRs, parities and bit packing are made of these. Nothing
// changed when it does not apply (a count from a variable, 0 or the width or more).
std::optional<Val> Compiler::shifted_operand(Op bitop, Slot a, Slot b, const Type* t) {
  auto& code = b_->code;
  const uint32_t at = b_->last_instr;
  if (at >= code.size() || b_->last_def_pos != at || b_->last_label_pos > at) return std::nullopt;
  if (!b_->lines.empty() && b_->lines.back().first > at) return std::nullopt;
  const Storage st = t->storage();
  if (!(t->is_integer() || t->is_bitstring()) || t->kind == TypeKind::Bool || storage_index(st) >= 8) return std::nullopt;
  const bool shl = code[at] == static_cast<uint32_t>(int_op(Op::SHL_I8, st));
  if (!shl && code[at] != static_cast<uint32_t>(int_op(Op::SHR_I8, st))) return std::nullopt;
  const Slot s = b_->last_def;
  auto is_s = [&](Slot x) { return x.kind == SK::Temp && s.kind == SK::Temp && x.off == s.off; };
  if (is_s(a) == is_s(b)) return std::nullopt;
  const std::optional<uint64_t> n = const_at(at + 3, 8);  // the count, a ULINT
  static constexpr uint64_t kBits[] = {8, 16, 32, 64, 8, 16, 32, 64};
  if (!n || *n == 0 || *n >= kBits[storage_index(st)]) return std::nullopt;
  const Slot other = is_s(a) ? b : a;
  const Arg x = unemit(at).first;
  static constexpr Op kFused[3][2] = {{Op::ANDSHR_I8, Op::ANDSHL_I8}, {Op::ORSHR_I8, Op::ORSHL_I8}, {Op::XORSHR_I8, Op::XORSHL_I8}};
  const int row = bitop == Op::AND_I8 ? 0 : bitop == Op::OR_I8 ? 1 : 2;
  Slot d = temp_for(t);
  emit(int_op(kFused[row][shl ? 1 : 0], st), {d, other, x, static_cast<uint32_t>(*n)});
  def(d);
  Val v;
  v.type = t;
  v.slot = d;
  return v;
}

// The type CODESYS computes a mixed operation in (REAL * BYTE, INT + UDINT, WORD AND
// INT): the real type when one side is real (LREAL when either is), else an integer wide
// enough for both (signed when either is signed, one size up when the unsigned side is
// as wide). Null when a side is no number or bit string.
const Type* Compiler::dialect_common_type(const Type* a, const Type* b) const {
  auto number = [](const Type* t) { return t->is_numeric() || t->is_bitstring(); };
  if (!number(a) || !number(b)) return nullptr;
  if (a->is_real() || b->is_real())
    return elem(a->kind == TypeKind::LReal || b->kind == TypeKind::LReal ? TypeKind::LReal : TypeKind::Real);
  bool sa = a->is_integer() && !a->is_unsigned_int(), sb = b->is_integer() && !b->is_unsigned_int();
  uint32_t w = std::max(a->size, b->size);
  if (sa == sb) {
    static constexpr TypeKind kS[] = {TypeKind::SInt, TypeKind::Int, TypeKind::DInt, TypeKind::LInt};
    static constexpr TypeKind kU[] = {TypeKind::USInt, TypeKind::UInt, TypeKind::UDInt, TypeKind::ULInt};
    uint32_t i = w == 1 ? 0 : w == 2 ? 1 : w == 4 ? 2 : 3;
    return elem(sa ? kS[i] : kU[i]);
  }
  uint32_t unsigned_w = sa ? b->size : a->size;
  if (unsigned_w >= w && w < 8) w *= 2;
  return elem(w == 1 ? TypeKind::SInt : w == 2 ? TypeKind::Int : w == 4 ? TypeKind::DInt : TypeKind::LInt);
}

Val Compiler::cond(const Expr& e) {
  const Expr* outer = cond_top_;
  cond_top_ = &e;  // a bit test that is the whole condition stays one jump (test_bits)
  Val v = expr(e, elem(TypeKind::Bool));
  cond_top_ = outer;
  if (!v.ok) return v;
  if (!v.type || v.type->kind != TypeKind::Bool) {
    diags_.error("ST205", e.loc, "a condition must be BOOL, not " + tname(v.type));
    return bad();
  }
  return v;
}

}  // namespace plcfi::st::detail
