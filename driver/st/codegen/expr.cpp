// Expressions and places: type checking with IEC implicit widening, constant folding,
// and translation to typed VM instructions.
#include <cmath>
#include <cstring>

#include "compiler_impl.hpp"

namespace plcfi::st::detail {

namespace {
bool is_cmp(BinaryOp op) {
  return op == BinaryOp::Lt || op == BinaryOp::Gt || op == BinaryOp::Le || op == BinaryOp::Ge ||
         op == BinaryOp::Eq || op == BinaryOp::Ne;
}
bool is_logic(BinaryOp op) { return op == BinaryOp::And || op == BinaryOp::Or || op == BinaryOp::Xor; }
const char* op_text(BinaryOp op) {
  switch (op) {
    case BinaryOp::Pow: return "**";
    case BinaryOp::Mul: return "*";
    case BinaryOp::Div: return "/";
    case BinaryOp::Mod: return "MOD";
    case BinaryOp::Add: return "+";
    case BinaryOp::Sub: return "-";
    case BinaryOp::Lt: return "<";
    case BinaryOp::Gt: return ">";
    case BinaryOp::Le: return "<=";
    case BinaryOp::Ge: return ">=";
    case BinaryOp::Eq: return "=";
    case BinaryOp::Ne: return "<>";
    case BinaryOp::And: return "AND";
    case BinaryOp::Xor: return "XOR";
    case BinaryOp::Or: return "OR";
  }
  return "?";
}
std::string tname(const Type* t) { return t ? t->name : "an untyped literal"; }
}  // namespace

std::optional<ConstV> fold_binary(BinaryOp op, const ConstV& l, const ConstV& r, std::string* err) {
  if (l.k == ConstV::K::Str || r.k == ConstV::K::Str) {
    if (l.k == r.k && (op == BinaryOp::Eq || op == BinaryOp::Ne)) {
      ConstV c;
      c.k = ConstV::K::Bool;
      c.i = (l.s == r.s) == (op == BinaryOp::Eq);
      return c;
    }
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
    c.k = ConstV::K::Bool;
    switch (op) {
      case BinaryOp::Lt: c.i = x < y; return c;
      case BinaryOp::Gt: c.i = x > y; return c;
      case BinaryOp::Le: c.i = x <= y; return c;
      case BinaryOp::Ge: c.i = x >= y; return c;
      case BinaryOp::Eq: c.i = x == y; return c;
      case BinaryOp::Ne: c.i = x != y; return c;
      default: *err = std::string(op_text(op)) + " is not applicable to REAL values"; return std::nullopt;
    }
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
  c.k = ConstV::K::Bool;
  switch (op) {
    case BinaryOp::Lt: c.i = x < y; return c;
    case BinaryOp::Gt: c.i = x > y; return c;
    case BinaryOp::Le: c.i = x <= y; return c;
    case BinaryOp::Ge: c.i = x >= y; return c;
    case BinaryOp::Eq: c.i = x == y; return c;
    case BinaryOp::Ne: c.i = x != y; return c;
    default: *err = "operator not applicable in a constant expression"; return std::nullopt;
  }
}

// ------------------------------------------------------------------ names

const Symbol* Compiler::lookup(const std::string& key) const {
  if (b_) {
    auto it = b_->locals.find(key);
    if (it != b_->locals.end()) return it->second;
  }
  auto g = globals_.find(key);
  if (g != globals_.end()) return g->second;
  auto e = enum_syms_.find(key);
  if (e != enum_syms_.end()) return e->second.get();
  auto ev = enum_values_.find(key);
  if (ev != enum_values_.end() && ev->second.size() == 1) {
    auto s = std::make_unique<Symbol>();
    s->kind = SymKind::EnumValue;
    s->type = ev->second[0];
    for (const auto& [n, v] : ev->second[0]->enum_values)
      if (canon(n) == key) {
        s->name = n;
        s->enum_value = v;
      }
    auto* raw = s.get();
    enum_syms_[key] = std::move(s);
    return raw;
  }
  return nullptr;
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

Place Compiler::symbol_place(const Symbol* s, SourceLoc loc) {
  Place p;
  p.type = s->type;
  p.sym = s;
  p.readonly = s->constant;
  switch (s->where) {
    case Where::Frame: p.k = Place::K::Frame; p.off = s->offset; break;
    case Where::Abs: p.k = Place::K::Abs; p.off = s->offset; break;
    case Where::AbsBit: p.k = Place::K::AbsBit; p.off = s->offset; p.bit = s->bit; break;
    case Where::InOut:
      p.k = Place::K::Ind;
      p.ptr = Slot{s->offset, SK::Var};
      p.off = 0;
      break;
    case Where::This: {
      p.k = Place::K::Ind;
      p.ptr = Slot{8, SK::Var};
      p.off = s->offset;
      if (s->type && s->type->kind == TypeKind::Ref && s->section == VarSection::InOut) {
        // The owner's VAR_IN_OUT: load the stored address, then go through it.
        Slot ptr = temp(4, 4);
        emit(Op::LDI4, {ptr, Slot{8, SK::Var}, s->offset});
        p.ptr = ptr;
        p.off = 0;
        p.type = s->type->target;
      }
      break;
    }
  }
  (void)loc;
  return p;
}

Place Compiler::this_place(SourceLoc loc) {
  Place p;
  if (!b_ || !b_->this_type) {
    diags_.error("ST231", loc, "THIS is only available inside a function block or its methods");
    p.ok = false;
    return p;
  }
  p.type = b_->this_type;
  if (b_->is_method) {
    p.k = Place::K::Ind;
    p.ptr = Slot{8, SK::Var};
  } else {
    p.k = Place::K::Frame;
    p.off = 0;
  }
  return p;
}

// ------------------------------------------------------------------ places

Place Compiler::place(const Expr& e, bool for_write) {
  Place bad_place;
  bad_place.ok = false;
  switch (e.kind) {
    case ExprKind::Name: {
      const auto& n = static_cast<const NameExpr&>(e);
      std::string key = canon(n.name.text);
      const Symbol* s = lookup(key);
      PouInfo* self = b_ ? b_->pou : nullptr;
      if (s && s->kind == SymKind::Var) {
        if (for_write) ++sym_src(s).writes;
        else ++sym_src(s).reads;
        return symbol_place(s, e.loc);
      }
      // Inside a FUNCTION or METHOD, its own name is the result variable.
      if (self && (self->kind == PouKind::Function || self->kind == PouKind::Method) && self->result &&
          self->result->kind != TypeKind::Void &&
          (iequals(self->name, n.name.text) || (!self->property.empty() && iequals(self->property, n.name.text)))) {
        return frame_place(Slot{self->result_offset, SK::Var}, self->result);
      }
      if (s && s->kind == SymKind::EnumValue) {
        diags_.error("ST206", e.loc, "'" + n.name.text + "' is an enumeration value, not a variable");
        return bad_place;
      }
      if (pous_.count(key)) {
        diags_.error("ST223", e.loc, "'" + n.name.text + "' is a POU, not a variable");
        return bad_place;
      }
      diags_.error("ST200", e.loc, "unknown identifier '" + n.name.text + "'");
      return bad_place;
    }
    case ExprKind::DirectAddr: {
      const auto& a = static_cast<const DirectAddrExpr&>(e);
      Place p;
      TypeKind k = a.size == 'X' ? TypeKind::Bool : a.size == 'B' ? TypeKind::Byte : a.size == 'W' ? TypeKind::Word
                   : a.size == 'D' ? TypeKind::DWord : TypeKind::LWord;
      p.type = elem(k);
      bool is_bit = false;
      if (!locate(a, p.type, &p.off, &p.bit, &is_bit)) return bad_place;
      p.k = is_bit ? Place::K::AbsBit : Place::K::Abs;
      return p;
    }
    case ExprKind::Member: {
      const auto& m = static_cast<const MemberExpr&>(e);
      // GVL.x / Config.x: qualified access to a global.
      if (m.base->kind == ExprKind::Name) {
        const auto& bn = static_cast<const NameExpr&>(*m.base);
        if (!lookup(canon(bn.name.text))) {
          if (instance_paths_) {
            // Main.x in a monitor: a variable of the program instance Main.
            for (const auto& pi : app_->programs)
              if (iequals(pi.name, bn.name.text)) {
                Place inst;
                inst.k = Place::K::Abs;
                inst.type = pi.pou->type;
                inst.off = pi.addr;
                return member_place(inst, m.member, e.loc);
              }
          }
          for (const auto& g : app_->globals)
            if (iequals(g.scope, bn.name.text) && iequals(g.sym->name, m.member.text)) {
              if (for_write) ++sym_src(g.sym).writes;
              else ++sym_src(g.sym).reads;
              return symbol_place(g.sym, e.loc);
            }
        }
      }
      Place base = place(*m.base, for_write);
      if (!base.ok) return base;
      return member_place(base, m.member, e.loc);
    }
    case ExprKind::Index: {
      const auto& ix = static_cast<const IndexExpr&>(e);
      Place base = place(*ix.base, for_write);
      if (!base.ok) return base;
      return index_place(base, ix);
    }
    case ExprKind::Deref: {
      const auto& d = static_cast<const DerefExpr&>(e);
      if (d.base->kind == ExprKind::This) return this_place(e.loc);
      if (d.base->kind == ExprKind::Super) {
        Place p = this_place(e.loc);
        if (p.ok) {
          if (!b_->this_type->pou->base && !(b_->is_method && b_->pou->owner->base)) {
            diags_.error("ST231", e.loc, "SUPER needs a function block that EXTENDS another");
            p.ok = false;
          } else {
            p.type = (b_->is_method ? b_->pou->owner : b_->this_type->pou)->base->type;
          }
        }
        return p;
      }
      Val v = expr(*d.base);
      if (!v.ok) return bad_place;
      if (!v.type || v.type->kind != TypeKind::Ref) {
        diags_.error("ST232", e.loc, "'^' needs a reference (REF_TO), not " + tname(v.type));
        return bad_place;
      }
      return deref_place(v, v.type->target, e.loc);
    }
    case ExprKind::BitAccess: {
      const auto& ba = static_cast<const BitAccessExpr&>(e);
      Place base = place(*ba.base, for_write);
      if (!base.ok) return base;
      if (!base.type->is_integer() && !base.type->is_bitstring()) {
        diags_.error("ST237", e.loc, "bit access needs an integer or bit-string variable, not " + base.type->name);
        return bad_place;
      }
      if (ba.bit >= base.type->bit_width()) {
        diags_.error("ST237", e.loc, "bit " + std::to_string(ba.bit) + " does not exist in " + base.type->name);
        return bad_place;
      }
      Place p;
      p.k = Place::K::Bit;
      p.type = elem(TypeKind::Bool);
      p.bit = static_cast<uint8_t>(ba.bit);
      p.readonly = base.readonly;
      p.inner = std::make_shared<Place>(base);
      return p;
    }
    case ExprKind::Call: {
      // A function result used as a structure or array: `f(x).field`.
      Val v = expr(e);
      if (!v.ok) return bad_place;
      if (v.is_const || !v.type || v.type->kind == TypeKind::Void) {
        diags_.error("ST206", e.loc, "this call has no result to select from");
        return bad_place;
      }
      Place p = frame_place(v.slot, v.type);
      p.readonly = true;
      return p;
    }
    default:
      diags_.error("ST206", e.loc, "this expression does not denote a variable");
      return bad_place;
  }
}

Place Compiler::member_place(Place base, const Ident& member, SourceLoc loc) {
  Place bad_place;
  bad_place.ok = false;
  const Type* t = base.type;
  if (t->kind == TypeKind::Ref) {
    diags_.error("ST207", loc, "'" + t->name + "' is a reference: write '^." + member.text + "' to reach the member");
    return bad_place;
  }
  if (t->kind != TypeKind::Struct && t->kind != TypeKind::Pou) {
    diags_.error("ST207", loc, t->name + " has no members (it is not a structure or FB instance)");
    return bad_place;
  }
  const Field* f = t->field(member.text);
  if (!f && t->kind == TypeKind::Pou && t->pou) {
    // Located variables of an instance live in the I/O image.
    if (Symbol* s = t->pou->find_var(member.text); s && (s->where == Where::Abs || s->where == Where::AbsBit)) {
      ++sym_src(s).reads;
      return symbol_place(s, loc);
    }
  }
  if (!f) {
    diags_.error("ST207", member.loc, "'" + t->name + "' has no member '" + member.text + "'");
    return bad_place;
  }
  if (t->kind == TypeKind::Pou && t->pou) {
    if (Symbol* s = t->pou->find_var(member.text)) {
      SymbolSource& ss = sym_src(s);
      ++ss.reads;
      ++ss.writes;
    }
  }
  Place p = base;
  p.type = f->type;
  switch (base.k) {
    case Place::K::Frame: case Place::K::Abs: case Place::K::Ind: p.off = base.off + f->offset; break;
    case Place::K::FrameIdx:
      if (!f->type->is_elementary()) {
        // Deeper selection: go through the element's address.
        Place ind;
        ind.k = Place::K::Ind;
        ind.type = base.type;
        ind.ptr = addr_of(base, loc);
        ind.readonly = base.readonly;
        return member_place(ind, member, loc);
      }
      p.field = base.field + f->offset;
      break;
    default:
      diags_.error("ST207", loc, "member access on this expression is not supported");
      return bad_place;
  }
  // A VAR_IN_OUT member of an FB instance holds an address.
  if (f->type->kind == TypeKind::Ref && t->kind == TypeKind::Pou && t->pou) {
    Symbol* s = t->pou->find_var(member.text);
    if (s && s->where == Where::InOut) {
      Val ptr = load(p);
      return deref_place(ptr, f->type->target, loc);
    }
  }
  return p;
}

Place Compiler::index_place(Place base, const IndexExpr& e) {
  Place bad_place;
  bad_place.ok = false;
  const Type* t = base.type;
  if (t->kind != TypeKind::Array) {
    diags_.error("ST208", e.loc, "'[ ]' needs an array, not " + t->name);
    return bad_place;
  }
  if (e.indices.size() != t->dims.size()) {
    diags_.error("ST208", e.loc, t->name + " needs " + std::to_string(t->dims.size()) + " index(es), not " + std::to_string(e.indices.size()));
    return bad_place;
  }
  uint32_t esize = t->elem->size;
  // Strides per dimension (row-major).
  std::vector<uint64_t> stride(t->dims.size());
  uint64_t s = esize;
  for (size_t i = t->dims.size(); i-- > 0;) {
    stride[i] = s;
    s *= static_cast<uint64_t>(t->dims[i].hi - t->dims[i].lo + 1);
  }
  uint64_t const_disp = 0;
  std::vector<std::pair<size_t, Slot>> dyn;
  for (size_t i = 0; i < e.indices.size(); ++i) {
    Val v = expr(*e.indices[i], elem(TypeKind::DInt));
    if (!v.ok) return bad_place;
    if (v.is_const) {
      if (v.c.k != ConstV::K::Int) {
        diags_.error("ST208", e.indices[i]->loc, "an array index must be an integer");
        return bad_place;
      }
      if (v.c.i < t->dims[i].lo || v.c.i > t->dims[i].hi) {
        diags_.error("ST209", e.indices[i]->loc, "index " + std::to_string(v.c.i) + " is outside " +
                                                      std::to_string(t->dims[i].lo) + ".." + std::to_string(t->dims[i].hi));
        return bad_place;
      }
      const_disp += static_cast<uint64_t>(v.c.i - t->dims[i].lo) * stride[i];
      continue;
    }
    if (!v.type || (!v.type->is_integer() && v.type->kind != TypeKind::Enum && !v.type->is_bitstring())) {
      diags_.error("ST208", e.indices[i]->loc, "an array index must be an integer, not " + tname(v.type));
      return bad_place;
    }
    // Index arithmetic is 32-bit: a wider index (LINT, ULINT, UDINT, ...) is checked
    // against the bounds in its own type first, so a value that only fits after
    // truncation traps instead of reaching another element.
    if (v.type->is_integer() || v.type->is_bitstring()) {
      bool wide = v.type->size == 8 || (v.type->size == 4 && !v.type->is_signed());
      if (wide) {
        int64_t lo = t->dims[i].lo, hi = t->dims[i].hi;
        if (!v.type->is_signed() && lo < 0) lo = 0;
        Slot los = konst(v.type, ConstV{ConstV::K::Int, lo, 0, {}}, e.indices[i]->loc);
        Slot his = konst(v.type, ConstV{ConstV::K::Int, hi < 0 && !v.type->is_signed() ? 0 : hi, 0, {}}, e.indices[i]->loc);
        mark(e.indices[i]->loc);
        emit(int_op(Op::CHK_I8, v.type->storage()), {v.slot, los, his, 1u});
      }
    }
    dyn.emplace_back(i, convert(v.slot, v.type, elem(TypeKind::DInt)));
  }
  if (dyn.empty()) {
    Place p = base;
    p.type = t->elem;
    p.off = base.off + static_cast<uint32_t>(const_disp);
    if (base.k == Place::K::AbsBit || base.k == Place::K::Bit || base.k == Place::K::FrameIdx) return bad_place;
    return p;
  }
  // Fast path: one variable index into a frame array of scalars or of structures (whose
  // scalar fields are then reached in one instruction).
  if (dyn.size() == 1 && base.k == Place::K::Frame && t->dims.size() == 1 &&
      ((t->elem->is_elementary() && (esize == 1 || esize == 2 || esize == 4 || esize == 8)) || t->elem->kind == TypeKind::Struct ||
       t->elem->kind == TypeKind::Pou)) {
    Place p;
    p.k = Place::K::FrameIdx;
    p.type = t->elem;
    p.off = base.off;
    p.sk = base.sk;
    p.idx = dyn[0].second;
    p.lo = static_cast<int32_t>(t->dims[0].lo);
    p.count = static_cast<uint32_t>(t->dims[0].hi - t->dims[0].lo + 1);
    p.stride = t->elem->is_elementary() ? 0 : esize;
    p.readonly = base.readonly;
    return p;
  }
  Slot ptr = addr_of(base, e.loc);
  Slot cur = ptr;
  for (auto [i, idx] : dyn) {
    Slot next = temp(4, 4);
    emit(Op::ELEM, {next, cur, idx, static_cast<uint32_t>(static_cast<int32_t>(t->dims[i].lo)),
                    static_cast<uint32_t>(t->dims[i].hi - t->dims[i].lo + 1), static_cast<uint32_t>(stride[i])});
    cur = next;
  }
  Place p;
  p.k = Place::K::Ind;
  p.type = t->elem;
  p.ptr = cur;
  p.off = static_cast<uint32_t>(const_disp);
  p.readonly = base.readonly;
  return p;
}

Place Compiler::deref_place(Val ptr, const Type* target, SourceLoc loc) {
  Place p;
  p.k = Place::K::Ind;
  p.type = target;
  if (ptr.is_const) {
    p.ptr = konst_u32(static_cast<uint32_t>(ptr.c.i));
  } else {
    p.ptr = ptr.slot;
  }
  (void)loc;
  return p;
}

Slot Compiler::addr_of(const Place& p, SourceLoc loc) {
  switch (p.k) {
    case Place::K::Frame: {
      Slot t = temp(4, 4);
      emit(Op::ADDR, {t, Slot{p.off, p.sk}});
      def(t);
      return t;
    }
    case Place::K::Abs: return konst_u32(p.off);
    case Place::K::Ind: {
      if (p.off == 0) return p.ptr;
      Slot t = temp(4, 4);
      emit(Op::ADDRI, {t, p.ptr, p.off});
      def(t);
      return t;
    }
    case Place::K::FrameIdx: {
      Slot a = temp(4, 4);
      emit(Op::ADDR, {a, Slot{p.off, p.sk}});
      Slot t = temp(4, 4);
      emit(Op::ELEM, {t, a, p.idx, static_cast<uint32_t>(p.lo), p.count, p.stride ? p.stride : p.type->size});
      if (p.field == 0) return t;
      Slot f = temp(4, 4);
      emit(Op::ADDRI, {f, t, p.field});
      return f;
    }
    default:
      diags_.error("ST232", loc, "cannot take the address of a single bit");
      return konst_u32(0);
  }
}

// ------------------------------------------------------------------ load/store

Val Compiler::load(const Place& p) {
  Val v;
  v.type = p.type;
  if (!p.ok) return bad();
  if (p.k == Place::K::FrameIdx && !p.type->is_elementary()) {
    Place ind = p;
    ind.k = Place::K::Ind;
    ind.ptr = addr_of(p, SourceLoc{});
    ind.off = 0;
    return load(ind);
  }
  uint32_t size = p.type->size;
  switch (p.k) {
    case Place::K::Frame: v.slot = Slot{p.off, p.sk}; return v;
    case Place::K::Abs: {
      Slot t = temp_for(p.type);
      switch (size) {
        case 1: emit(Op::LDG1, {t, p.off}); break;
        case 2: emit(Op::LDG2, {t, p.off}); break;
        case 4: emit(Op::LDG4, {t, p.off}); break;
        case 8: emit(Op::LDG8, {t, p.off}); break;
        default: emit(Op::LDGN, {t, p.off, size}); break;
      }
      def(t);
      v.slot = t;
      return v;
    }
    case Place::K::AbsBit: {
      Slot t = temp(1, 1);
      emit(Op::LDBIT, {t, p.off, p.bit});
      def(t);
      v.slot = t;
      return v;
    }
    case Place::K::Ind: {
      Slot t = temp_for(p.type);
      switch (size) {
        case 1: emit(Op::LDI1, {t, p.ptr, p.off}); break;
        case 2: emit(Op::LDI2, {t, p.ptr, p.off}); break;
        case 4: emit(Op::LDI4, {t, p.ptr, p.off}); break;
        case 8: emit(Op::LDI8, {t, p.ptr, p.off}); break;
        default: emit(Op::LDIN, {t, p.ptr, p.off, size}); break;
      }
      def(t);
      v.slot = t;
      return v;
    }
    case Place::K::FrameIdx: {
      Slot t = temp_for(p.type);
      if (p.stride) {
        Op op = size == 1 ? Op::LDXS1 : size == 2 ? Op::LDXS2 : size == 4 ? Op::LDXS4 : Op::LDXS8;
        emit(op, {t, Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field});
      } else {
        Op op = size == 1 ? Op::LDX1 : size == 2 ? Op::LDX2 : size == 4 ? Op::LDX4 : Op::LDX8;
        emit(op, {t, Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count});
      }
      def(t);
      v.slot = t;
      return v;
    }
    case Place::K::Bit: {
      Val w = load(*p.inner);
      Slot t = temp(1, 1);
      uint32_t ws = p.inner->type->size;
      Op op = ws == 1 ? Op::GETBIT1 : ws == 2 ? Op::GETBIT2 : ws == 4 ? Op::GETBIT4 : Op::GETBIT8;
      emit(op, {t, w.slot, p.bit});
      def(t);
      v.slot = t;
      return v;
    }
  }
  return v;
}

void Compiler::store(const Place& p, Slot src) {
  const Type* t = p.type;
  if (p.k == Place::K::FrameIdx && !t->is_elementary()) {
    Place ind = p;
    ind.k = Place::K::Ind;
    ind.ptr = addr_of(p, SourceLoc{});
    ind.off = 0;
    store(ind, src);
    return;
  }
  uint32_t size = t->size;
  if (t->is_string() && p.k == Place::K::Frame) {
    emit(Op::SCPY, {Slot{p.off, p.sk}, src, t->str_len});
    return;
  }
  if (t->is_string()) {
    // Truncate to the destination's capacity in a temporary, then copy the buffer.
    Slot tmp = temp(size, 1);
    emit(Op::SCPY, {tmp, src, t->str_len});
    src = tmp;
  }
  switch (p.k) {
    case Place::K::Frame: {
      Slot dst{p.off, p.sk};
      if (dst.off == src.off && dst.kind == src.kind) return;
      if (retarget(src, dst)) return;
      if (size == 1 || size == 2 || size == 4 || size == 8) emit(mov_op(size), {dst, src});
      else emit(Op::MOVN, {dst, src, size});
      return;
    }
    case Place::K::Abs:
      switch (size) {
        case 1: emit(Op::STG1, {p.off, src}); return;
        case 2: emit(Op::STG2, {p.off, src}); return;
        case 4: emit(Op::STG4, {p.off, src}); return;
        case 8: emit(Op::STG8, {p.off, src}); return;
        default: emit(Op::STGN, {p.off, src, size}); return;
      }
    case Place::K::AbsBit: emit(Op::STBIT, {p.off, p.bit, src}); return;
    case Place::K::Ind:
      switch (size) {
        case 1: emit(Op::STI1, {p.ptr, p.off, src}); return;
        case 2: emit(Op::STI2, {p.ptr, p.off, src}); return;
        case 4: emit(Op::STI4, {p.ptr, p.off, src}); return;
        case 8: emit(Op::STI8, {p.ptr, p.off, src}); return;
        default: emit(Op::STIN, {p.ptr, p.off, src, size}); return;
      }
    case Place::K::FrameIdx: {
      if (p.stride) {
        Op op = size == 1 ? Op::STXS1 : size == 2 ? Op::STXS2 : size == 4 ? Op::STXS4 : Op::STXS8;
        emit(op, {Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field, src});
        return;
      }
      Op op = size == 1 ? Op::STX1 : size == 2 ? Op::STX2 : size == 4 ? Op::STX4 : Op::STX8;
      emit(op, {Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, src});
      return;
    }
    case Place::K::Bit: {
      uint32_t ws = p.inner->type->size;
      Op op = ws == 1 ? Op::SETBIT1 : ws == 2 ? Op::SETBIT2 : ws == 4 ? Op::SETBIT4 : Op::SETBIT8;
      if (p.inner->k == Place::K::Frame) {
        emit(op, {Slot{p.inner->off, p.inner->sk}, p.bit, src});
        return;
      }
      Val w = load(*p.inner);
      Slot tmp = temp_for(p.inner->type);
      emit(mov_op(ws), {tmp, w.slot});
      emit(op, {tmp, p.bit, src});
      store(*p.inner, tmp);
      return;
    }
  }
}

Val Compiler::coerce(const Val& v, const Type* to, SourceLoc loc, const char* what) {
  if (!v.ok || !to) return bad();
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
      (v.type->kind == TypeKind::Ref && to->kind == TypeKind::Ref && same_type(v.type, to))) {
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
  std::string hint;
  if (v.type->is_elementary() && to->is_elementary() && v.type->kind != TypeKind::Enum && to->kind != TypeKind::Enum)
    hint = "; use " + canon(v.type->name) + "_TO_" + canon(to->name) + "()";
  diags_.error("ST203", loc, "cannot convert " + v.type->name + " to " + to->name + " implicitly" +
                                 (what ? std::string(" in ") + what : "") + hint);
  return bad();
}

Slot Compiler::to_slot(const Val& v, const Type* t, SourceLoc loc) {
  if (v.is_const) return konst(t, v.c, loc);
  return convert(v.slot, v.type, t);
}

Slot Compiler::convert(Slot s, const Type* from, const Type* to) {
  if (!from || !to || from == to) return s;
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

void Compiler::assign(const Place& dst, const Val& v, SourceLoc loc) {
  if (!dst.ok || !v.ok) return;
  if (dst.readonly) {
    diags_.error("ST206", loc, dst.sym ? "'" + dst.sym->name + "' is a constant and cannot be assigned" : "this expression cannot be assigned");
    return;
  }
  Val c = coerce(v, dst.type, loc, "assignment");
  if (!c.ok) return;
  Slot s = to_slot(c, dst.type, loc);
  if (dst.type->ranged && dst.type->is_integer()) {
    Slot lo = konst(dst.type, ConstV{ConstV::K::Int, dst.type->lo, 0, {}}, loc);
    Slot hi = konst(dst.type, ConstV{ConstV::K::Int, dst.type->hi, 0, {}}, loc);
    if (!(c.is_const)) {
      mark(loc);
      emit(int_op(Op::CHK_I8, dst.type->storage()), {s, lo, hi, 0u});
    }
  }
  store(dst, s);
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
      v.type = tt_->string_type(std::max<uint32_t>(1, static_cast<uint32_t>(l.str_value.size())), l.lit == LiteralKind::WString);
      return v;
    case LiteralKind::Time: v.type = elem(l.is_long ? TypeKind::LTime : TypeKind::Time); return v;
    case LiteralKind::Date: v.type = elem(TypeKind::Date); return v;
    case LiteralKind::TimeOfDay: v.type = elem(TypeKind::TimeOfDay); return v;
    case LiteralKind::DateTime: v.type = elem(TypeKind::DateTime); return v;
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
        const VarDecl* sd = s && s->constant ? decl_of(s) : nullptr;
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
        return load(member_place(base, m.member, e.loc));
      }
      case ExprKind::DirectAddr:
      case ExprKind::Index:
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
    if (v.c.k == ConstV::K::Bool) out.c.i = !v.c.i;
    else if (v.c.k == ConstV::K::Int && v.type) {
      // NOT on a typed bit string: complement within its width.
      uint64_t mask = v.type->size >= 8 ? ~0ULL : ((1ULL << (v.type->size * 8)) - 1);
      out.c.i = static_cast<int64_t>(~static_cast<uint64_t>(v.c.i) & mask);
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
    Val r = expr(*n.rhs, l.type && l.type->kind == TypeKind::Enum ? l.type : (is_cmp(n.op) ? nullptr : want[k]));
    if (!r.ok) return bad();
    l = combine(n.op, l, r, n.loc);
  }
  return l;
}

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
    if (is_cmp(e.op)) {
      if (lk != rk && !(is_dur(lk) && is_dur(rk))) return op_error();
      Slot a = operand(l, lt), b = operand(r, lt);
      static const Op kCmp[] = {Op::LT_I8, Op::GT_I8, Op::LE_I8, Op::GE_I8, Op::EQ_I8, Op::NE_I8};
      return emit_bin(kCmp[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)], elem(TypeKind::LInt), a, b, elem(TypeKind::Bool));
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
        Slot a = convert(operand(l, elem(TypeKind::LInt)), elem(TypeKind::LInt), elem(TypeKind::LReal));
        Slot b = operand(r, elem(TypeKind::LReal));
        Val x = emit_bin(e.op == BinaryOp::Mul ? Op::MUL_I8 : Op::DIV_I8, elem(TypeKind::LReal), a, b, elem(TypeKind::LReal));
        Val out;
        out.type = lt;
        out.slot = convert(x.slot, elem(TypeKind::LReal), elem(TypeKind::LInt));
        return out;
      }
      Slot a = operand(l, elem(TypeKind::LInt)), b = operand(r, elem(TypeKind::LInt));
      return emit_bin(e.op == BinaryOp::Mul ? Op::MUL_I8 : Op::DIV_I8, elem(TypeKind::LInt), a, b, lt);
    }
    if (e.op == BinaryOp::Mul && is_dur(rk) && lt->is_integer()) {
      return emit_bin(Op::MUL_I8, elem(TypeKind::LInt), operand(l, elem(TypeKind::LInt)), operand(r, elem(TypeKind::LInt)), rt);
    }
    return op_error();
  }

  // Strings: comparisons only.
  if (lt->is_string() || rt->is_string()) {
    if (!lt->is_string() || !rt->is_string() || !is_cmp(e.op)) return op_error();
    Slot a = l.is_const ? konst(lt, l.c, e.loc) : l.slot;
    Slot b = r.is_const ? konst(rt, r.c, e.loc) : r.slot;
    Slot d = temp(1, 1);
    static const uint32_t kRel[] = {2, 4, 3, 5, 0, 1};  // Lt Gt Le Ge Eq Ne -> SCMP relation
    emit(Op::SCMP, {d, a, b, kRel[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)]});
    def(d);
    Val v;
    v.type = elem(TypeKind::Bool);
    v.slot = d;
    return v;
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
  if (!t) {
    // IEC forbids mixing, say, DINT and REAL implicitly; say what to write instead.
    diags_.error("ST204", e.loc, std::string("operator ") + op_text(e.op) + " mixes " + lt->name + " and " + rt->name +
                                     " which have no common type; convert one side explicitly");
    return bad();
  }
  if (t->kind == TypeKind::Bool) t = elem(TypeKind::Byte);
  Slot a = operand(l, t), b = operand(r, t);
  if (is_cmp(e.op)) {
    static const Op kCmp[] = {Op::LT_I8, Op::GT_I8, Op::LE_I8, Op::GE_I8, Op::EQ_I8, Op::NE_I8};
    return emit_bin(kCmp[static_cast<int>(e.op) - static_cast<int>(BinaryOp::Lt)], t, a, b, elem(TypeKind::Bool));
  }
  if (is_logic(e.op)) {
    if (t->is_real()) return op_error();
    Op bitop = e.op == BinaryOp::And ? Op::AND_I8 : e.op == BinaryOp::Or ? Op::OR_I8 : Op::XOR_I8;
    Slot d = temp_for(t);
    emit(int_op(bitop, t->storage()), {d, a, b});
    def(d);
    Val v;
    v.type = t;
    v.slot = d;
    return v;
  }
  if (e.op == BinaryOp::Pow) {
    const Type* rt2 = t->kind == TypeKind::Real ? t : elem(TypeKind::LReal);
    Slot x = convert(a, t, rt2), y = convert(b, t, rt2);
    return native(rt2->kind == TypeKind::Real ? Native::EXPT_F32 : Native::EXPT_F64, rt2, {x, y});
  }
  if (!t->is_numeric() && !t->is_bitstring()) return op_error();
  // Division by a constant: multiply by a precomputed reciprocal instead of dividing.
  if ((e.op == BinaryOp::Div || e.op == BinaryOp::Mod) && r.is_const && r.c.k == ConstV::K::Int &&
      (t->storage() == Storage::I16 || t->storage() == Storage::I32) && r.c.i != 0 && r.c.i != 1 && r.c.i != -1 &&
      r.c.i >= INT32_MIN + 1 && r.c.i <= INT32_MAX) {
    uint64_t k = static_cast<uint64_t>(r.c.i < 0 ? -r.c.i : r.c.i);
    uint64_t m = (uint64_t(1) << 63) / k + 1;
    bool i16 = t->storage() == Storage::I16;
    Op divop = e.op == BinaryOp::Div ? (i16 ? Op::DIVK_I16 : Op::DIVK_I32) : (i16 ? Op::MODK_I16 : Op::MODK_I32);
    Slot d = temp_for(t);
    emit(divop, {d, a, static_cast<uint32_t>(m), static_cast<uint32_t>(m >> 32), static_cast<uint32_t>(static_cast<int32_t>(r.c.i))});
    def(d);
    Val v;
    v.type = t;
    v.slot = d;
    return v;
  }
  switch (e.op) {
    case BinaryOp::Add: return emit_bin(Op::ADD_I8, t, a, b, t);
    case BinaryOp::Sub: return emit_bin(Op::SUB_I8, t, a, b, t);
    case BinaryOp::Mul: return emit_bin(Op::MUL_I8, t, a, b, t);
    case BinaryOp::Div: return emit_bin(Op::DIV_I8, t, a, b, t);
    case BinaryOp::Mod: {
      if (t->is_real()) return op_error();
      Slot d = temp_for(t);
      mark(e.loc);
      emit(int_op(Op::MOD_I8, t->storage()), {d, a, b});
      def(d);
      Val v;
      v.type = t;
      v.slot = d;
      return v;
    }
    default: return op_error();
  }
}

Val Compiler::cond(const Expr& e) {
  Val v = expr(e, elem(TypeKind::Bool));
  if (!v.ok) return v;
  if (!v.type || v.type->kind != TypeKind::Bool) {
    diags_.error("ST205", e.loc, "a condition must be BOOL, not " + tname(v.type));
    return bad();
  }
  return v;
}

}  // namespace plcfi::st::detail
