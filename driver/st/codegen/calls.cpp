// Calls: user functions (frames inside the caller's frame), function block instances,
// methods and properties (frames on the method stack, static or dynamic dispatch),
// the standard functions and conversions, and the test-file built-ins.
#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "compiler_impl.hpp"

namespace plcfi::st::detail {

namespace {
struct BuiltinParams {
  const char* name;
  std::vector<const char*> params;
};
// Formal parameter names of standard functions (for calls like LIMIT(MN := 0, IN := x, MX := 9)).
const std::vector<BuiltinParams>& builtin_params() {
  static const std::vector<BuiltinParams> k = {
      {"LIMIT", {"MN", "IN", "MX"}}, {"SEL", {"G", "IN0", "IN1"}},   {"SHL", {"IN", "N"}},
      {"SHR", {"IN", "N"}},          {"ROL", {"IN", "N"}},           {"ROR", {"IN", "N"}},
      {"LEFT", {"IN", "L"}},         {"RIGHT", {"IN", "L"}},         {"MID", {"IN", "L", "P"}},
      {"INSERT", {"IN1", "IN2", "P"}}, {"DELETE", {"IN", "L", "P"}}, {"REPLACE", {"IN1", "IN2", "L", "P"}},
      {"FIND", {"IN1", "IN2"}},      {"EXPT", {"IN1", "IN2"}},       {"MUX", {"K"}},
      {"LEN", {"IN"}},
  };
  return k;
}
}  // namespace

std::vector<const Expr*> Compiler::positional(const CallExpr& c, size_t min, size_t max, const char* name) {
  std::vector<const Expr*> out;
  const std::vector<const char*>* names = nullptr;
  for (const auto& bp : builtin_params())
    if (iequals(bp.name, name)) names = &bp.params;
  bool formal = false;
  for (const auto& a : c.args) {
    if (a.is_output) {
      diags_.error("ST210", a.loc, std::string(name) + " has no outputs to capture with '=>'");
      return {};
    }
    if (a.name) formal = true;
  }
  if (formal) {
    out.assign(c.args.size(), nullptr);
    for (const auto& a : c.args) {
      size_t idx = SIZE_MAX;
      if (a.name && names)
        for (size_t i = 0; i < names->size(); ++i)
          if (iequals((*names)[i], a.name->text)) idx = i;
      if (a.name && idx == SIZE_MAX) {
        // IN0, IN1, ... for the variadic functions.
        std::string n = canon(a.name->text);
        if (n.size() > 2 && n.rfind("IN", 0) == 0 && std::all_of(n.begin() + 2, n.end(), ::isdigit))
          idx = static_cast<size_t>(std::stoul(n.substr(2))) + (names && names->size() && iequals((*names)[0], "K") ? 1 : 0);
        else if (n == "IN") idx = 0;
      }
      if (idx == SIZE_MAX) {
        diags_.error("ST212", a.loc, std::string(name) + " has no parameter '" + (a.name ? a.name->text : "") + "'");
        return {};
      }
      if (idx >= out.size()) out.resize(idx + 1, nullptr);
      out[idx] = a.value.get();
    }
    for (size_t i = 0; i < out.size(); ++i)
      if (!out[i]) {
        diags_.error("ST210", c.loc, std::string(name) + ": parameter " + std::to_string(i + 1) + " is missing");
        return {};
      }
  } else {
    for (const auto& a : c.args) out.push_back(a.value.get());
  }
  if (out.size() < min || out.size() > max) {
    diags_.error("ST210", c.loc, std::string(name) + " takes " +
                                     (min == max ? std::to_string(min) : std::to_string(min) + (max == SIZE_MAX ? " or more" : " to " + std::to_string(max))) +
                                     " argument(s), not " + std::to_string(out.size()));
    return {};
  }
  for (const Expr* e : out)
    if (!e) return {};
  return out;
}

Val Compiler::native(Native n, const Type* result, std::initializer_list<Slot> args, uint32_t cap) {
  return native_list(n, result, std::vector<Slot>(args), cap);
}

Val Compiler::native_list(Native n, const Type* result, const std::vector<Slot>& args, uint32_t cap) {
  Slot d = result->is_string() ? temp(result->size, 1) : temp_for(result);
  Arg a[4] = {0u, 0u, 0u, 0u};
  size_t i = 0;
  for (Slot s : args) a[i++] = Arg(s);
  emit(Op::NATIVE, {static_cast<uint32_t>(n) | (cap << 16), d, a[0], a[1], a[2]});
  def(d, 2);
  Val v;
  v.type = result;
  v.slot = d;
  return v;
}

// Whether evaluating e may run a call (a function, a method, a property getter), which
// could change variables or take the method stack's top. Conservative: only literals,
// variables, fields of a named structure or instance, and operators over them are known
// to run none. Iterative, so that a long operator chain costs no stack.
bool Compiler::may_call(const Expr& root) const {
  std::vector<const Expr*> todo{&root};
  while (!todo.empty()) {
    const Expr* e = todo.back();
    todo.pop_back();
    switch (e->kind) {
      case ExprKind::Literal:
      case ExprKind::EnumLiteral:
      case ExprKind::DirectAddr:
      case ExprKind::This:
        break;
      case ExprKind::Name: {
        const Symbol* s = lookup(canon(static_cast<const NameExpr&>(*e).name.text));
        if (!s) return true;  // a property of this instance, read by its bare name
        break;
      }
      case ExprKind::Member: {
        const auto& m = static_cast<const MemberExpr&>(*e);
        if (m.base->kind != ExprKind::Name) return true;
        const Symbol* s = lookup(canon(static_cast<const NameExpr&>(*m.base).name.text));
        if (!s || s->kind != SymKind::Var || !s->type) return true;
        if (s->type->kind != TypeKind::Struct && s->type->kind != TypeKind::Pou) return true;
        if (!s->type->field(m.member.text)) return true;
        break;
      }
      case ExprKind::BitAccess: todo.push_back(static_cast<const BitAccessExpr&>(*e).base.get()); break;
      case ExprKind::Deref: todo.push_back(static_cast<const DerefExpr&>(*e).base.get()); break;
      case ExprKind::Unary: todo.push_back(static_cast<const UnaryExpr&>(*e).operand.get()); break;
      case ExprKind::Binary:
        todo.push_back(static_cast<const BinaryExpr&>(*e).lhs.get());
        todo.push_back(static_cast<const BinaryExpr&>(*e).rhs.get());
        break;
      case ExprKind::Index: {
        const auto& ix = static_cast<const IndexExpr&>(*e);
        todo.push_back(ix.base.get());
        for (const auto& i : ix.indices) todo.push_back(i.get());
        break;
      }
      default: return true;
    }
  }
  return false;
}

// ------------------------------------------------------------------ dispatch

Val Compiler::call(const CallExpr& c, bool as_statement) {
  mark(c.loc);
  const Expr& callee = *c.callee;
  auto void_val = [&]() {
    Val v;
    v.type = elem(TypeKind::Void);
    return v;
  };
  // SUPER^(): the base FB's body on this instance.
  if (callee.kind == ExprKind::Deref && static_cast<const DerefExpr&>(callee).base->kind == ExprKind::Super) {
    Place p = place(callee, false);
    if (!p.ok) return bad();
    return call_fb(p, p.type->pou, c, p.type->pou);
  }
  if (callee.kind == ExprKind::Name) {
    const auto& n = static_cast<const NameExpr&>(callee);
    std::string key = canon(n.name.text);
    const Symbol* s = lookup(key);
    if (s && s->kind == SymKind::Var) {
      if (s->type->kind == TypeKind::Pou) {
        Place p = place(callee, false);
        if (!p.ok) return bad();
        Val r = call_fb(p, s->type->pou, c);
        return r;
      }
      diags_.error("ST213", callee.loc, "'" + n.name.text + "' is a " + s->type->name + " variable, not callable");
      return bad();
    }
    auto it = pous_.find(key);
    if (it != pous_.end()) {
      PouInfo* p = it->second;
      if (p->kind == PouKind::Function) return call_function(p, c);
      diags_.error("ST213", callee.loc, "'" + n.name.text + "' is a " +
                                            (p->kind == PouKind::FunctionBlock ? std::string("function block type: declare an instance and call that") :
                                             p->kind == PouKind::Program ? std::string("PROGRAM type: it runs from a task, or declare an instance in a test") :
                                                                            std::string("interface")));
      return bad();
    }
    if (auto b = builtin(key, c)) return *b;
    // A method of this instance called by its bare name.
    if (b_->this_type && b_->this_type->pou) {
      if (PouInfo* m = b_->this_type->pou->find_method(n.name.text)) {
        Place self = this_place(c.loc);
        return call_method(c, m, &self, addr_of(self, c.loc), true);
      }
    }
    diags_.error("ST211", callee.loc, "unknown function '" + n.name.text + "'");
    return bad();
  }
  if (callee.kind == ExprKind::Member) {
    const auto& m = static_cast<const MemberExpr&>(callee);
    bool via_super = m.base->kind == ExprKind::Deref && static_cast<const DerefExpr&>(*m.base).base->kind == ExprKind::Super;
    bool via_this = m.base->kind == ExprKind::Deref && static_cast<const DerefExpr&>(*m.base).base->kind == ExprKind::This;
    Place base = place(*m.base, false);
    if (!base.ok) return bad();
    if (base.type->kind == TypeKind::Interface) {
      PouInfo* itf = base.type->pou;
      PouInfo* meth = itf ? itf->find_method(m.member.text) : nullptr;
      if (!meth) {
        diags_.error("ST211", m.member.loc, "interface " + base.type->name + " has no method '" + m.member.text + "'");
        return bad();
      }
      Val ptr = load(base);
      return call_method(c, meth, nullptr, ptr.slot, true);
    }
    if (base.type->kind == TypeKind::Pou && base.type->pou) {
      if (base.type->field(m.member.text)) {
        Place inner = member_place(base, m.member, callee.loc);
        if (!inner.ok) return bad();
        if (inner.type->kind == TypeKind::Pou) return call_fb(inner, inner.type->pou, c);
        diags_.error("ST213", callee.loc, "'" + m.member.text + "' is not callable");
        return bad();
      }
      PouInfo* meth = base.type->pou->find_method(m.member.text);
      if (!meth) {
        diags_.error("ST211", m.member.loc, base.type->name + " has no method '" + m.member.text + "'");
        return bad();
      }
      if (meth->access == Access::Private && !(b_->this_type && b_->this_type == meth->owner->type)) {
        diags_.error("ST211", m.member.loc, "method " + base.type->name + "." + meth->name + " is PRIVATE");
        return bad();
      }
      // Calls through THIS dispatch on the instance's run-time type; SUPER and plain
      // instances (whose type is exactly their declaration) bind statically.
      return call_method(c, meth, &base, addr_of(base, c.loc), via_this && !via_super);
    }
    if (base.type->kind == TypeKind::Struct) {
      Place inner = member_place(base, m.member, callee.loc);
      if (!inner.ok) return bad();
      if (inner.type->kind == TypeKind::Pou) return call_fb(inner, inner.type->pou, c);
    }
    diags_.error("ST213", callee.loc, "'" + m.member.text + "' is not callable");
    return bad();
  }
  if (callee.kind == ExprKind::Deref || callee.kind == ExprKind::Index) {
    Place p = place(callee, false);
    if (!p.ok) return bad();
    if (p.type->kind == TypeKind::Pou) return call_fb(p, p.type->pou, c);
    diags_.error("ST213", callee.loc, "a " + p.type->name + " is not callable");
    return bad();
  }
  (void)as_statement;
  (void)void_val;
  diags_.error("ST213", callee.loc, "this expression is not callable");
  return bad();
}

// ------------------------------------------------------------------ functions

Val Compiler::call_function(PouInfo* f, const CallExpr& c) {
  ensure_compiled(f, c.loc);
  if (!f->compiled) return bad();
  Slot frame = temp(f->frame_size, 8);
  if (f->tmpl_to > f->tmpl_from) emit(Op::INITBLK, {frame, f->template_addr, f->tmpl_to - f->tmpl_from});
  std::vector<Symbol*> params = f->inputs;
  params.insert(params.end(), f->inouts.begin(), f->inouts.end());
  size_t pos = 0;
  struct OutCapture {
    Symbol* sym;
    const CallArg* arg;
  };
  std::vector<OutCapture> outs;
  std::vector<bool> given(params.size(), false);
  for (const auto& a : c.args) {
    Symbol* p = nullptr;
    if (a.name) {
      for (Symbol* q : params)
        if (iequals(q->name, a.name->text)) p = q;
      if (!p)
        for (Symbol* q : f->outputs)
          if (iequals(q->name, a.name->text)) p = q;
      if (!p) {
        diags_.error("ST212", a.loc, f->name + " has no parameter '" + a.name->text + "'");
        continue;
      }
    } else {
      if (pos >= params.size()) {
        diags_.error("ST210", a.loc, f->name + " takes " + std::to_string(params.size()) + " argument(s)");
        break;
      }
      p = params[pos++];
    }
    if (a.is_output || p->section == VarSection::Output) {
      if (!a.is_output) {
        diags_.error("ST210", a.loc, "'" + p->name + "' is an output: capture it with '" + p->name + " => var'");
        continue;
      }
      outs.push_back({p, &a});
      continue;
    }
    for (size_t i = 0; i < params.size(); ++i)
      if (params[i] == p) given[i] = true;
    if (!a.value) continue;
    if (p->where == Where::InOut) {
      Place src = place(*a.value, true);
      if (!src.ok) continue;
      if (!same_type(src.type, p->type) && src.type != p->type) {
        diags_.error("ST222", a.value->loc, "VAR_IN_OUT '" + p->name + "' needs a variable of type " + p->type->name + ", not " + src.type->name);
        continue;
      }
      store(frame_place(frame.plus(p->offset), elem(TypeKind::UDInt)), addr_of(src, a.value->loc));
      continue;
    }
    Val v = expr_for(*a.value, p->type);
    assign(frame_place(frame.plus(p->offset), p->type), v, a.value->loc);
  }
  // A non-formal call lists every input in order (IEC 61131-3 6.6.1.4.2); only a formal
  // call may leave inputs at their initial values.
  bool any_named = std::any_of(c.args.begin(), c.args.end(), [](const CallArg& a) { return a.name.has_value(); });
  if (!any_named && pos > 0 && pos < params.size())
    diags_.error("ST210", c.loc,
                 fmt::format("{} takes {} argument(s), {} given; a non-formal call lists every input (or name them: {}({} := ...))",
                             f->name, params.size(), pos, f->name, params[pos]->name));
  else
    for (size_t i = 0; i < params.size(); ++i)
      if (!given[i] && params[i]->where == Where::InOut)
        diags_.error("ST224", c.loc, "VAR_IN_OUT '" + params[i]->name + "' of " + f->name + " must be passed");
  mark(c.loc);
  emit(Op::CALL, {frame, Arg::entry(f)});
  for (const auto& o : outs) {
    if (!o.arg->value) continue;
    Place dst = place(*o.arg->value, true);
    Val v = load(frame_place(frame.plus(o.sym->offset), o.sym->type));
    if (o.arg->negate) {
      Slot t = temp(1, 1);
      emit(Op::BNOT, {t, v.slot});
      v.slot = t;
    }
    assign(dst, v, o.arg->loc);
  }
  Val r;
  r.type = f->result;
  r.slot = frame.plus(f->result_offset);
  return r;
}

// ------------------------------------------------------------------ FB instances

Val Compiler::call_fb(const Place& inst_in, PouInfo* fb, const CallExpr& c, PouInfo* body_of) {
  Val none;
  none.type = elem(TypeKind::Void);
  if (!fb) return bad();
  Place inst = inst_in;
  if (inst.k == Place::K::FrameIdx) {
    // An element of an instance array: call through its address.
    inst.k = Place::K::Ind;
    inst.ptr = addr_of(inst_in, c.loc);
    inst.off = 0;
  }
  std::vector<std::pair<Symbol*, const CallArg*>> outs;
  std::vector<Symbol*> params;
  for (PouInfo* f = fb; f; f = f->base) {
    std::vector<Symbol*> own = f->inputs;
    own.insert(own.end(), f->inouts.begin(), f->inouts.end());
    params.insert(params.begin(), own.begin(), own.end());
  }
  size_t pos = 0;
  std::vector<Symbol*> passed;
  for (const auto& a : c.args) {
    Symbol* p = nullptr;
    if (a.name) {
      p = fb->find_var(a.name->text);
      if (!p || (p->section != VarSection::Input && p->section != VarSection::Output && p->section != VarSection::InOut)) {
        diags_.error("ST212", a.loc, fb->name + " has no input or output '" + a.name->text + "'");
        continue;
      }
    } else {
      if (pos >= params.size()) {
        diags_.error("ST210", a.loc, "too many arguments for " + fb->name);
        break;
      }
      p = params[pos++];
    }
    if (a.is_output || p->section == VarSection::Output) {
      if (!a.is_output) {
        diags_.error("ST210", a.loc, "'" + p->name + "' is an output of " + fb->name + ": write '" + p->name + " => var'");
        continue;
      }
      outs.emplace_back(p, &a);
      continue;
    }
    passed.push_back(p);
    if (!a.value) continue;
    ++sym_src(p).writes;
    Place field = inst;
    field.type = p->where == Where::InOut ? elem(TypeKind::UDInt) : p->type;
    field.off = inst.off + p->offset;
    field.readonly = false;
    if (p->where == Where::InOut) {
      Place src = place(*a.value, true);
      if (!src.ok) continue;
      if (!same_type(src.type, p->type) && src.type != p->type) {
        diags_.error("ST222", a.value->loc, "VAR_IN_OUT '" + p->name + "' needs a variable of type " + p->type->name + ", not " + src.type->name);
        continue;
      }
      store(field, addr_of(src, a.value->loc));
      continue;
    }
    Val v = expr_for(*a.value, p->type);
    assign(field, v, a.value->loc);
  }
  for (Symbol* p : params)
    if (p->where == Where::InOut && std::find(passed.begin(), passed.end(), p) == passed.end())
      diags_.error("ST224", c.loc, "VAR_IN_OUT '" + p->name + "' of " + fb->name + " must be passed in every call");
  mark(c.loc);
  PouInfo* target = body_of ? body_of : fb;
  switch (inst.k) {
    case Place::K::Frame: emit(Op::CALL, {Slot{inst.off, inst.sk}, Arg::entry(target)}); break;
    case Place::K::Abs: emit(Op::CALLA, {inst.off, Arg::entry(target)}); break;
    case Place::K::Ind: {
      Slot p = inst.ptr;
      if (inst.off) {
        p = temp(4, 4);
        emit(Op::ADDRI, {p, inst.ptr, inst.off});
      }
      emit(Op::CALLP, {p, Arg::entry(target)});
      break;
    }
    default:
      diags_.error("ST213", c.loc, "cannot call this instance");
      return bad();
  }
  // Every output is read before any destination is evaluated: a call in a destination
  // (arr[f()]) may run this instance again, and what the caller captures is what this
  // call produced.
  bool dst_calls = std::any_of(outs.begin(), outs.end(), [&](const auto& o) { return o.second->value && may_call(*o.second->value); });
  std::vector<Val> out_vals;
  for (auto [p, a] : outs) {
    if (!a->value) {
      out_vals.emplace_back();
      continue;
    }
    ++sym_src(p).reads;
    Place field = inst;
    field.type = p->type;
    field.off = inst.off + p->offset;
    Val v = load(field);
    if (dst_calls && v.slot.kind == SK::Var) {
      Slot copy = p->type->is_string() ? temp(p->type->size, 1) : temp_for(p->type);
      store(frame_place(copy, p->type), v.slot);
      v.slot = copy;
    }
    out_vals.push_back(v);
  }
  for (size_t k = 0; k < outs.size(); ++k) {
    const CallArg* a = outs[k].second;
    if (!a->value) continue;
    Val v = out_vals[k];
    if (a->negate) {
      Slot t = temp(1, 1);
      emit(Op::BNOT, {t, v.slot});
      v.slot = t;
    }
    assign(place(*a->value, true), v, a->loc);
  }
  return none;
}

// ------------------------------------------------------------------ methods

void Compiler::declare_pou(PouInfo* p) {
  PouSource& ps = src(p);
  if (ps.declared) return;
  ps.declared = true;
  uint32_t saved = file_;
  file_ = p->file;
  if (p->kind == PouKind::Function || p->kind == PouKind::Method) {
    p->result = elem(TypeKind::Void);
    if (ps.property && !p->is_setter) p->result = ps.property->type ? resolve_type(*ps.property->type, p->file) : nullptr;
    else if (ps.decl && ps.decl->return_type) p->result = resolve_type(*ps.decl->return_type, p->file);
    if (!p->result) p->result = elem(TypeKind::Void);
  }
  if (p->base) ensure_compiled(p->base, p->loc);
  Body* saved_b = b_;
  b_ = nullptr;
  declare_vars(p);
  b_ = saved_b;
  file_ = saved;
  // A METHOD's inputs: the value an omitted argument gets, kept with the program so that
  // a unit linked onto it later can call the method too.
  if (p->kind == PouKind::Method)
    for (Symbol* in : p->inputs) {
      in->init.assign(in->type->size, 0);
      const VarDecl* d = decl_of(in);
      write_init(in->init, 0, in->type, d ? d->init.get() : nullptr, p->file);
    }
}

// Arguments are evaluated before the method's frame is taken. FRAME names the method
// stack's top, and a call in an argument (a method, a property getter, a function whose
// body calls one) takes its frame at that same top: a frame taken first would have the
// arguments stored so far overwritten by the nested call. Outputs and the result are read
// from the frame right after the call, before any destination is evaluated, for the same
// reason.
Val Compiler::call_method(const CallExpr& c, PouInfo* m, const Place* inst, Slot this_ptr, bool virt) {
  declare_pou(m);
  (void)inst;
  std::vector<Symbol*> params = m->inputs;
  params.insert(params.end(), m->inouts.begin(), m->inouts.end());
  std::vector<const CallArg*> bound(params.size(), nullptr);
  std::vector<std::pair<Symbol*, const CallArg*>> outs;
  std::vector<size_t> order;  // bound parameters in the order their arguments are written
  size_t pos = 0;
  for (const auto& a : c.args) {
    size_t idx = SIZE_MAX;
    if (a.name) {
      for (size_t i = 0; i < params.size(); ++i)
        if (iequals(params[i]->name, a.name->text)) idx = i;
      if (idx == SIZE_MAX) {
        for (Symbol* o : m->outputs)
          if (iequals(o->name, a.name->text)) outs.emplace_back(o, &a);
        if (outs.empty() || outs.back().second != &a)
          diags_.error("ST212", a.loc, "method " + m->name + " has no parameter '" + a.name->text + "'");
        continue;
      }
    } else {
      idx = pos++;
      if (idx >= params.size()) {
        diags_.error("ST210", a.loc, "too many arguments for method " + m->name);
        break;
      }
    }
    bound[idx] = &a;
    order.push_back(idx);
  }
  // A value read from a variable is copied when a later argument may run a call (which
  // could change that variable), so that each argument is read in its turn, as a
  // FUNCTION's are.
  std::vector<bool> call_after(order.size(), false);
  for (size_t k = order.size(); k-- > 1;)
    call_after[k - 1] = call_after[k] || (bound[order[k]]->value && may_call(*bound[order[k]]->value));
  struct Staged {
    Val v;
    bool direct = true;  // v still to be coerced into the field; else v.slot holds the field's value
    bool ok = false;
  };
  std::vector<Staged> staged(params.size());
  for (size_t k = 0; k < order.size(); ++k) {
    size_t i = order[k];
    Symbol* p = params[i];
    const CallArg* a = bound[i];
    if (!a->value) continue;
    Staged& st = staged[i];
    if (p->where == Where::InOut) {
      Place src = place(*a->value, true);
      if (!src.ok) continue;
      st.v.type = elem(TypeKind::UDInt);
      st.v.slot = addr_of(src, a->loc);
    } else {
      st.v = expr_for(*a->value, p->type);
      if (!st.v.ok) continue;
    }
    st.ok = true;
    bool from_variable = !st.v.is_const && (st.v.slot.kind == SK::Var || st.v.slot.kind == SK::Hidden);
    if (from_variable && call_after[k]) {
      const Type* t = p->where == Where::InOut ? elem(TypeKind::UDInt) : p->type;
      Slot copy = t->is_string() ? temp(t->size, 1) : temp_for(t);
      Place dst = frame_place(copy, t);
      assign(dst, st.v, a->loc);
      st.v.type = t;
      st.v.is_const = false;
      st.v.slot = copy;
      st.direct = false;
    }
  }
  Slot frame = temp(4, 4);
  emit(Op::FRAME, {frame});
  if (!virt) emit(Op::STI4, {frame, 8u, this_ptr});
  // Every input is written: given ones from the call, the others from their defaults
  // (a method's frame is fresh on each call).
  for (size_t i = 0; i < params.size(); ++i) {
    Symbol* p = params[i];
    Place field;
    field.k = Place::K::Ind;
    field.ptr = frame;
    field.off = p->offset;
    field.type = p->where == Where::InOut ? elem(TypeKind::UDInt) : p->type;
    if (p->where == Where::InOut) {
      if (!bound[i] || !bound[i]->value) {
        diags_.error("ST224", c.loc, "VAR_IN_OUT '" + p->name + "' of method " + m->name + " must be passed");
        continue;
      }
      if (staged[i].ok) store(field, staged[i].v.slot);
      continue;
    }
    if (bound[i] && bound[i]->value) {
      if (!staged[i].ok) continue;
      if (staged[i].direct) assign(field, staged[i].v, bound[i]->loc);
      else store(field, staged[i].v.slot);
    } else {
      store(field, konst_bytes(p->init.data(), static_cast<uint32_t>(p->init.size()), p->type->align));
    }
  }
  mark(c.loc);
  if (virt) emit(Op::CALLV, {frame, this_ptr, m->selector});
  else emit(Op::CALLS, {frame, Arg::entry(m)});
  auto frame_field = [&](uint32_t off, const Type* t) {
    Place f;
    f.k = Place::K::Ind;
    f.ptr = frame;
    f.off = off;
    f.type = t;
    return f;
  };
  Val r;
  r.type = m->result;
  if (m->result && m->result->kind != TypeKind::Void) r = load(frame_field(m->result_offset, m->result));
  std::vector<Val> out_vals;
  for (auto [o, a] : outs) out_vals.push_back(a->value ? load(frame_field(o->offset, o->type)) : Val{});
  for (size_t k = 0; k < outs.size(); ++k) {
    const CallArg* a = outs[k].second;
    if (!a->value) continue;
    Val v = out_vals[k];
    if (a->negate) {
      Slot t = temp(1, 1);
      emit(Op::BNOT, {t, v.slot});
      v.slot = t;
    }
    assign(place(*a->value, true), v, a->loc);
  }
  return r;
}

Val Compiler::property_get(const Place& inst, PouInfo* getter, Slot this_ptr, SourceLoc loc) {
  CallExpr c(loc);
  bool virt = !inst.ok || inst.type == nullptr || inst.type->kind != TypeKind::Pou ||
              (b_->this_type && inst.type == b_->this_type);
  return call_method(c, getter, &inst, this_ptr, virt);
}

void Compiler::property_set(PouInfo* setter, Slot this_ptr, const Val& v, SourceLoc loc) {
  declare_pou(setter);
  if (!v.ok) return;
  if (setter->inputs.empty()) return;
  Slot frame = temp(4, 4);
  emit(Op::FRAME, {frame});
  Place field;
  field.k = Place::K::Ind;
  field.ptr = frame;
  field.off = setter->inputs[0]->offset;
  field.type = setter->inputs[0]->type;
  assign(field, v, loc);
  mark(loc);
  emit(Op::CALLV, {frame, this_ptr, setter->selector});
}

// ------------------------------------------------------------------ standard functions

std::optional<Val> Compiler::conversion(const std::string& name, const CallExpr& c) {
  size_t at = name.find("_TO_");
  std::string from_name, to_name;
  if (at != std::string::npos) {
    from_name = name.substr(0, at);
    to_name = name.substr(at + 4);
  } else if (name.rfind("TO_", 0) == 0) {
    to_name = name.substr(3);
  } else if (name == "TRUNC") {
    to_name = "DINT";
  } else {
    return std::nullopt;
  }
  const Type* to = tt_->by_name(to_name);
  const Type* from = from_name.empty() ? nullptr : tt_->by_name(from_name);
  if (!to || (!from_name.empty() && !from)) return std::nullopt;
  auto args = positional(c, 1, 1, name.c_str());
  if (args.empty()) return bad();
  Val v = expr(*args[0], from);
  if (!v.ok) return bad();
  if (from) {
    v = coerce(v, from, args[0]->loc, name.c_str());
    if (!v.ok) return bad();
  } else {
    from = v.type ? v.type : default_type(v.c);
  }
  Slot s = to_slot(v, from, args[0]->loc);
  const Type* I64 = elem(TypeKind::LInt);
  const Type* F64 = elem(TypeKind::LReal);
  auto cvt = [&](Slot x, const Type* a, const Type* b) { return convert(x, a, b); };
  auto mul = [&](Slot x, int64_t k, Op op) {
    Slot d = temp(8, 8);
    emit(num_op(op, Storage::I64), {d, x, konst_i64(k)});
    def(d);
    return d;
  };
  Val out;
  out.type = to;
  if (from->kind == TypeKind::Enum) from = from->base;  // TO_INT(enum value)
  TypeKind fk = from->kind;
  TypeKind tk = to->kind;
  bool from_dur_ms = fk == TypeKind::Time;
  bool to_dur_ms = tk == TypeKind::Time;
  if (name == "TRUNC" || (name.find("TRUNC") != std::string::npos)) {
    if (!from->is_real()) {
      diags_.error("ST203", args[0]->loc, "TRUNC needs a REAL or LREAL, not " + from->name);
      return bad();
    }
    Slot t = temp_for(from);
    emit(from->kind == TypeKind::Real ? Op::TRUNC_F32 : Op::TRUNC_F64, {t, s});
    out.slot = cvt(t, from, to);
    return out;
  }
  if (tk == TypeKind::String || tk == TypeKind::WString) {
    const Type* st = tt_->string_type(80, tk == TypeKind::WString);
    if (from->is_string()) {
      out.slot = s;
      out.type = from;
      return out;
    }
    if (fk == TypeKind::Bool) return native(Native::BOOL_TO_S, st, {s}, 80);
    if (fk == TypeKind::Time || fk == TypeKind::LTime) return native(Native::TIME_TO_S, st, {s}, 80);
    if (fk == TypeKind::Date) return native(Native::DATE_TO_S, st, {s}, 80);
    if (fk == TypeKind::TimeOfDay) return native(Native::TOD_TO_S, st, {s}, 80);
    if (fk == TypeKind::DateTime) return native(Native::DT_TO_S, st, {s}, 80);
    if (fk == TypeKind::Real) return native(Native::F32_TO_S, st, {s}, 80);
    if (fk == TypeKind::LReal) return native(Native::F64_TO_S, st, {s}, 80);
    if (from->is_unsigned_int() || from->is_bitstring()) return native(Native::U64_TO_S, st, {cvt(s, from, elem(TypeKind::ULInt))}, 80);
    if (from->is_integer()) return native(Native::I64_TO_S, st, {cvt(s, from, I64)}, 80);
    return std::nullopt;
  }
  if (from->is_string()) {
    if (tk == TypeKind::Bool) return native(Native::S_TO_BOOL, to, {s});
    if (to->is_real()) {
      Val r = native(Native::S_TO_F64, F64, {s});
      out.slot = cvt(r.slot, F64, to);
      return out;
    }
    if (tk == TypeKind::Time || tk == TypeKind::LTime) return native(Native::S_TO_TIME, to, {s});
    if (to->is_integer() || to->is_bitstring()) {
      Val r = native(to->is_unsigned_int() || to->is_bitstring() ? Native::S_TO_U64 : Native::S_TO_I64, I64, {s});
      out.slot = cvt(r.slot, I64, to);
      return out;
    }
    return std::nullopt;
  }
  if (fk == TypeKind::DateTime && tk == TypeKind::Date) return native(Native::DT_TO_DATE, to, {s});
  if (fk == TypeKind::DateTime && tk == TypeKind::TimeOfDay) return native(Native::DT_TO_TOD, to, {s});
  if (from->is_time_like() && to->is_time_like()) {
    out.slot = s;
    return out;
  }
  if (tk == TypeKind::Bool) {
    if (fk == TypeKind::Bool) {
      out.slot = s;
      return out;
    }
    if (from->is_real()) {
      Slot t = temp(1, 1);
      emit(num_op(Op::NE_I8, from->storage()), {t, s, konst(from, ConstV{ConstV::K::Real, 0, 0.0, {}}, c.loc)});
      out.slot = t;
      return out;
    }
    Slot t = temp(1, 1);
    Op op = from->size == 1 ? Op::TOBOOL8 : from->size == 2 ? Op::TOBOOL16 : from->size == 4 ? Op::TOBOOL32 : Op::TOBOOL64;
    emit(op, {t, s});
    def(t);
    out.slot = t;
    return out;
  }
  if (from->is_time_like()) {
    // TIME counts in milliseconds when converted to numbers (as CODESYS and TwinCAT do).
    Slot x = from_dur_ms ? mul(s, 1'000'000, Op::DIV_I8) : s;
    if (to->is_real() && from_dur_ms) {
      Slot f = cvt(s, I64, F64);
      Slot d = temp(8, 8);
      emit(Op::DIV_F64, {d, f, konst(F64, ConstV{ConstV::K::Real, 0, 1e6, {}}, c.loc)});
      out.slot = cvt(d, F64, to);
      return out;
    }
    out.slot = cvt(x, I64, to);
    return out;
  }
  if (to->is_time_like()) {
    if (from->is_real()) {
      Slot f = cvt(s, from, F64);
      Slot d = temp(8, 8);
      emit(Op::MUL_F64, {d, f, konst(F64, ConstV{ConstV::K::Real, 0, to_dur_ms ? 1e6 : 1.0, {}}, c.loc)});
      out.slot = cvt(d, F64, I64);
      return out;
    }
    Slot x = cvt(s, from, I64);
    out.slot = to_dur_ms ? mul(x, 1'000'000, Op::MUL_I8) : x;
    return out;
  }
  if (from->is_real() && (to->is_integer() || to->is_bitstring())) {
    // REAL_TO_INT rounds to the nearest integer, halves away from zero.
    Slot t = temp_for(from);
    emit(from->kind == TypeKind::Real ? Op::ROUND_F32 : Op::ROUND_F64, {t, s});
    def(t);
    out.slot = cvt(t, from, to);
    return out;
  }
  if ((from->is_numeric() || from->is_anybit()) && (to->is_numeric() || to->is_anybit())) {
    out.slot = cvt(s, from, to);
    return out;
  }
  return std::nullopt;
}

// Temporal operators of requirement formulas (EDTL), only in monitors: each occurrence
// keeps its argument's current and previous value in hidden state; all are FALSE in the
// first state.
std::optional<Val> Compiler::temporal(const std::string& name, const CallExpr& c) {
  static const char* kOps[] = {"RISING", "FALLING", "HIGH", "LOW", "CHANGES", "INCREASES", "DECREASES", "PASSED"};
  bool known = false;
  for (const char* k : kOps) known = known || name == k;
  if (!known || !b_->pou || !is_late(b_->pou)) return std::nullopt;
  auto args = positional(c, 1, 1, name.c_str());
  if (args.empty()) return bad();
  const Type* BOOL = elem(TypeKind::Bool);
  if (name == "PASSED") {
    // time(i) - time(j) >= t, with the elapsed time since the timer point as an input.
    const Symbol* el = lookup("__ELAPSED");
    if (!el) {
      diags_.error("ST211", c.loc, "PASSED is not available here");
      return bad();
    }
    Val t = expr(*args[0]);
    if (!t.ok) return bad();
    if (!t.type || (t.type->kind != TypeKind::Time && t.type->kind != TypeKind::LTime)) {
      diags_.error("ST203", args[0]->loc, "PASSED needs a duration such as T#2s, not " + (t.type ? t.type->name : std::string("a number")));
      return bad();
    }
    Val e;
    e.type = el->type;
    e.slot = Slot{el->offset, SK::Var};
    return combine(BinaryOp::Ge, e, t, c.loc);
  }
  bool edge = name == "RISING" || name == "FALLING" || name == "HIGH" || name == "LOW";
  Val v = edge ? cond(*args[0]) : expr(*args[0]);
  if (!v.ok) return bad();
  const Type* t = v.type ? v.type : default_type(v.c);
  if (!edge && !(t->is_numeric() || t->is_bitstring() || t->is_time_like() || t->kind == TypeKind::Enum || t->kind == TypeKind::Bool)) {
    diags_.error("ST203", args[0]->loc, name + " needs a number, bit string, time or enumeration value, not " + t->name);
    return bad();
  }
  if (!edge && (name != "CHANGES") && !(t->is_numeric() || t->is_time_like() || t->is_bitstring())) {
    diags_.error("ST203", args[0]->loc, name + " needs an ordered value (a number or a time), not " + t->name);
    return bad();
  }
  Slot cur = hidden(t->size, t->align), prev = hidden(t->size, t->align);
  if (!b_->started) b_->started = hidden(1, 1);
  Slot src = to_slot(v, t, args[0]->loc);
  if (!retarget(src, cur)) emit(mov_op(t->size), {cur, src});
  b_->edges.push_back({cur, prev, t->size});
  auto tmp_bool = [&]() { return temp(1, 1); };
  if (edge) {
    // One instruction: RISING = cur AND NOT prev, FALLING, HIGH, LOW; FALSE before the
    // first committed state.
    Op op = name == "RISING" ? Op::RISE : name == "FALLING" ? Op::FALL : name == "HIGH" ? Op::STEADY_HIGH : Op::STEADY_LOW;
    Slot out = tmp_bool();
    emit(op, {out, cur, prev, *b_->started});
    def(out);
    Val res;
    res.type = BOOL;
    res.slot = out;
    return res;
  }
  Slot r = tmp_bool();
  Op cmp = name == "CHANGES" ? Op::NE_I8 : name == "INCREASES" ? Op::GT_I8 : Op::LT_I8;
  emit(num_op(cmp, t->storage()), {r, cur, prev});
  Slot out = tmp_bool();
  emit(Op::BAND, {out, r, *b_->started});
  def(out);
  Val res;
  res.type = BOOL;
  res.slot = out;
  return res;
}

std::optional<Val> Compiler::builtin(const std::string& name, const CallExpr& c) {
  if (auto v = temporal(name, c)) return v;
  if (auto v = conversion(name, c)) return v;
  auto first_type = [&](std::vector<Val>& vals) -> const Type* {
    const Type* t = nullptr;
    for (auto& v : vals) {
      if (!v.type) continue;
      if (!t) t = v.type;
      else {
        const Type* ct = common_type(*tt_, t, v.type);
        if (!ct) return nullptr;
        t = ct;
      }
    }
    if (!t) {
      // Only untyped literals: the context's type when it can hold them (an integer
      // target for integer literals, a real one for any), else DINT / LREAL.
      bool real = false;
      for (auto& v : vals) real = real || v.c.k == ConstV::K::Real;
      const Type* want = call_expected_;
      if (want && (want->is_real() || (!real && (want->is_integer() || want->is_bitstring())))) return want;
      t = real ? elem(TypeKind::LReal) : elem(TypeKind::DInt);
    }
    return t;
  };
  auto eval_all = [&](const std::vector<const Expr*>& args) {
    std::vector<Val> vals;
    for (const Expr* a : args) vals.push_back(expr(*a));
    return vals;
  };
  auto ok_all = [](const std::vector<Val>& vals) {
    for (const auto& v : vals)
      if (!v.ok) return false;
    return true;
  };
  auto real_of = [&](const Type* t) { return t && t->kind == TypeKind::Real ? t : elem(TypeKind::LReal); };

  static const std::pair<const char*, Native> kMath[] = {
      {"SQRT", Native::SQRT_F32}, {"LN", Native::LN_F32},     {"LOG", Native::LOG_F32},   {"EXP", Native::EXP_F32},
      {"SIN", Native::SIN_F32},   {"COS", Native::COS_F32},   {"TAN", Native::TAN_F32},   {"ASIN", Native::ASIN_F32},
      {"ACOS", Native::ACOS_F32}, {"ATAN", Native::ATAN_F32},
  };
  for (auto [fn, nat] : kMath) {
    if (name != fn) continue;
    auto args = positional(c, 1, 1, fn);
    if (args.empty()) return bad();
    Val v = expr(*args[0]);
    if (!v.ok) return bad();
    const Type* from = v.type ? v.type : default_type(v.c);
    if (!from->is_numeric()) {
      diags_.error("ST203", args[0]->loc, std::string(fn) + " needs a number, not " + from->name);
      return bad();
    }
    const Type* rt = real_of(from);
    Slot s = v.is_const ? konst(rt, v.c, c.loc) : convert(v.slot, from, rt);
    return native(static_cast<Native>(static_cast<uint32_t>(nat) + (rt->kind == TypeKind::LReal ? 1 : 0)), rt, {s});
  }
  if (name == "EXPT") {
    auto args = positional(c, 2, 2, "EXPT");
    if (args.empty()) return bad();
    auto vals = eval_all(args);
    if (!ok_all(vals)) return bad();
    const Type* t = real_of(vals[0].type);
    Slot a = to_slot(coerce(vals[0], vals[0].type && !vals[0].type->is_real() ? vals[0].type : t, args[0]->loc, "EXPT"), vals[0].type && !vals[0].type->is_real() ? vals[0].type : t, args[0]->loc);
    a = convert(a, vals[0].type && !vals[0].type->is_real() ? vals[0].type : t, t);
    const Type* bt = vals[1].type ? vals[1].type : t;
    Slot b = vals[1].is_const ? konst(t, vals[1].c, args[1]->loc) : convert(vals[1].slot, bt, t);
    return native(t->kind == TypeKind::Real ? Native::EXPT_F32 : Native::EXPT_F64, t, {a, b});
  }
  if (name == "ABS") {
    auto args = positional(c, 1, 1, "ABS");
    if (args.empty()) return bad();
    Val v = expr(*args[0]);
    if (!v.ok) return bad();
    const Type* t = v.type ? v.type : default_type(v.c);
    if (!t->is_numeric()) {
      diags_.error("ST203", args[0]->loc, "ABS needs a number, not " + t->name);
      return bad();
    }
    Slot s = to_slot(v, t, c.loc);
    Slot d = temp_for(t);
    emit(num_op(Op::ABS_I8, t->storage()), {d, s});
    def(d);
    Val out;
    out.type = t;
    out.slot = d;
    return out;
  }
  if (name == "MIN" || name == "MAX" || name == "LIMIT") {
    auto args = positional(c, name == "LIMIT" ? 3 : 2, name == "LIMIT" ? 3 : SIZE_MAX, name.c_str());
    if (args.empty()) return bad();
    auto vals = eval_all(args);
    if (!ok_all(vals)) return bad();
    const Type* t = first_type(vals);
    if (!t || !(t->is_numeric() || t->is_bitstring() || t->is_time_like())) {
      diags_.error("ST203", c.loc, name + " needs numbers of compatible types");
      return bad();
    }
    std::vector<Slot> slots;
    for (size_t i = 0; i < vals.size(); ++i) {
      Val cv = coerce(vals[i], t, args[i]->loc, name.c_str());
      if (!cv.ok) return bad();
      slots.push_back(to_slot(cv, t, args[i]->loc));
    }
    auto op2 = [&](Op op, Slot a, Slot b) {
      Slot d = temp_for(t);
      emit(num_op(op, t->storage()), {d, a, b});
      def(d);
      return d;
    };
    Slot r;
    if (name == "LIMIT") r = op2(Op::MIN_I8, op2(Op::MAX_I8, slots[1], slots[0]), slots[2]);
    else {
      r = slots[0];
      for (size_t i = 1; i < slots.size(); ++i) r = op2(name == "MIN" ? Op::MIN_I8 : Op::MAX_I8, r, slots[i]);
    }
    Val out;
    out.type = t;
    out.slot = r;
    return out;
  }
  if (name == "SEL" || name == "MUX") {
    bool mux = name == "MUX";
    auto args = positional(c, mux ? 2 : 3, mux ? SIZE_MAX : 3, name.c_str());
    if (args.empty()) return bad();
    Val g = expr(*args[0]);
    if (!g.ok) return bad();
    std::vector<const Expr*> ins(args.begin() + 1, args.end());
    auto vals = eval_all(ins);
    if (!ok_all(vals)) return bad();
    const Type* t = first_type(vals);
    if (!t) {
      diags_.error("ST203", c.loc, name + " needs inputs of one type");
      return bad();
    }
    std::vector<Slot> slots;
    for (size_t i = 0; i < vals.size(); ++i) {
      Val cv = coerce(vals[i], t, ins[i]->loc, name.c_str());
      if (!cv.ok) return bad();
      slots.push_back(to_slot(cv, t, ins[i]->loc));
    }
    Slot d = t->is_string() ? temp(t->size, 1) : temp_for(t);
    auto copy = [&](Slot src) {
      if (t->is_string()) emit(Op::SCPY, {d, src, t->str_len});
      else if (t->size == 1 || t->size == 2 || t->size == 4 || t->size == 8) emit(mov_op(t->size), {d, src});
      else emit(Op::MOVN, {d, src, t->size});
    };
    Label end = new_label();
    if (!mux) {
      Val gc = coerce(g, elem(TypeKind::Bool), args[0]->loc, "SEL");
      if (!gc.ok) return bad();
      Slot gs = to_slot(gc, elem(TypeKind::Bool), args[0]->loc);
      Label l0 = new_label();
      emit(Op::JMPF, {Arg::target(l0.id), gs});
      copy(slots[1]);
      emit(Op::JMP, {Arg::target(end.id)});
      bind(l0);
      copy(slots[0]);
    } else {
      const Type* gt = g.type ? g.type : elem(TypeKind::DInt);
      if (!gt->is_integer()) {
        diags_.error("ST203", args[0]->loc, "MUX needs an integer selector");
        return bad();
      }
      Slot k = convert(to_slot(g, gt, args[0]->loc), gt, elem(TypeKind::DInt));
      Label bad_k = new_label();
      std::vector<Label> ls;
      std::vector<Arg> jt{k, 0u, static_cast<uint32_t>(slots.size()), Arg::target(bad_k.id)};
      for (size_t i = 0; i < slots.size(); ++i) {
        ls.push_back(new_label());
        jt.push_back(Arg::target(ls.back().id));
      }
      emit_list(Op::JTAB, jt);
      for (size_t i = 0; i < slots.size(); ++i) {
        bind(ls[i]);
        copy(slots[i]);
        emit(Op::JMP, {Arg::target(end.id)});
      }
      bind(bad_k);
      mark(c.loc);
      emit(Op::TRAP, {static_cast<uint32_t>(TrapKind::IndexOutOfRange)});
    }
    bind(end);
    Val out;
    out.type = t;
    out.slot = d;
    return out;
  }
  // Functional forms of the operators (ADD, GT, ...) and the named time functions.
  static const std::pair<const char*, BinaryOp> kOps[] = {
      {"ADD", BinaryOp::Add}, {"SUB", BinaryOp::Sub}, {"MUL", BinaryOp::Mul}, {"DIV", BinaryOp::Div},
      {"MOD", BinaryOp::Mod}, {"AND", BinaryOp::And}, {"OR", BinaryOp::Or},   {"XOR", BinaryOp::Xor},
      {"GT", BinaryOp::Gt},   {"GE", BinaryOp::Ge},   {"EQ", BinaryOp::Eq},   {"LE", BinaryOp::Le},
      {"LT", BinaryOp::Lt},   {"NE", BinaryOp::Ne},   {"ADD_TIME", BinaryOp::Add}, {"SUB_TIME", BinaryOp::Sub},
      {"MUL_TIME", BinaryOp::Mul}, {"DIV_TIME", BinaryOp::Div}, {"ADD_TOD_TIME", BinaryOp::Add},
      {"ADD_DT_TIME", BinaryOp::Add}, {"SUB_TOD_TIME", BinaryOp::Sub}, {"SUB_DT_TIME", BinaryOp::Sub},
      {"SUB_DATE_DATE", BinaryOp::Sub}, {"SUB_TOD_TOD", BinaryOp::Sub}, {"SUB_DT_DT", BinaryOp::Sub},
      {"ADD_LTIME", BinaryOp::Add}, {"SUB_LTIME", BinaryOp::Sub}, {"MUL_LTIME", BinaryOp::Mul}, {"DIV_LTIME", BinaryOp::Div},
  };
  for (auto [fn, op] : kOps) {
    if (name != fn) continue;
    bool extensible = op == BinaryOp::Add || op == BinaryOp::Mul || op == BinaryOp::And || op == BinaryOp::Or || op == BinaryOp::Xor;
    auto args = positional(c, 2, extensible && name.find('_') == std::string::npos ? SIZE_MAX : 2, fn);
    if (args.empty()) return bad();
    Val acc = expr(*args[0]);
    for (size_t i = 1; i < args.size() && acc.ok; ++i) {
      Val next = expr(*args[i], acc.type && acc.type->kind == TypeKind::Enum ? acc.type : nullptr);
      if (!next.ok) return bad();
      acc = combine(op, acc, next, c.loc);
    }
    return acc;
  }
  if (name == "CONCAT_DATE_TOD") {
    auto args = positional(c, 2, 2, "CONCAT_DATE_TOD");
    if (args.empty()) return bad();
    Val d = expr(*args[0]);
    Val t = expr(*args[1]);
    if (!d.ok || !t.ok) return bad();
    if (!d.type || d.type->kind != TypeKind::Date || !t.type || t.type->kind != TypeKind::TimeOfDay) {
      diags_.error("ST203", c.loc, "CONCAT_DATE_TOD needs a DATE and a TIME_OF_DAY");
      return bad();
    }
    const Type* I64 = elem(TypeKind::LInt);
    Slot a = d.is_const ? konst(I64, d.c, c.loc) : d.slot;
    Slot b = t.is_const ? konst(I64, t.c, c.loc) : t.slot;
    Slot r = temp(8, 8);
    emit(Op::ADD_I64, {r, a, b});
    def(r);
    Val out;
    out.type = elem(TypeKind::DateTime);
    out.slot = r;
    return out;
  }
  if (name == "MOVE") {
    auto args = positional(c, 1, 1, "MOVE");
    if (args.empty()) return bad();
    return expr(*args[0]);
  }
  if (name == "SHL" || name == "SHR" || name == "ROL" || name == "ROR") {
    auto args = positional(c, 2, 2, name.c_str());
    if (args.empty()) return bad();
    Val v = expr(*args[0]);
    Val n = expr(*args[1]);
    if (!v.ok || !n.ok) return bad();
    const Type* t = v.type ? v.type : elem(TypeKind::DWord);
    if (!t->is_bitstring() && !t->is_integer()) {
      diags_.error("ST203", args[0]->loc, name + " needs a bit string or integer, not " + t->name);
      return bad();
    }
    const Type* nt = n.type ? n.type : elem(TypeKind::LInt);
    if (!nt->is_integer() && !nt->is_bitstring()) {
      diags_.error("ST203", args[1]->loc, name + ": the shift count must be an integer");
      return bad();
    }
    Slot a = to_slot(v, t, args[0]->loc);
    Slot b = n.is_const ? konst(elem(TypeKind::ULInt), n.c, args[1]->loc) : convert(n.slot, nt, elem(TypeKind::ULInt));
    Op base = name == "SHL" ? Op::SHL_I8 : name == "SHR" ? Op::SHR_I8 : name == "ROL" ? Op::ROL_I8 : Op::ROR_I8;
    Slot d = temp_for(t);
    emit(int_op(base, t->storage()), {d, a, b});
    def(d);
    Val out;
    out.type = t;
    out.slot = d;
    return out;
  }
  // Strings.
  auto str_arg = [&](const Expr* e) -> std::optional<Slot> {
    Val v = expr(*e);
    if (!v.ok) return std::nullopt;
    const Type* t = v.type ? v.type : default_type(v.c);
    if (!t->is_string()) {
      diags_.error("ST203", e->loc, name + " needs a STRING here, not " + t->name);
      return std::nullopt;
    }
    return v.is_const ? konst(t, v.c, e->loc) : v.slot;
  };
  auto int_arg = [&](const Expr* e) -> std::optional<Slot> {
    Val v = expr(*e);
    if (!v.ok) return std::nullopt;
    const Type* t = v.type ? v.type : elem(TypeKind::LInt);
    if (!t->is_integer()) {
      diags_.error("ST203", e->loc, name + " needs an integer here, not " + t->name);
      return std::nullopt;
    }
    return v.is_const ? konst(elem(TypeKind::LInt), v.c, e->loc) : convert(v.slot, t, elem(TypeKind::LInt));
  };
  const Type* rstr = tt_->string_type(255, false);
  // String functions with fixed operand lists: S = string, I = integer (passed as LINT).
  struct StringFn {
    const char* name;
    const char* args;
    Native fn;
    bool int_result;
  };
  static const StringFn kStringFns[] = {
      {"LEN", "S", Native::S_LEN, true},           {"LEFT", "SI", Native::S_LEFT, false},
      {"RIGHT", "SI", Native::S_RIGHT, false},     {"MID", "SII", Native::S_MID, false},
      {"INSERT", "SSI", Native::S_INSERT, false},  {"DELETE", "SII", Native::S_DELETE, false},
      {"FIND", "SS", Native::S_FIND, true},
  };
  for (const auto& f : kStringFns) {
    if (name != f.name) continue;
    size_t n = std::strlen(f.args);
    auto args = positional(c, n, n, f.name);
    if (args.empty()) return bad();
    std::vector<Slot> slots;
    for (size_t i = 0; i < n; ++i) {
      auto s = f.args[i] == 'S' ? str_arg(args[i]) : int_arg(args[i]);
      if (!s) return bad();
      slots.push_back(*s);
    }
    return native_list(f.fn, f.int_result ? elem(TypeKind::Int) : rstr, slots, f.int_result ? 0 : 255);
  }
  if (name == "CONCAT") {
    auto args = positional(c, 2, SIZE_MAX, "CONCAT");
    if (args.empty()) return bad();
    auto s = str_arg(args[0]);
    if (!s) return bad();
    Slot acc = *s;
    for (size_t i = 1; i < args.size(); ++i) {
      auto n = str_arg(args[i]);
      if (!n) return bad();
      acc = native(Native::S_CONCAT, rstr, {acc, *n}, 255).slot;
    }
    Val out;
    out.type = rstr;
    out.slot = acc;
    return out;
  }
  if (name == "INSERT") {
    auto args = positional(c, 3, 3, "INSERT");
    if (args.empty()) return bad();
    auto a = str_arg(args[0]);
    auto b = str_arg(args[1]);
    auto p = int_arg(args[2]);
    if (!a || !b || !p) return bad();
    return native(Native::S_INSERT, rstr, {*a, *b, *p}, 255);
  }
  if (name == "DELETE") {
    auto args = positional(c, 3, 3, "DELETE");
    if (args.empty()) return bad();
    auto a = str_arg(args[0]);
    auto l = int_arg(args[1]);
    auto p = int_arg(args[2]);
    if (!a || !l || !p) return bad();
    return native(Native::S_DELETE, rstr, {*a, *l, *p}, 255);
  }
  if (name == "REPLACE") {
    auto args = positional(c, 4, 4, "REPLACE");
    if (args.empty()) return bad();
    auto a = str_arg(args[0]);
    auto b = str_arg(args[1]);
    auto l = int_arg(args[2]);
    auto p = int_arg(args[3]);
    if (!a || !b || !l || !p) return bad();
    Slot lp = temp(16, 8);
    emit(Op::MOV8, {lp, *l});
    emit(Op::MOV8, {lp.plus(8), *p});
    return native(Native::S_REPLACE, rstr, {*a, *b, lp}, 255);
  }
  if (name == "ADR" || name == "REF") {
    auto args = positional(c, 1, 1, name.c_str());
    if (args.empty()) return bad();
    Place p = place(*args[0], true);
    if (!p.ok) return bad();
    Val out;
    out.type = tt_->ref_to(p.type);
    out.slot = addr_of(p, args[0]->loc);
    return out;
  }
  if (name == "SIZEOF") {
    auto args = positional(c, 1, 1, "SIZEOF");
    if (args.empty()) return bad();
    Val v = expr(*args[0]);
    if (!v.ok) return bad();
    const Type* t = v.type ? v.type : default_type(v.c);
    Val out;
    out.is_const = true;
    out.type = elem(TypeKind::UDInt);
    out.c = ConstV{ConstV::K::Int, t->size, 0, {}};
    return out;
  }
  if (name == "__NOW") {
    Slot d = temp(8, 8);
    emit(Op::NOW, {d});
    def(d);
    Val out;
    out.type = elem(TypeKind::Time);
    out.slot = d;
    return out;
  }

  // Test-file built-ins.
  static const std::pair<const char*, AssertKind> kAsserts[] = {
      {"ASSERT_EQ", AssertKind::Eq}, {"ASSERT_NEQ", AssertKind::Neq}, {"ASSERT_GT", AssertKind::Gt},
      {"ASSERT_LT", AssertKind::Lt}, {"ASSERT_GE", AssertKind::Ge},   {"ASSERT_LE", AssertKind::Le},
      {"ASSERT_TRUE", AssertKind::True}, {"ASSERT_FALSE", AssertKind::False}, {"ASSERT_NEAR", AssertKind::Near},
      {"MOCK_VERIFY_CALLED", AssertKind::Called}, {"MOCK_VERIFY_CALL_COUNT", AssertKind::CallCount},
  };
  bool is_test_builtin = name == "ADVANCE_TIME";
  AssertKind kind = AssertKind::Eq;
  for (auto [n, k] : kAsserts)
    if (name == n) {
      is_test_builtin = true;
      kind = k;
    }
  if (!is_test_builtin) return std::nullopt;
  if (!b_->in_test) {
    diags_.error("ST211", c.loc, name + " is only available in TEST, SETUP and TEARDOWN blocks of test files");
    return bad();
  }
  Val none;
  none.type = elem(TypeKind::Void);
  std::vector<const Expr*> args;
  for (const auto& a : c.args) {
    if (a.name || a.is_output) {
      diags_.error("ST210", a.loc, name + " takes positional arguments");
      return bad();
    }
    args.push_back(a.value.get());
  }
  if (name == "ADVANCE_TIME") {
    if (args.size() != 1) {
      diags_.error("ST210", c.loc, "ADVANCE_TIME takes one duration");
      return bad();
    }
    Val v = expr(*args[0]);
    if (!v.ok) return bad();
    const Type* t = v.type ? v.type : elem(TypeKind::LInt);
    if (!(t->kind == TypeKind::Time || t->kind == TypeKind::LTime || t->is_integer())) {
      diags_.error("ST203", args[0]->loc, "ADVANCE_TIME needs a TIME or a number of nanoseconds, not " + t->name);
      return bad();
    }
    Slot s = v.is_const ? konst_i64(v.c.i) : convert(v.slot, t, elem(TypeKind::LInt));
    emit(Op::ADVTIME, {s});
    return none;
  }
  size_t nvals = (kind == AssertKind::True || kind == AssertKind::False || kind == AssertKind::Called) ? 1
                 : kind == AssertKind::Near ? 3 : 2;
  if (args.size() != nvals && args.size() != nvals + 1) {
    diags_.error("ST210", c.loc, name + " takes " + std::to_string(nvals) + " argument(s) and an optional message");
    return bad();
  }
  std::optional<Slot> msg;
  if (args.size() == nvals + 1) {
    Val m = expr(*args.back());
    if (!m.ok) return bad();
    if (!m.type || !m.type->is_string()) {
      diags_.error("ST203", args.back()->loc, "the assertion message must be a string");
      return bad();
    }
    msg = m.is_const ? konst(m.type, m.c, args.back()->loc) : m.slot;
  }
  auto emit_assert = [&](uint32_t kindword, Slot a, Slot b, Slot tol) {
    mark(c.loc);
    emit(Op::ASSERT, {kindword, a, b, tol, msg ? Arg(*msg) : Arg(0u)});
  };
  bool instance_arg = kind == AssertKind::Called || kind == AssertKind::CallCount;
  std::vector<Val> vals;
  for (size_t i = 0; i < nvals; ++i) {
    vals.push_back(instance_arg && i == 0 ? Val{} : expr(*args[i]));
    if (!vals.back().ok) return bad();
  }
  if (instance_arg) {
    Place p = place(*args[0], false);
    if (!p.ok || p.type->kind != TypeKind::Pou) {
      diags_.error("ST234", args[0]->loc, name + " needs a function block instance");
      return bad();
    }
    Slot ptr = addr_of(p, args[0]->loc);
    Slot cnt = ptr;
    if (kind == AssertKind::CallCount) {
      Val cv = coerce(vals[1], elem(TypeKind::LInt), args[1]->loc, name.c_str());
      if (!cv.ok) return bad();
      cnt = to_slot(cv, elem(TypeKind::LInt), args[1]->loc);
    }
    emit_assert(static_cast<uint32_t>(kind) << 8, ptr, cnt, ptr);
    return none;
  }
  if (kind == AssertKind::True || kind == AssertKind::False) {
    Val cv = coerce(vals[0], elem(TypeKind::Bool), args[0]->loc, name.c_str());
    if (!cv.ok) return bad();
    Slot s = to_slot(cv, elem(TypeKind::Bool), args[0]->loc);
    emit_assert((static_cast<uint32_t>(kind) << 8) | static_cast<uint32_t>(ValueKind::Bool), s, s, s);
    return none;
  }
  if (kind == AssertKind::Near) {
    const Type* F64 = elem(TypeKind::LReal);
    Slot s3[3];
    for (int i = 0; i < 3; ++i) {
      const Type* t = vals[i].type && vals[i].type->is_numeric() ? vals[i].type : F64;
      Val cv = coerce(vals[i], t, args[i]->loc, name.c_str());
      if (!cv.ok) return bad();
      s3[i] = convert(to_slot(cv, t, args[i]->loc), t, F64);
    }
    emit_assert((static_cast<uint32_t>(kind) << 8) | static_cast<uint32_t>(ValueKind::F64), s3[0], s3[1], s3[2]);
    return none;
  }
  const Type* t = first_type(vals);
  if (vals[0].type && vals[1].type && vals[0].type->kind == TypeKind::Enum && vals[0].type != vals[1].type) t = nullptr;
  if (vals[0].type && vals[1].type && vals[0].type->is_string() && vals[1].type->is_string()) t = vals[0].type;
  if (!t) {
    diags_.error("ST203", c.loc, name + ": cannot compare " + (vals[0].type ? vals[0].type->name : std::string("a literal")) + " with " +
                                     (vals[1].type ? vals[1].type->name : std::string("a literal")));
    return bad();
  }
  Val c0 = coerce(vals[0], t, args[0]->loc, name.c_str());
  Val c1 = coerce(vals[1], t, args[1]->loc, name.c_str());
  if (!c0.ok || !c1.ok) return bad();
  Slot a = t->is_string() && c0.is_const ? konst(vals[0].type, c0.c, args[0]->loc) : to_slot(c0, t, args[0]->loc);
  Slot b = t->is_string() && c1.is_const ? konst(vals[1].type, c1.c, args[1]->loc) : to_slot(c1, t, args[1]->loc);
  emit_assert((static_cast<uint32_t>(kind) << 8) | static_cast<uint32_t>(value_kind(t)), a, b, a);
  return none;
}

}  // namespace plcfi::st::detail
