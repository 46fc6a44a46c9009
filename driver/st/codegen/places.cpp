// Places (lvalues): name lookup, variables, members, array elements, dereferences,
// THIS; loading from and storing to them, assignment and ADR.
#include <algorithm>
#include <optional>

#include <fmt/format.h>

#include "compiler_impl.hpp"

namespace plcfi::st::detail {

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

// A PROGRAM named from another POU (CODESYS: MAIN.n, MAIN.A_Init()): its one instance,
// laid out here when first named; the configuration's instance of it takes that memory
// (run()).
Place Compiler::program_place(PouInfo* p, SourceLoc loc) {
  Place bad;
  bad.ok = false;
  if (b_ && b_->pou == p) {
    diags_.error("ST223", loc, "inside " + p->name + ", name its variables without '" + p->name + ".'");
    return bad;
  }
  if (std::find(compiling_.begin(), compiling_.end(), p) != compiling_.end()) {
    diags_.error("ST223", loc, p->name + " and the POU that names it here name each other: one of them must reach the "
                                        "other's variables through a global variable");
    return bad;
  }
  ensure_compiled(p, loc);
  if (!p->compiled) return bad;
  auto it = program_addr_.find(p);
  if (it == program_addr_.end()) {
    const uint32_t addr = alloc(p->frame_size, 8);
    std::copy(p->type->init.begin(), p->type->init.end(), app_->init_image.begin() + addr);
    it = program_addr_.emplace(p, std::make_pair(addr, loc)).first;
  }
  Place pl;
  pl.k = Place::K::Abs;
  pl.off = it->second.first;
  pl.type = p->type;
  return pl;
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

Place Compiler::place(const Expr& e, bool for_write) { return implicit_deref(place_ref(e, for_write), e.loc); }

Place Compiler::implicit_deref(const Place& p, SourceLoc loc) {
  if (!p.ok || !p.type || p.type->kind != TypeKind::Ref || !p.type->implicit_deref) return p;
  Val ptr = load(p);
  mark(loc);  // an unbound reference traps at this use
  Place t = deref_place(ptr, p.type->target, loc);
  t.sym = p.sym;
  return t;
}

Val Compiler::reference_to_var(const Type* ref, const Expr& e) {
  Place src = place(e, false);
  if (!src.ok) return bad();
  const Type* want = ref->target;
  if (!same_type(src.type, want) && src.type != want && !derives(src.type, want)) {
    diags_.error("ST203", e.loc, ref->name + " needs a variable of type " + want->name + ", not " + src.type->name);
    return bad();
  }
  if (src.readonly) {
    diags_.error("ST232", e.loc, (src.sym ? "'" + src.sym->name + "'" : std::string("this expression")) +
                                     " is a constant: a reference to it would allow writing it");
    return bad();
  }
  Val v;
  v.type = ref;
  v.slot = addr_of(src, e.loc);
  return v;
}

bool Compiler::bind_reference(const Place& dst, const Expr& e, SourceLoc loc) {
  Val v = reference_to_var(dst.type, e);
  if (!v.ok) return false;
  assign(dst, v, loc);
  return true;
}

Place Compiler::place_ref(const Expr& e, bool for_write) {
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
      if (auto it = pous_.find(key); it != pous_.end()) {
        if (it->second->kind == PouKind::Program && opt_.dialect == Dialect::Codesys) return program_place(it->second, e.loc);
        diags_.error("ST223", e.loc, "'" + n.name.text + "' is a POU, not a variable" +
                                         (it->second->kind == PouKind::Program
                                              ? std::string(" (a program's variables by its name, ") + n.name.text +
                                                    ".x, are CODESYS: --dialect codesys)"
                                              : std::string()));
        return bad_place;
      }
      // An IL current-result variable whose declaration failed: that error was reported.
      if (n.name.text.rfind("__IL_CR", 0) == 0) return bad_place;
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
      if (opt_.dialect == Dialect::Codesys && base.type->kind == TypeKind::Ref && !base.type->implicit_deref &&
          base.type->target && ix.indices.size() == 1) {
        // CODESYS: p[i] of a POINTER TO T is the T at p + i * SIZEOF(T), a dereference
        // (an address outside the PLC's memory traps as p^ does).
        const Type* u32 = elem(TypeKind::UDInt);
        Val pv = load(base);
        Val i = expr(*ix.indices[0], elem(TypeKind::DInt));
        if (!i.ok) return bad_place;
        if (!(i.type ? i.type->is_integer() : i.c.k == ConstV::K::Int)) {
          diags_.error("ST208", ix.indices[0]->loc, "a pointer's index must be an integer, not " + tname(i.type));
          return bad_place;
        }
        Slot is = i.is_const ? konst_u32(static_cast<uint32_t>(i.c.i)) : convert(i.slot, i.type, u32);
        Slot off = temp(4, 4), addr = temp(4, 4);
        emit(num_op(Op::MUL_I8, u32->storage()), {off, is, konst_u32(base.type->target->size)});
        emit(num_op(Op::ADD_I8, u32->storage()), {addr, pv.slot, off});
        def(addr);
        Val at;
        at.type = base.type;
        at.slot = addr;
        return deref_place(at, base.type->target, e.loc);
      }
      return index_place(base, ix, for_write);
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

namespace {
// LDXXN/STXXN: the lower bounds folded into the element's offset (a 32-bit two's-complement
// displacement), so the instruction only multiplies and adds.
uint32_t unchecked_field(const Place& p) { return static_cast<uint32_t>(p.unchecked_disp()); }
// Data alone: nothing in it can be called or reached through (no FB instance, reference,
// pointer or interface), so an access to it is done where it is compiled.
bool plain_data(const Type* t) {
  if (!t) return false;
  if (t->kind == TypeKind::Ref || t->kind == TypeKind::Interface) return false;
  if (t->is_elementary() || t->is_string()) return true;
  if (t->kind == TypeKind::Array) return plain_data(t->elem);
  if (t->kind != TypeKind::Struct) return false;
  for (const Field& f : t->fields)
    if (!plain_data(f.type)) return false;
  return true;
}
}  // namespace

// An index v + K, K + v or v - K, v a DINT variable named as it is and K an untyped
// integer literal of at most 2^20: the access checks v against the bounds minus K
// (rank-1 frame arrays, see index_place), which spares the addition an instruction of
// its own. In DINT arithmetic, v + K wraps where the source's sum wraps, so the element
// reached and the trap are the same; a trap's message adds K back (Application::
// index_message).
std::optional<Compiler::Displaced> Compiler::displaced_index(const Expr& e) {
  if (e.kind != ExprKind::Binary) return std::nullopt;
  const auto& b = static_cast<const BinaryExpr&>(e);
  if (b.op != BinaryOp::Add && b.op != BinaryOp::Sub) return std::nullopt;
  const Expr* var = b.lhs.get();
  const Expr* lit = b.rhs.get();
  if (b.op == BinaryOp::Add && var && var->kind == ExprKind::Literal) std::swap(var, lit);
  if (!var || !lit || var->kind != ExprKind::Name || lit->kind != ExprKind::Literal) return std::nullopt;
  const auto& l = static_cast<const LiteralExpr&>(*lit);
  if (l.lit != LiteralKind::Int || !l.type_prefix.empty() || l.int_value > (uint64_t{1} << 20)) return std::nullopt;
  const Symbol* sym = lookup(canon(static_cast<const NameExpr&>(*var).name.text));
  if (!sym || sym->kind != SymKind::Var || !sym->type || sym->type->kind != TypeKind::DInt) return std::nullopt;
  const int64_t k = static_cast<int64_t>(l.int_value);
  return Displaced{var, b.op == BinaryOp::Sub ? -k : k};
}

// Records the shift of the access just emitted for p, for its trap's message. Code after
// the access was dropped when the table's last entry lies there.
void Compiler::note_shift(const Place& p) {
  if (p.shift == 0 || b_->last_instr >= b_->code.size()) return;
  auto& v = b_->index_shifts;
  while (!v.empty() && v.back().first >= b_->last_instr) v.pop_back();
  v.emplace_back(b_->last_instr, p.shift);
}

Place Compiler::index_place(Place base, const IndexExpr& e, bool for_write) {
  Place bad_place;
  bad_place.ok = false;
  // Set by an assignment whose right-hand side runs no call: an INT variable index cannot
  // change before the store, which then reads it directly (STXH) instead of a DINT copy.
  const bool defer = defer_index_cvt_ && e.indices.size() == 1;
  defer_index_cvt_ = false;
  const Type* t = base.type;
  if (t->kind != TypeKind::Array) {
    diags_.error("ST208", e.loc, "'[ ]' needs an array, not " + t->name);
    return bad_place;
  }
  if (e.indices.size() != t->dims.size()) {
    diags_.error("ST208", e.loc, t->name + " needs " + std::to_string(t->dims.size()) + " index(es), not " + std::to_string(e.indices.size()));
    return bad_place;
  }
  if (t->open) return open_index_place(base, e);
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
  uint32_t idx_cvt = UINT32_MAX;
  std::optional<Slot> raw16;
  // A displaced index (v + K) into a rank-1 frame array of data: v alone, K in the bounds.
  // A place written after a right-hand side that may call something keeps v + K computed
  // first, as the source orders it.
  std::optional<Displaced> disp;
  // Elements the fast path (below) reaches in one instruction.
  const bool fast_elem = (t->elem->is_elementary() && (esize == 1 || esize == 2 || esize == 4 || esize == 8)) ||
                         t->elem->kind == TypeKind::Struct || t->elem->kind == TypeKind::Pou;
  if (e.indices.size() == 1 && base.k == Place::K::Frame && fast_elem && plain_data(t->elem) && (!for_write || defer) &&
      t->dims[0].lo > -(int64_t{1} << 30) && t->dims[0].hi < (int64_t{1} << 30))
    disp = displaced_index(*e.indices[0]);
  int32_t shift = 0;
  for (size_t i = 0; i < e.indices.size(); ++i) {
    Val v = expr(disp ? *disp->var : *e.indices[i], elem(TypeKind::DInt));
    if (!v.ok) return bad_place;
    if (disp && v.is_const && v.c.k == ConstV::K::Int) v.c.i = static_cast<int32_t>(static_cast<uint32_t>(v.c.i) + static_cast<uint32_t>(disp->k));
    else if (disp) shift = static_cast<int32_t>(disp->k);
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
    if (defer && v.slot.kind == SK::Var && v.type->storage() == Storage::I16) {
      raw16 = v.slot;
      dyn.emplace_back(i, Slot{});
      continue;
    }
    size_t before = b_->code.size();
    dyn.emplace_back(i, convert(v.slot, v.type, elem(TypeKind::DInt)));
    if (b_->code.size() != before) idx_cvt = b_->last_instr;
  }
  // Fast path: one or two variable indices into a frame array, of any rank, of scalars or
  // of structures (whose scalar fields are then reached in one instruction). The constant
  // indices make a fixed offset into the element's row.
  const bool fast = (dyn.size() == 1 || dyn.size() == 2) && base.k == Place::K::Frame && fast_elem;
  if (raw16 && !fast) dyn[0].second = convert(*raw16, elem(TypeKind::Int), elem(TypeKind::DInt));
  if (dyn.empty()) {
    Place p = base;
    p.type = t->elem;
    p.off = base.off + static_cast<uint32_t>(const_disp);
    if (base.k == Place::K::AbsBit || base.k == Place::K::Bit || base.k == Place::K::FrameIdx) return bad_place;
    return p;
  }
  if (fast) {
    const size_t d0 = dyn[0].first;
    Place p;
    p.k = Place::K::FrameIdx;
    p.type = t->elem;
    p.off = base.off;
    p.sk = base.sk;
    p.idx = dyn[0].second;
    if (raw16) {
      p.has_idx16 = true;
      p.idx16 = *raw16;
    }
    p.shift = shift;
    p.lo = static_cast<int32_t>(t->dims[d0].lo - shift);
    p.count = static_cast<uint32_t>(t->dims[d0].hi - t->dims[d0].lo + 1);
    // stride 0: a rank-1 array of scalars (LDX/STX); else the element's or row's size.
    const bool plain = t->elem->is_elementary() && dyn.size() == 1 && stride[d0] == esize && const_disp == 0;
    p.stride = plain ? 0 : static_cast<uint32_t>(stride[d0]);
    p.field = static_cast<uint32_t>(const_disp);
    if (dyn.size() == 2) {
      const size_t d1 = dyn[1].first;
      p.two = true;
      p.idx2 = dyn[1].second;
      p.lo2 = static_cast<int32_t>(t->dims[d1].lo);
      p.count2 = static_cast<uint32_t>(t->dims[d1].hi - t->dims[d1].lo + 1);
      p.stride2 = static_cast<uint32_t>(stride[d1]);
      // Both indices FOR counters that stay inside their dimensions (see for_stmt).
      const CounterRange* r0 = proven_range(dyn[0].second);
      const CounterRange* r1 = proven_range(dyn[1].second);
      p.proven = r0 && r1 && r0->lo >= t->dims[d0].lo && r0->hi <= t->dims[d0].hi &&
                 r1->lo >= t->dims[d1].lo && r1->hi <= t->dims[d1].hi;
    }
    p.idx_cvt = idx_cvt;
    p.arr_bytes = t->size;
    p.readonly = base.readonly;
    // A place read now, or stored to after a right-hand side that runs no call, may read
    // its index's variables when it is accessed.
    if (plain && !raw16 && shift == 0 && (!for_write || defer) && take_linear_index(p.idx, &p))
      p.lin_proven = linear_in_range(p, t->dims[d0].lo, t->dims[d0].hi);
    // One index, a FOR counter that stays inside the dimension (see for_stmt); displaced
    // by K, the counter's range moves by K.
    if (dyn.size() == 1 && !raw16 && !p.has_lin) {
      const CounterRange* r = proven_range(p.idx);
      p.proven = r && r->lo + shift >= t->dims[d0].lo && r->hi + shift <= t->dims[d0].hi;
    }
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

// ------------------------------------------------------------------ ARRAY[*]

bool Compiler::open_bound(const Place& arr, size_t dim, bool upper, SourceLoc loc, Place* out) {
  const Symbol* s = arr.sym;
  const uint32_t at = 4 + 8 * static_cast<uint32_t>(dim) + (upper ? 4 : 0);
  // A METHOD reaching its FB's in-out: the slot is in the instance, through THIS.
  if (arr.k == Place::K::Ind && s && s->where == Where::This && s->section == VarSection::InOut && s->type &&
      s->type->kind == TypeKind::Ref && s->type->target && s->type->target->open) {
    Place b;
    b.k = Place::K::Ind;
    b.ptr = Slot{8, SK::Var};
    b.off = s->offset + at;
    b.type = elem(TypeKind::DInt);
    *out = b;
    return true;
  }
  if (arr.k != Place::K::Ind || !s || s->where != Where::InOut || !s->type || !s->type->open) {
    diags_.error("ST208", loc, "the bounds of this ARRAY[*] are not known here: only the POU whose VAR_IN_OUT it is "
                               "(and its methods) can index it or ask LOWER_BOUND/UPPER_BOUND");
    return false;
  }
  Place b;
  b.k = Place::K::Frame;
  b.sk = SK::Var;
  b.off = s->offset + at;
  b.type = elem(TypeKind::DInt);
  *out = b;
  return true;
}

// arr[i, j]: every index checked against the argument's bounds at run time, then the
// element at (((i - lo0) * n1 + (j - lo1)) * ...) * SIZEOF(element) from the address.
Place Compiler::open_index_place(const Place& base, const IndexExpr& e) {
  Place bad_place;
  bad_place.ok = false;
  const Type* t = base.type;
  const Type* dint = elem(TypeKind::DInt);
  Slot linear;
  for (size_t i = 0; i < e.indices.size(); ++i) {
    Place lo_p, hi_p;
    if (!open_bound(base, i, false, e.loc, &lo_p) || !open_bound(base, i, true, e.loc, &hi_p)) return bad_place;
    Val v = expr(*e.indices[i], dint);
    if (!v.ok) return bad_place;
    if (!v.type ? v.c.k != ConstV::K::Int : !(v.type->is_integer() || v.type->is_bitstring() || v.type->kind == TypeKind::Enum)) {
      diags_.error("ST208", e.indices[i]->loc, "an array index must be an integer, not " + tname(v.type));
      return bad_place;
    }
    const Type* it = v.type ? v.type : dint;
    Slot ix = to_slot(v, it, e.indices[i]->loc);
    if (it->size == 8 || (it->size == 4 && !it->is_signed())) {
      // Index arithmetic is 32-bit: a wider index is first checked in its own type.
      Slot los = konst(it, ConstV{ConstV::K::Int, it->is_signed() ? INT32_MIN : 0, 0, {}}, e.indices[i]->loc);
      Slot his = konst(it, ConstV{ConstV::K::Int, INT32_MAX, 0, {}}, e.indices[i]->loc);
      mark(e.indices[i]->loc);
      emit(int_op(Op::CHK_I8, it->storage()), {ix, los, his, 1u});
    }
    ix = convert(ix, it, dint);
    Slot lo = load(lo_p).slot, hi = load(hi_p).slot;
    mark(e.indices[i]->loc);
    emit(Op::CHK_I32, {ix, lo, hi, 1u});
    Slot d = temp(4, 4);
    emit(Op::SUB_I32, {d, ix, lo});
    if (i == 0) {
      linear = d;
      continue;
    }
    Slot extent = temp(4, 4), next = temp(4, 4);
    emit(Op::SUB_I32, {extent, hi, lo});
    emit(Op::ADD_I32, {extent, extent, konst(dint, ConstV{ConstV::K::Int, 1, 0, {}}, e.loc)});
    emit(Op::MUL_I32, {next, linear, extent});
    emit(Op::ADD_I32, {next, next, d});
    linear = next;
  }
  Slot bytes = temp(4, 4), addr = temp(4, 4);
  emit(Op::MUL_I32, {bytes, linear, konst(dint, ConstV{ConstV::K::Int, t->elem->size, 0, {}}, e.loc)});
  emit(Op::ADD_I32, {addr, addr_of(base, e.loc), bytes});
  Place p;
  p.k = Place::K::Ind;
  p.type = t->elem;
  p.ptr = addr;
  p.off = 0;
  p.readonly = base.readonly;
  return p;
}

bool Compiler::stage_inout(const Symbol* param, const Expr& arg, Slot* addr, std::vector<Slot>* bounds) {
  Place src = place(arg, true);
  if (!src.ok) return false;
  const Type* pt = param->type;
  const Type* st = src.type;
  if (pt->open) {
    if (st->kind != TypeKind::Array || st->dims.size() != pt->dims.size() || !same_type(st->elem, pt->elem)) {
      diags_.error("ST222", arg.loc, fmt::format("VAR_IN_OUT '{}' ({}) needs an array of {} with {} dimension(s), not {}", param->name,
                                                 pt->name, pt->elem->name, pt->dims.size(), st->name));
      return false;
    }
    for (size_t i = 0; i < st->dims.size(); ++i)
      for (bool upper : {false, true}) {
        if (st->open) {  // passed on: the bounds of the caller's argument
          Place b;
          if (!open_bound(src, i, upper, arg.loc, &b)) return false;
          bounds->push_back(load(b).slot);
        } else {
          bounds->push_back(konst(elem(TypeKind::DInt), ConstV{ConstV::K::Int, upper ? st->dims[i].hi : st->dims[i].lo, 0, {}}, arg.loc));
        }
      }
  } else if (st->open) {
    diags_.error("ST222", arg.loc, "VAR_IN_OUT '" + param->name + "' needs a variable of type " + pt->name + ", not an ARRAY[*]");
    return false;
  } else if (!same_type(st, pt) && st != pt && !derives(st, pt)) {
    diags_.error("ST222", arg.loc, "VAR_IN_OUT '" + param->name + "' needs a variable of type " + pt->name + ", not " + st->name);
    return false;
  }
  *addr = addr_of(src, arg.loc);
  return true;
}

void Compiler::store_inout(const Place& slot, Slot addr, const std::vector<Slot>& bounds) {
  Place a = slot;
  a.type = elem(TypeKind::UDInt);
  store(a, addr);
  for (size_t k = 0; k < bounds.size(); ++k) {
    Place b = slot;
    b.off += 4 + 4 * static_cast<uint32_t>(k);
    b.type = elem(TypeKind::DInt);
    store(b, bounds[k]);
  }
}

bool Compiler::bind_inout(const Place& slot, const Symbol* param, const Expr& arg) {
  Slot addr;
  std::vector<Slot> bounds;
  if (!stage_inout(param, arg, &addr, &bounds)) return false;
  store_inout(slot, addr, bounds);
  return true;
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
      emit(Op::ELEM, {t, a, frame_idx(p), static_cast<uint32_t>(p.lo), p.count, p.stride ? p.stride : p.type->size});
      note_shift(p);
      if (p.two) {
        Slot t2 = temp(4, 4);
        emit(Op::ELEM, {t2, t, p.idx2, static_cast<uint32_t>(p.lo2), p.count2, p.stride2});
        t = t2;
      }
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

// A read of an element of a frame array through an INT index, right after the index's
// conversion to DINT: the element is read with the INT index itself (LDXH, LDXSH) and the
// conversion dropped. Only for a place read once, here: another use of the place would
// read the dropped DINT copy.
Val Compiler::load_once(const Place& p) {
  auto& code = b_->code;
  uint32_t at = b_->last_instr;
  uint32_t size = p.ok && p.type ? p.type->size : 0;
  if (!p.ok || p.k != Place::K::FrameIdx || p.has_idx16 || p.two || !p.type->is_elementary() || !(size == 1 || size == 2 || size == 4 || size == 8) ||
      at >= code.size() || p.idx_cvt != at || code[at] != static_cast<uint32_t>(Op::CVT_I16_I32) || b_->last_def_pos != at ||
      b_->last_label_pos > at || b_->last_def.kind != SK::Temp || p.idx.kind != SK::Temp || b_->last_def.off != p.idx.off ||
      (!b_->lines.empty() && b_->lines.back().first > at))
    return load(p);
  Arg x(code[at + 2]);
  for (auto it = b_->slot_fix.begin(); it != b_->slot_fix.end();) {
    if (it->first == at + 2) x = Arg(Slot{code[at + 2], it->second});
    if (it->first >= at) it = b_->slot_fix.erase(it);
    else ++it;
  }
  code.resize(at);
  b_->last_def_pos = UINT32_MAX;
  for (auto it = b_->cvt_cache.begin(); it != b_->cvt_cache.end();) {
    if (it->second.kind == p.idx.kind && it->second.off == p.idx.off) it = b_->cvt_cache.erase(it);
    else ++it;
  }
  Slot t = temp_for(p.type);
  if (p.stride) {
    Op op = size == 1 ? Op::LDXSH1 : size == 2 ? Op::LDXSH2 : size == 4 ? Op::LDXSH4 : Op::LDXSH8;
    emit(op, {t, Slot{p.off, p.sk}, x, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field});
  } else {
    Op op = size == 1 ? Op::LDXH1 : size == 2 ? Op::LDXH2 : size == 4 ? Op::LDXH4 : Op::LDXH8;
    emit(op, {t, Slot{p.off, p.sk}, x, static_cast<uint32_t>(p.lo), p.count});
  }
  def(t);
  Val v;
  v.type = p.type;
  v.slot = t;
  return v;
}

// A load of the element the instruction just before stored: "STX... a, i, ..., src"
// then "LDX... t, a, i, ..." with the same operands (array, indices, bounds, field), no
// jump target between them and no instruction (the loads of x[i] := v; IF x[i] ...). The
// element holds src's value, so the load is not emitted and its value is read from src,
// when src is a constant or a temporary nothing allocated since (which no call can
// change: it stays reserved until the statement ends). The store checked the same indices
// (nothing changed them: no index variable lies inside the array), so the load could not
// trap. Null: emit the load.
std::optional<Slot> Compiler::stored_element(Op load_op, const std::vector<Arg>& addr, const Place& p) {
  auto& code = b_->code;
  const uint32_t at = b_->last_elem_store;
  const std::string_view ld = op_info(load_op).name;
  if (at >= code.size() || b_->last_label_pos > at || p.arr_bytes == 0 || ld.substr(0, 2) != "LD") return std::nullopt;
  const std::string_view st = op_info(static_cast<Op>(code[at])).name;
  const uint32_t n = op_info(static_cast<Op>(code[at])).nargs;
  if (st.substr(0, 2) != "ST" || st.substr(2) != ld.substr(2) || n != addr.size() + 1 || at + 1 + n != code.size())
    return std::nullopt;
  const uint32_t base_at = ld.rfind("LDXR", 0) == 0 ? 3 : 0;  // the array's operand (LDXR: row, counter, m first)
  for (uint32_t i = 0; i < addr.size(); ++i) {
    const Arg& a = addr[i];
    const uint32_t word = at + 1 + i;
    if (a.k == Arg::K::Slot) {
      if (code[word] != a.v || kind_at(word) != a.sk) return std::nullopt;
      // An index variable the store may have written (a UNION): its value may differ now.
      if (i != base_at && a.sk == p.sk && uint64_t{a.v} < uint64_t{p.off} + p.arr_bytes && uint64_t{a.v} + 8 > p.off) return std::nullopt;
    } else if (a.k != Arg::K::Imm || code[word] != a.v || kind_at(word) != SK::Var) {
      return std::nullopt;
    }
  }
  const Slot src{code[at + n], kind_at(at + n)};
  if (src.kind == SK::Const) return src;
  if (src.kind != SK::Temp || src.off < b_->temp_top) return std::nullopt;
  b_->temp_top = src.off + std::max<uint32_t>(p.type->size, 1);
  b_->temp_max = std::max(b_->temp_max, b_->temp_top);
  return src;
}

Slot Compiler::frame_idx(const Place& p) {
  if (p.has_lin) {
    Slot sum = temp(4, 4);
    emit(Op::MADD_I32, {sum, p.lin_x, p.lin_m, p.lin_y});
    def(sum);
    return sum;
  }
  return p.has_idx16 ? convert(p.idx16, elem(TypeKind::Int), elem(TypeKind::DInt)) : p.idx;
}

// An index linear in two variables: "MADD_I32 idx, x, m, y" (x * m + y, see
// multiply_add), just emitted for this index, in the same statement line and block, x, m
// and y variables or constants. It goes; the access computes x * m + y (wrapping, as it
// did) and checks the sum once (LDXL/STXL). False: nothing changed.
bool Compiler::take_linear_index(Slot idx, Place* p) {
  auto& code = b_->code;
  const uint32_t at = b_->last_instr;
  if (at >= code.size() || code[at] != static_cast<uint32_t>(Op::MADD_I32) || at < b_->last_label_pos) return false;
  if (!b_->lines.empty() && b_->lines.back().first > at) return false;
  auto slot_at = [&](uint32_t word) { return Slot{code[word], kind_at(word)}; };
  auto operand = [](Slot s) { return s.kind == SK::Var || s.kind == SK::Const; };
  const Slot sum = slot_at(at + 1), x = slot_at(at + 2), m = slot_at(at + 3), y = slot_at(at + 4);
  if (idx.kind != SK::Temp || sum.kind != SK::Temp || sum.off != idx.off) return false;
  if (!operand(x) || !operand(m) || !operand(y)) return false;
  for (auto it = b_->slot_fix.begin(); it != b_->slot_fix.end();) {
    if (it->first >= at) it = b_->slot_fix.erase(it);
    else ++it;
  }
  code.resize(at);
  b_->last_instr = b_->prev_instr = b_->prev2_instr = b_->last_def_pos = UINT32_MAX;
  p->has_lin = true;
  p->lin_x = x;
  p->lin_m = m;
  p->lin_y = y;
  return true;
}

Val Compiler::load(const Place& p) {
  Val v;
  v.type = p.type;
  if (!p.ok) return bad();
  if (p.type && p.type->open) {
    // At the statement being compiled: a load has no location of its own.
    diags_.error("ST203", b_ && !b_->lines.empty() ? b_->lines.back().second : SourceLoc{},
                 "an ARRAY[*] has no value of its own: index it, or pass it to another ARRAY[*]");
    return bad();
  }
  if (p.k == Place::K::FrameIdx && !p.type->is_elementary()) {
    if (!p.two) {
      // A whole element (a structure, an FB instance) as one block.
      Slot t = temp_for(p.type);
      emit(Op::LDXB, {t, Slot{p.off, p.sk}, frame_idx(p), static_cast<uint32_t>(p.lo), p.count, p.stride, p.field, p.type->size});
      note_shift(p);
      def(t);
      v.slot = t;
      return v;
    }
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
      Op op;
      std::vector<Arg> addr;  // the operands after the destination
      const auto row = row_for(p);
      Slot idx = row || p.has_lin ? Slot{} : frame_idx(p);
      if (row) {
        op = size == 1 ? Op::LDXR1 : size == 2 ? Op::LDXR2 : size == 4 ? Op::LDXR4 : Op::LDXR8;
        addr = {row->row, row->counter, static_cast<uint32_t>(static_cast<int32_t>(row->m)), Slot{p.off, p.sk}, p.arr_bytes};
      } else if (p.two && p.proven) {
        op = size == 1 ? Op::LDXXN1 : size == 2 ? Op::LDXXN2 : size == 4 ? Op::LDXXN4 : Op::LDXXN8;
        addr = {Slot{p.off, p.sk}, idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.idx2, static_cast<uint32_t>(p.lo2),
                p.count2, p.stride2, unchecked_field(p)};
      } else if (p.two) {
        op = size == 1 ? Op::LDXX1 : size == 2 ? Op::LDXX2 : size == 4 ? Op::LDXX4 : Op::LDXX8;
        addr = {Slot{p.off, p.sk}, idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.idx2, static_cast<uint32_t>(p.lo2),
                p.count2, p.stride2, p.field};
      } else if (p.has_lin) {
        op = size == 1 ? Op::LDXL1 : size == 2 ? Op::LDXL2 : size == 4 ? Op::LDXL4 : Op::LDXL8;
        addr = {Slot{p.off, p.sk}, p.lin_x, p.lin_m, p.lin_y, static_cast<uint32_t>(p.lo), p.count};
      } else if (p.stride && p.proven) {
        op = size == 1 ? Op::LDXSN1 : size == 2 ? Op::LDXSN2 : size == 4 ? Op::LDXSN4 : Op::LDXSN8;
        addr = {Slot{p.off, p.sk}, idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field};
      } else if (p.stride) {
        op = size == 1 ? Op::LDXS1 : size == 2 ? Op::LDXS2 : size == 4 ? Op::LDXS4 : Op::LDXS8;
        addr = {Slot{p.off, p.sk}, idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field};
      } else if (p.proven) {
        op = size == 1 ? Op::LDXN1 : size == 2 ? Op::LDXN2 : size == 4 ? Op::LDXN4 : Op::LDXN8;
        addr = {Slot{p.off, p.sk}, idx, static_cast<uint32_t>(p.lo), p.count};
      } else {
        op = size == 1 ? Op::LDX1 : size == 2 ? Op::LDX2 : size == 4 ? Op::LDX4 : Op::LDX8;
        addr = {Slot{p.off, p.sk}, idx, static_cast<uint32_t>(p.lo), p.count};
      }
      if (auto stored = stored_element(op, addr, p)) {
        v.slot = *stored;
        return v;
      }
      Slot t = temp_for(p.type);
      addr.insert(addr.begin(), Arg(t));
      emit_list(op, addr);
      if (!row) note_shift(p);
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
    if (!p.two) {
      emit(Op::STXB, {Slot{p.off, p.sk}, frame_idx(p), static_cast<uint32_t>(p.lo), p.count, p.stride, p.field, src, t->size});
      note_shift(p);
      return;
    }
    Place ind = p;
    ind.k = Place::K::Ind;
    ind.ptr = addr_of(p, SourceLoc{});
    ind.off = 0;
    store(ind, src);
    return;
  }
  uint32_t size = t->size;
  if (t->is_string() && p.k == Place::K::Frame) {
    emit(string_copy_op(t), {Slot{p.off, p.sk}, src, t->str_len});
    return;
  }
  if (t->is_string()) {
    // Truncate to the destination's capacity in a temporary, then copy the buffer.
    Slot tmp = temp(size, t->align);
    emit(string_copy_op(t), {tmp, src, t->str_len});
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
      if (auto r = row_for(p)) {
        Op op = size == 1 ? Op::STXR1 : size == 2 ? Op::STXR2 : size == 4 ? Op::STXR4 : Op::STXR8;
        emit(op, {r->row, r->counter, static_cast<uint32_t>(static_cast<int32_t>(r->m)), Slot{p.off, p.sk}, p.arr_bytes, src});
        b_->last_elem_store = b_->last_instr;
        return;
      }
      if (p.two && p.proven) {
        Op op = size == 1 ? Op::STXXN1 : size == 2 ? Op::STXXN2 : size == 4 ? Op::STXXN4 : Op::STXXN8;
        emit(op, {Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.idx2, static_cast<uint32_t>(p.lo2), p.count2,
                  p.stride2, unchecked_field(p), src});
        b_->last_elem_store = b_->last_instr;
        return;
      }
      if (p.two) {
        Op op = size == 1 ? Op::STXX1 : size == 2 ? Op::STXX2 : size == 4 ? Op::STXX4 : Op::STXX8;
        emit(op, {Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.idx2, static_cast<uint32_t>(p.lo2), p.count2,
                  p.stride2, p.field, src});
        b_->last_elem_store = b_->last_instr;
        return;
      }
      if (p.has_lin) {
        Op op = size == 1 ? Op::STXL1 : size == 2 ? Op::STXL2 : size == 4 ? Op::STXL4 : Op::STXL8;
        emit(op, {Slot{p.off, p.sk}, p.lin_x, p.lin_m, p.lin_y, static_cast<uint32_t>(p.lo), p.count, src});
        b_->last_elem_store = b_->last_instr;
        return;
      }
      if (p.has_idx16 && p.stride) {
        Op op = size == 1 ? Op::STXSH1 : size == 2 ? Op::STXSH2 : size == 4 ? Op::STXSH4 : Op::STXSH8;
        emit(op, {Slot{p.off, p.sk}, p.idx16, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field, src});
        b_->last_elem_store = b_->last_instr;
        return;
      }
      if (p.has_idx16) {
        Op op = size == 1 ? Op::STXH1 : size == 2 ? Op::STXH2 : size == 4 ? Op::STXH4 : Op::STXH8;
        emit(op, {Slot{p.off, p.sk}, p.idx16, static_cast<uint32_t>(p.lo), p.count, src});
        b_->last_elem_store = b_->last_instr;
        return;
      }
      if (p.stride && p.proven) {
        Op op = size == 1 ? Op::STXSN1 : size == 2 ? Op::STXSN2 : size == 4 ? Op::STXSN4 : Op::STXSN8;
        emit(op, {Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field, src});
        b_->last_elem_store = b_->last_instr;
        note_shift(p);
        return;
      }
      if (p.stride) {
        Op op = size == 1 ? Op::STXS1 : size == 2 ? Op::STXS2 : size == 4 ? Op::STXS4 : Op::STXS8;
        emit(op, {Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, p.stride, p.field, src});
        b_->last_elem_store = b_->last_instr;
        note_shift(p);
        return;
      }
      Op op = p.proven ? (size == 1 ? Op::STXN1 : size == 2 ? Op::STXN2 : size == 4 ? Op::STXN4 : Op::STXN8)
                       : (size == 1 ? Op::STX1 : size == 2 ? Op::STX2 : size == 4 ? Op::STX4 : Op::STX8);
      emit(op, {Slot{p.off, p.sk}, p.idx, static_cast<uint32_t>(p.lo), p.count, src});
      b_->last_elem_store = b_->last_instr;
      note_shift(p);
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

void Compiler::assign(const Place& dst, const Val& v, SourceLoc loc) {
  if (!dst.ok || !v.ok) return;
  if (dst.type->open || (v.type && v.type->open)) {
    diags_.error("ST203", loc, "an ARRAY[*] is not assigned whole: copy it element by element (LOWER_BOUND/UPPER_BOUND give its bounds)");
    return;
  }
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

}  // namespace plcfi::st::detail
