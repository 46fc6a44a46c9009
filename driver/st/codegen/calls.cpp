// Calls of user code: functions (frames inside the caller's frame), function block
// instances, methods and properties (frames on the method stack, static or dynamic
// dispatch). Names that are none of these go to the standard functions (builtins.cpp).
#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>

#include "compiler_impl.hpp"
#include "sema/stdfuncs.hpp"

namespace plcfi::st::detail {

// Whether evaluating e may run a call (a function, a method, a property getter), which
// could change variables or take the method stack's top. Conservative: only literals,
// variables, fields of a named structure or instance, and operators over them are known
// to run none. Iterative, so that a long operator chain costs no stack.
namespace {
// Standard functions whose result depends on their inputs alone and that write nothing.
bool pure_std_family(StdFamily f) {
  switch (f) {
    case StdFamily::Math: case StdFamily::Expt: case StdFamily::Abs: case StdFamily::Extremum: case StdFamily::Sel:
    case StdFamily::Mux: case StdFamily::Operator: case StdFamily::ConcatDateTod: case StdFamily::Move: case StdFamily::Shift:
    case StdFamily::String: case StdFamily::Concat: case StdFamily::Replace: case StdFamily::SizeOf: case StdFamily::Bound:
      return true;
    default: return false;
  }
}
}  // namespace

// The type of a path made of a variable, elements and fields (`a`, `a[i].b`, `s.c[j]`), or
// null for anything else: a path that reads no property and calls nothing.
const Type* Compiler::field_path_type(const Expr& e) const {
  switch (e.kind) {
    case ExprKind::Name: {
      const Symbol* s = lookup(canon(static_cast<const NameExpr&>(e).name.text));
      return s && s->kind == SymKind::Var ? s->type : nullptr;
    }
    case ExprKind::Index: {
      const Type* t = field_path_type(*static_cast<const IndexExpr&>(e).base);
      return t && t->kind == TypeKind::Array ? t->elem : nullptr;
    }
    case ExprKind::Member: {
      const auto& m = static_cast<const MemberExpr&>(e);
      const Type* t = field_path_type(*m.base);
      if (!t || (t->kind != TypeKind::Struct && t->kind != TypeKind::Pou)) return nullptr;
      const Field* f = t->field(m.member.text);
      return f ? f->type : nullptr;
    }
    default: return nullptr;
  }
}

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
        // A field of a variable, of an element, of a field, ...: no call. Anything else
        // (a property, a method's result) may be one.
        const auto& m = static_cast<const MemberExpr&>(*e);
        const Type* t = field_path_type(*m.base);
        if (!t || (t->kind != TypeKind::Struct && t->kind != TypeKind::Pou) || !t->field(m.member.text)) return true;
        todo.push_back(m.base.get());
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
      case ExprKind::Call: {
        // A standard function that computes a value from its inputs (SHL, MIN, LEN,
        // INT_TO_DINT, ...) changes no variable: it is no call here.
        const auto& c = static_cast<const CallExpr&>(*e);
        if (c.callee->kind != ExprKind::Name) return true;
        const std::string key = canon(static_cast<const NameExpr&>(*c.callee).name.text);
        if (lookup(key) || pous_.count(key)) return true;
        if (const StdFunc* f = find_std_function(key)) {
          if (!pure_std_family(f->family) || (f->flags & ~kStdExtensible) != 0) return true;
        } else if (!parse_conversion(*tt_, key)) {
          return true;
        }
        for (const CallArg& a : c.args) {
          if (a.is_output || !a.value) return true;
          todo.push_back(a.value.get());
        }
        break;
      }
      default: return true;
    }
  }
  return false;
}

namespace {
// The implicit EN input / ENO output of a call, when the call names them.
const CallArg* enable_arg(const CallExpr& c, bool eno) {
  for (const auto& a : c.args)
    if (a.name && a.is_output == eno && iequals(a.name->text, eno ? "ENO" : "EN")) return &a;
  return nullptr;
}
}  // namespace

// ------------------------------------------------------------------ dispatch

Val Compiler::call(const CallExpr& c, bool as_statement) {
  mark(c.loc);
  const Expr& callee = *c.callee;
  if (!as_statement) {
    const CallArg* en = nullptr;
    const CallArg* eno = nullptr;
    if (implicit_enable(c, &en, &eno)) return enabled_value(c);
  }
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
      if (c.il_operator)
        diags_.error("ST245", callee.loc, "'" + n.name.text + "' is a " + s->type->name + " variable, not an IL operator "
                                          "(to load it: LD " + n.name.text + ")");
      else
        diags_.error("ST213", callee.loc, "'" + n.name.text + "' is a " + s->type->name + " variable, not callable");
      return bad();
    }
    auto it = pous_.find(key);
    if (it != pous_.end()) {
      PouInfo* p = it->second;
      if (p->kind == PouKind::Function) return call_function(p, c);
      if (p->kind == PouKind::Program && opt_.dialect == Dialect::Codesys) {  // MAIN(); its one instance
        Place inst = program_place(p, callee.loc);
        if (!inst.ok) return bad();
        return call_fb(inst, p, c);
      }
      diags_.error("ST213", callee.loc, "'" + n.name.text + "' is a " +
                                            (p->kind == PouKind::FunctionBlock ? std::string("function block type: declare an instance and call that") :
                                             p->kind == PouKind::Program ? std::string("PROGRAM type: it runs from a task, or declare an instance in a test "
                                                                                     "(calling a program by its name is CODESYS: --dialect codesys)") :
                                                                            std::string("interface")));
      return bad();
    }
    if (key == "__NEW" || key == "__DELETE") {
      diags_.error("ST235", callee.loc,
                   n.name.text + " (dynamic memory) is CODESYS that plcfi does not run: declare the instance as a variable");
      return bad();
    }
    if (key == "__QUERYINTERFACE" || key == "__QUERYPOINTER") return query_interface(c, key == "__QUERYPOINTER");
    if (auto b = builtin(key, c)) return *b;
    // A method of this instance called by its bare name.
    if (b_->this_type && b_->this_type->pou) {
      if (PouInfo* m = b_->this_type->pou->find_method(n.name.text)) {
        Place self = this_place(c.loc);
        return call_method(c, m, &self, addr_of(self, c.loc), true);
      }
    }
    // A vendor library's name says which library, so that the fix is clear: the dialect,
    // or a library plcfi does not have (then the project needs a stand-in of its own).
    std::string why;
    if (const char* lib = unprovided_library(n.name.text)) why = ": " + n.name.text + " is from " + lib + ", which plcfi does not provide";
    else if (const StdFunc* f = find_std_function(key); opt_.dialect != Dialect::Codesys &&
             ((f && f->codesys_only()) || std::any_of(tc2_system_items().begin(), tc2_system_items().end(),
                                                      [&](const Tc2Item& t) { return iequals(t.name, key); })))
      why = " (a function of TwinCAT's Tc2_System: --dialect codesys)";
    if (c.il_operator) {
      diags_.error("ST245", callee.loc, "unknown IL operator '" + n.name.text + "': neither an operator of Instruction List "
                                        "(LD, ST, S, R, AND, OR, XOR, NOT, ADD, ..., JMP, CAL, RET) nor a function" + why);
      return bad();
    }
    diags_.error("ST211", callee.loc, "unknown function '" + n.name.text + "'" + why);
    return bad();
  }
  if (callee.kind == ExprKind::Member) {
    const auto& m = static_cast<const MemberExpr&>(callee);
    bool via_super = m.base->kind == ExprKind::Deref && static_cast<const DerefExpr&>(*m.base).base->kind == ExprKind::Super;
    bool via_this = m.base->kind == ExprKind::Deref && static_cast<const DerefExpr&>(*m.base).base->kind == ExprKind::This;
    // Lib.F(): a FUNCTION of a library namespace (TcUnit.RUN()), when Lib names nothing else.
    if (m.base->kind == ExprKind::Name) {
      const std::string ns = canon(static_cast<const NameExpr&>(*m.base).name.text);
      if (!lookup(ns) && !pous_.count(ns) && !types_.count(ns)) {
        const std::string key = canon(m.member.text);
        if (auto it = pous_.find(key); it != pous_.end() && it->second->kind == PouKind::Function)
          return call_function(it->second, c);
        if (auto b = builtin(key, c)) return *b;
      }
    }
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
      // Calls through THIS, a reference or a VAR_IN_OUT (which may hold a derived
      // instance) dispatch on the instance's run-time type; SUPER and plain instances
      // (whose type is exactly their declaration) bind statically.
      bool indirect = base.k == Place::K::Ind && has_derived(base.type->pou);
      return call_method(c, meth, &base, addr_of(base, c.loc), (via_this || indirect) && !via_super);
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

// ------------------------------------------------------------------ EN/ENO

// The POU a call's callee names, where it is a user POU (function, FB instance, method);
// null for the standard functions and what cannot be told without compiling.
const PouInfo* Compiler::callee_pou(const Expr& callee) {
  if (callee.kind == ExprKind::Name) {
    const std::string key = canon(static_cast<const NameExpr&>(callee).name.text);
    if (const Symbol* s = lookup(key)) return s->kind == SymKind::Var && s->type && s->type->kind == TypeKind::Pou ? s->type->pou : nullptr;
    auto it = pous_.find(key);
    return it == pous_.end() ? nullptr : it->second;
  }
  if (callee.kind == ExprKind::Member) {
    const auto& m = static_cast<const MemberExpr&>(callee);
    if (m.base->kind != ExprKind::Name) return nullptr;
    const Symbol* s = lookup(canon(static_cast<const NameExpr&>(*m.base).name.text));
    if (!s || s->kind != SymKind::Var || !s->type || s->type->kind != TypeKind::Pou || !s->type->pou) return nullptr;
    if (const PouInfo* meth = s->type->pou->find_method(m.member.text)) return meth;
    if (const Symbol* f = s->type->pou->find_var(m.member.text); f && f->type && f->type->kind == TypeKind::Pou) return f->type->pou;
  }
  return nullptr;
}

// IEC 61131-3's EN/ENO on a call written in ST: `F(EN := c, ..., ENO => ok)`. With EN
// FALSE the POU does not run, its outputs are not captured and the variable its value is
// assigned to keeps its value (as an FBD box's connected variable does; MATIEC writes the
// result type's initial value instead); ENO is EN. A POU that declares EN or ENO itself
// takes them as ordinary parameters. A call with EN nested inside an expression (an FBD
// box feeding another) has the result type's initial value when EN is FALSE, as MATIEC
// computes it: enabled_value.
bool Compiler::enabled_call(const CallExpr& c, const AssignStmt* assignment) {
  const CallArg* en = nullptr;
  const CallArg* eno = nullptr;
  if (!implicit_enable(c, &en, &eno)) return false;
  Val enabled;
  if (!enable_flag(c, en, &enabled)) return true;
  Label skip = new_label();
  if (en) branch_on(enabled, c.loc, skip, false);
  without_enable(c, en, eno, [&] {
    if (assignment) assign_stmt(*assignment);
    else call(c, true);
  });
  bind(skip);
  b_->cvt_cache.clear();  // conversions cached in the skipped code were not computed
  capture_eno(c, enabled);
  return true;
}

Val Compiler::enabled_value(const CallExpr& c) {
  const CallArg* en = nullptr;
  const CallArg* eno = nullptr;
  implicit_enable(c, &en, &eno);
  Val enabled;
  if (!enable_flag(c, en, &enabled)) return bad();
  Label off = new_label(), done = new_label();
  if (en) branch_on(enabled, c.loc, off, false);
  Val r;
  without_enable(c, en, eno, [&] { r = call(c, false); });
  if (!r.ok) return bad();
  const Type* t = r.type ? r.type : default_type(r.c);
  if (!t || t->kind == TypeKind::Void || t->kind == TypeKind::Pou) {
    diags_.error("ST210", c.loc, "this call with EN gives no value to use in an expression; make it a statement");
    return bad();
  }
  Slot result = temp_for(t);
  assign(frame_place(result, t), r, c.loc);
  emit(Op::JMP, {Arg::target(done.id)});
  bind(off);
  // Not executed: the result type's initial value.
  const uint32_t size = t->size ? t->size : 1;
  const uint32_t blob = alloc(size, 8);
  std::copy(t->init.begin(), t->init.begin() + std::min<size_t>(t->init.size(), size), app_->init_image.begin() + blob);
  switch (size) {
    case 1: emit(Op::LDG1, {result, blob}); break;
    case 2: emit(Op::LDG2, {result, blob}); break;
    case 4: emit(Op::LDG4, {result, blob}); break;
    case 8: emit(Op::LDG8, {result, blob}); break;
    default: emit(Op::INITBLK, {result, blob, size}); break;
  }
  bind(done);
  b_->cvt_cache.clear();
  capture_eno(c, enabled);
  Val out;
  out.type = t;
  out.slot = result;
  return out;
}

// The EN input and ENO output a call names that its POU does not declare itself; false
// when there are none.
bool Compiler::implicit_enable(const CallExpr& c, const CallArg** en, const CallArg** eno) {
  *en = enable_arg(c, false);
  *eno = enable_arg(c, true);
  if (!*en && !*eno) return false;
  if (const PouInfo* p = callee_pou(*c.callee)) {
    if (*en && p->find_var("EN")) *en = nullptr;
    if (*eno && p->find_var("ENO")) *eno = nullptr;
  }
  return *en || *eno;
}

// The call's EN in a BOOL temporary (TRUE when it names none). False after an error.
bool Compiler::enable_flag(const CallExpr& c, const CallArg* en, Val* enabled) {
  const Type* boolean = elem(TypeKind::Bool);
  Slot flag = temp(1, 1);
  Place flag_place = frame_place(flag, boolean);
  enabled->type = boolean;
  enabled->slot = flag;
  if (en) {
    Val v = en->value ? expr(*en->value, boolean) : bad();
    if (!v.ok) return false;
    if (!v.type || v.type->kind != TypeKind::Bool) {
      diags_.error("ST204", en->value->loc, "EN needs a BOOL, not " + tname(v.type));
      return false;
    }
    assign(flag_place, v, en->loc);
  } else {
    store(flag_place, konst(boolean, ConstV{ConstV::K::Bool, 1, 0, {}}, c.loc));
  }
  return true;
}

// Compiles `body` with EN and ENO taken out of the call's argument list; they are put back
// where they were afterwards (the tree is compiled more than once).
void Compiler::without_enable(const CallExpr& c, const CallArg* en, const CallArg* eno, const std::function<void()>& body) {
  auto& args = const_cast<std::vector<CallArg>&>(c.args);
  std::vector<std::pair<size_t, CallArg>> held;
  for (size_t i = args.size(); i-- > 0;)
    if (&args[i] == en || &args[i] == eno) {
      held.emplace_back(i, std::move(args[i]));
      args.erase(args.begin() + static_cast<std::ptrdiff_t>(i));
    }
  body();
  for (auto it = held.rbegin(); it != held.rend(); ++it)
    args.insert(args.begin() + static_cast<std::ptrdiff_t>(it->first), std::move(it->second));
}

// ENO => target (or NOT ENO => target): the EN flag.
void Compiler::capture_eno(const CallExpr& c, const Val& enabled) {
  const CallArg* eno = enable_arg(c, true);
  if (const PouInfo* p = callee_pou(*c.callee); p && p->find_var("ENO")) eno = nullptr;
  if (!eno || !eno->value) return;
  Place target = place(*eno->value, true);
  if (!target.ok) return;
  if (target.type->kind != TypeKind::Bool) {
    diags_.error("ST203", eno->value->loc, "ENO is a BOOL; " + tname(target.type) + " cannot take it");
    return;
  }
  Val out = enabled;
  if (eno->negate) {
    Slot n = temp(1, 1);
    emit(Op::BNOT, {n, enabled.slot});
    out.slot = n;
  }
  assign(target, out, eno->loc);
}

// ------------------------------------------------------------------ functions

namespace {
// A positional argument after named ones takes the parameter declared after the last one
// named (CODESYS: `fb(a := 1, 2)` gives 2 to the parameter after a).
size_t next_position(const std::vector<Symbol*>& order, const Symbol* named, size_t pos) {
  auto it = std::find(order.begin(), order.end(), named);
  return it == order.end() ? pos : static_cast<size_t>(it - order.begin()) + 1;
}

// How many arguments a non-formal call must give: every parameter up to the last input or
// in-out (outputs after it may be left out, their values then not captured).
size_t non_formal_needed(const std::vector<Symbol*>& order) {
  size_t needed = 0;
  for (size_t i = 0; i < order.size(); ++i)
    if (order[i]->section != VarSection::Output) needed = i + 1;
  return needed;
}

// The names an expression mentions (reads, or passes on to a call that may write them);
// false for a form this does not look into.
bool mentions(const Expr* e, std::set<std::string>* out) {
  if (!e) return true;
  switch (e->kind) {
    case ExprKind::Literal:
    case ExprKind::EnumLiteral:
    case ExprKind::DirectAddr:
    case ExprKind::This:
    case ExprKind::Super: return true;
    case ExprKind::Name: out->insert(canon(static_cast<const NameExpr*>(e)->name.text)); return true;
    case ExprKind::Member: return mentions(static_cast<const MemberExpr*>(e)->base.get(), out);
    case ExprKind::BitAccess: return mentions(static_cast<const BitAccessExpr*>(e)->base.get(), out);
    case ExprKind::Deref: return mentions(static_cast<const DerefExpr*>(e)->base.get(), out);
    case ExprKind::Index: {
      const auto* ix = static_cast<const IndexExpr*>(e);
      for (const auto& i : ix->indices)
        if (!mentions(i.get(), out)) return false;
      return mentions(ix->base.get(), out);
    }
    case ExprKind::Call: {
      const auto* c = static_cast<const CallExpr*>(e);
      for (const auto& a : c->args) {
        if (a.name) out->insert(canon(a.name->text));
        if (!mentions(a.value.get(), out)) return false;
      }
      return mentions(c->callee.get(), out);
    }
    case ExprKind::Unary: return mentions(static_cast<const UnaryExpr*>(e)->operand.get(), out);
    case ExprKind::Binary: {
      // Iterative over the left spine: long operator chains are common.
      const Expr* cur = e;
      while (cur->kind == ExprKind::Binary) {
        const auto* b = static_cast<const BinaryExpr*>(cur);
        if (!mentions(b->rhs.get(), out)) return false;
        cur = b->lhs.get();
      }
      return mentions(cur, out);
    }
    default: return false;
  }
}

// The same for statements; false also where a path may leave the body early (RETURN).
bool mentions(const StmtList& list, std::set<std::string>* out);
bool mentions(const Stmt& s, std::set<std::string>* out) {
  switch (s.kind) {
    case StmtKind::Assign: {
      const auto& a = static_cast<const AssignStmt&>(s);
      return mentions(a.lhs.get(), out) && mentions(a.rhs.get(), out);
    }
    case StmtKind::Call: return mentions(static_cast<const CallStmt&>(s).call.get(), out);
    case StmtKind::If: {
      const auto& i = static_cast<const IfStmt&>(s);
      for (const auto& arm : i.arms)
        if (!mentions(arm.cond.get(), out) || !mentions(arm.body, out)) return false;
      return !i.else_body || mentions(*i.else_body, out);
    }
    case StmtKind::Case: {
      const auto& c = static_cast<const CaseStmt&>(s);
      if (!mentions(c.selector.get(), out)) return false;
      for (const auto& arm : c.arms) {
        for (const auto& l : arm.labels)
          if (!mentions(l.lo.get(), out) || !mentions(l.hi.get(), out)) return false;
        if (!mentions(arm.body, out)) return false;
      }
      return !c.else_body || mentions(*c.else_body, out);
    }
    case StmtKind::For: {
      const auto& f = static_cast<const ForStmt&>(s);
      return mentions(f.var.get(), out) && mentions(f.from.get(), out) && mentions(f.to.get(), out) &&
             mentions(f.by.get(), out) && mentions(f.body, out);
    }
    case StmtKind::While: {
      const auto& w = static_cast<const WhileStmt&>(s);
      return mentions(w.cond.get(), out) && mentions(w.body, out);
    }
    case StmtKind::Repeat: {
      const auto& r = static_cast<const RepeatStmt&>(s);
      return mentions(r.until.get(), out) && mentions(r.body, out);
    }
    case StmtKind::Exit:
    case StmtKind::Continue:
    case StmtKind::Empty: return true;
    default: return false;  // RETURN, test-file statements
  }
}
bool mentions(const StmtList& list, std::set<std::string>* out) {
  for (const auto& s : list)
    if (!mentions(*s, out)) return false;
  return true;
}
}  // namespace

// The frame ranges of a FUNCTION whose initial values no call needs: its VAR/VAR_TEMP
// scalars and its result that the body assigns, at the top level and with a plain `:=`,
// before any statement mentions them (so every path writes them before reading them).
// The walk stops at the first statement it cannot follow (a RETURN, anything unknown).
// Outputs are left out: a mocked FUNCTION returns without running its body.
const std::vector<std::pair<uint32_t, uint32_t>>& Compiler::written_first(PouInfo* f) {
  auto found = written_first_.find(f);
  if (found != written_first_.end()) return found->second;
  auto& ranges = written_first_[f];
  const Pou* decl = decl_of(f);
  if (!decl || f->kind != PouKind::Function) return ranges;
  std::map<std::string, std::pair<uint32_t, uint32_t>> candidates;
  for (const auto& v : f->vars)
    if (v->where == Where::Frame && (v->section == VarSection::Var || v->section == VarSection::Temp) && v->type &&
        v->type->is_elementary() && v->type->kind != TypeKind::Ref && v->type->kind != TypeKind::Interface && !v->constant)
      candidates[canon(v->name)] = {v->offset, v->type->size};
  if (f->result && f->result->is_elementary() && f->result->kind != TypeKind::Ref && f->result->kind != TypeKind::Interface &&
      f->result->kind != TypeKind::Void)
    candidates[canon(f->name)] = {f->result_offset, f->result->size};
  std::set<std::string> seen;  // mentioned so far
  for (const auto& st : decl->body) {
    if (st->kind == StmtKind::Assign) {
      const auto& a = static_cast<const AssignStmt&>(*st);
      // `r := F(EN := c, ...)` leaves r as it was when c is FALSE: not a first write.
      if (a.rhs->kind == ExprKind::Call && enable_arg(static_cast<const CallExpr&>(*a.rhs), false)) break;
      if (!a.is_ref_assign && !a.set_reset && a.lhs->kind == ExprKind::Name) {
        std::string key = canon(static_cast<const NameExpr&>(*a.lhs).name.text);
        if (!mentions(a.rhs.get(), &seen)) break;
        auto c = candidates.find(key);
        if (c != candidates.end() && !seen.count(key)) ranges.push_back(c->second);
        seen.insert(key);
        continue;
      }
    }
    if (!mentions(*st, &seen)) break;
  }
  return ranges;
}

// Copies the parts of the frame template a call needs: not the inputs it stores, not
// what the body writes before reading (written_first); the constants always.
void Compiler::init_function_frame(PouInfo* f, Slot frame, const std::vector<const Symbol*>& stored) {
  if (f->tmpl_to <= f->tmpl_from) return;
  // Per byte: 2 copy, 1 either way (header, written first), 0 never (the call stored it:
  // the arguments are in the frame already).
  std::vector<uint8_t> need(f->tmpl_to - f->tmpl_from, 2);
  auto mark_bytes = [&](uint32_t off, uint32_t size, uint8_t v) {
    for (uint32_t k = off; k < off + size; ++k)
      if (k >= f->tmpl_from && k < f->tmpl_to) need[k - f->tmpl_from] = std::min(need[k - f->tmpl_from], v);
  };
  mark_bytes(0, 8, 1);  // the header: a FUNCTION's is never read
  for (auto [off, size] : written_first(f)) mark_bytes(off, size, 1);
  for (const Symbol* s : stored) mark_bytes(s->offset, s->where == Where::InOut ? inout_slot_size(s->type) : s->type->size, 0);
  // Needed runs, joined across short either-way gaps when that saves an instruction.
  std::vector<std::pair<uint32_t, uint32_t>> runs;  // [from, to) relative to tmpl_from
  for (uint32_t k = 0; k < need.size();) {
    if (need[k] != 2) {
      ++k;
      continue;
    }
    uint32_t e = k;
    while (e < need.size() && need[e] == 2) ++e;
    bool gap_free = !runs.empty() && std::all_of(need.begin() + runs.back().second, need.begin() + k, [](uint8_t v) { return v == 1; });
    if (gap_free && k - runs.back().second <= 8) {
      uint32_t merged = e - runs.back().first;
      if (merged > 8 || merged == 4 || merged == 8) {
        runs.back().second = e;
        k = e;
        continue;
      }
    }
    runs.emplace_back(k, e);
    k = e;
  }
  for (auto [from, to] : runs) {
    uint32_t n = to - from;
    Slot dst = frame.plus(f->tmpl_from + from);
    uint32_t src_addr = f->template_addr + from;
    switch (n) {
      case 1: emit(Op::LDG1, {dst, src_addr}); break;
      case 2: emit(Op::LDG2, {dst, src_addr}); break;
      case 4: emit(Op::LDG4, {dst, src_addr}); break;
      case 8: emit(Op::LDG8, {dst, src_addr}); break;
      default: emit(Op::INITBLK, {dst, src_addr, n}); break;
    }
  }
}

Val Compiler::call_function(PouInfo* f, const CallExpr& c) {
  ensure_compiled(f, c.loc);
  if (!f->compiled) return bad();
  Slot frame = temp(f->frame_size, 8);
  std::vector<const Symbol*> stored;  // parameters this call writes into the frame
  std::vector<Symbol*> params = f->inputs;
  params.insert(params.end(), f->inouts.begin(), f->inouts.end());
  const std::vector<Symbol*> order = positional_params(f);
  size_t pos = 0;
  struct OutCapture {
    Symbol* sym;
    const CallArg* arg;
  };
  std::vector<OutCapture> outs;
  std::vector<bool> given(params.size(), false);
  std::vector<Symbol*> bound_syms;
  bool named_before = false;
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
      pos = next_position(order, p, pos);
      named_before = true;
    } else {
      if (named_before && !positional_after_named_ok(a.loc)) continue;
      if (pos >= order.size()) {
        diags_.error("ST210", a.loc, f->name + " takes " + std::to_string(order.size()) + " argument(s)");
        break;
      }
      p = order[pos++];
    }
    if (std::find(bound_syms.begin(), bound_syms.end(), p) != bound_syms.end()) {
      diags_.error("ST212", a.loc, "'" + p->name + "' of " + f->name + " is given twice");
      continue;
    }
    bound_syms.push_back(p);
    if (a.is_output || p->section == VarSection::Output) {
      if (!a.is_output && a.name) {
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
      if (bind_inout(frame_place(frame.plus(p->offset), elem(TypeKind::UDInt)), p, *a.value)) stored.push_back(p);
      continue;
    }
    if (is_reference(p->type)) {  // a REFERENCE TO input is bound to the argument
      bind_reference(frame_place(frame.plus(p->offset), p->type), *a.value, a.value->loc);
      stored.push_back(p);
      continue;
    }
    Val v = expr_for(*a.value, p->type);
    assign(frame_place(frame.plus(p->offset), p->type), v, a.value->loc);
    stored.push_back(p);  // whole: a STRING's bytes past its end are never read
  }
  // A non-formal call lists every input in order (IEC 61131-3 6.6.1.4.2); only a formal
  // call may leave inputs at their initial values.
  // Outputs after the last input may be left out (their values are then not captured).
  bool any_named = std::any_of(c.args.begin(), c.args.end(), [](const CallArg& a) { return a.name.has_value(); });
  size_t needed = non_formal_needed(order);
  if (!any_named && pos > 0 && pos < needed)
    diags_.error("ST210", c.loc,
                 fmt::format("{} takes {} argument(s), {} given; a non-formal call lists every input (or name them: {}({} := ...))",
                             f->name, needed, pos, f->name, order[pos]->name));
  else
    for (size_t i = 0; i < params.size(); ++i)
      if (!given[i] && params[i]->where == Where::InOut)
        diags_.error("ST224", c.loc, "VAR_IN_OUT '" + params[i]->name + "' of " + f->name + " must be passed");
  init_function_frame(f, frame, stored);
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
  const std::vector<Symbol*> order = positional_params(fb);
  size_t pos = 0;
  std::vector<Symbol*> passed;
  std::vector<Symbol*> bound_syms;
  bool named_before = false;
  for (const auto& a : c.args) {
    Symbol* p = nullptr;
    if (a.name) {
      p = fb->find_var(a.name->text);
      if (!p || (p->section != VarSection::Input && p->section != VarSection::Output && p->section != VarSection::InOut)) {
        diags_.error("ST212", a.loc, fb->name + " has no input or output '" + a.name->text + "'");
        continue;
      }
      pos = next_position(order, p, pos);
      named_before = true;
    } else {
      if (named_before && !positional_after_named_ok(a.loc)) continue;
      if (pos >= order.size()) {
        diags_.error("ST210", a.loc, "too many arguments for " + fb->name);
        break;
      }
      p = order[pos++];
    }
    if (std::find(bound_syms.begin(), bound_syms.end(), p) != bound_syms.end()) {
      diags_.error("ST212", a.loc, "'" + p->name + "' of " + fb->name + " is given twice");
      continue;
    }
    bound_syms.push_back(p);
    if (a.is_output || p->section == VarSection::Output) {
      if (!a.is_output && a.name) {
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
      bind_inout(field, p, *a.value);
      continue;
    }
    if (is_reference(p->type)) {  // a REFERENCE TO input is bound to the argument
      bind_reference(field, *a.value, a.value->loc);
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
      Slot copy = p->type->is_string() ? temp(p->type->size, p->type->align) : temp_for(p->type);
      store(frame_place(copy, p->type), v.slot);
      v.slot = copy;
    }
    out_vals.push_back(v);
  }
  store_outputs(outs, out_vals);
  return none;
}

// The `x => v` and `NOT x => v` arguments of a call, in order, from the output values
// read out of the callee's frame after the call (one per output, invalid where unused).
void Compiler::store_outputs(const std::vector<std::pair<Symbol*, const CallArg*>>& outs, const std::vector<Val>& out_vals) {
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
  (void)inst;
  if (is_tcunit_method(m) && !(m = tcunit_lowering(c, m))) return bad();
  return call_method(c.args, c.loc, m, this_ptr, virt, {});
}

Val Compiler::call_method(const std::vector<CallArg>& args, SourceLoc loc, PouInfo* m, Slot this_ptr, bool virt,
                          const std::vector<FixedArg>& fixed) {
  declare_pou(m);
  std::vector<Symbol*> params = m->inputs;
  params.insert(params.end(), m->inouts.begin(), m->inouts.end());
  std::vector<const CallArg*> bound(params.size(), nullptr);
  std::vector<std::pair<Symbol*, const CallArg*>> outs;
  std::vector<size_t> order;  // bound parameters in the order their arguments are written
  auto fixed_of = [&](const Symbol* p) -> const FixedArg* {
    for (const auto& f : fixed)
      if (f.param == p) return &f;
    return nullptr;
  };
  // Positional arguments go to the parameters the compiler does not supply itself, in
  // declaration order (outputs among them).
  std::vector<Symbol*> by_position;
  for (Symbol* p : positional_params(m))
    if (!fixed_of(p)) by_position.push_back(p);
  size_t pos = 0;
  bool named_before = false;
  for (const auto& a : args) {
    size_t idx = SIZE_MAX;
    if (a.name) {
      for (size_t i = 0; i < params.size(); ++i)
        if (iequals(params[i]->name, a.name->text)) idx = i;
      if (idx != SIZE_MAX && fixed_of(params[idx])) {
        diags_.error("ST212", a.loc, "'" + params[idx]->name + "' of " + m->name + " is set by the runtime, not by an argument");
        continue;
      }
      if (idx == SIZE_MAX) {
        for (Symbol* o : m->outputs)
          if (iequals(o->name, a.name->text)) outs.emplace_back(o, &a);
        if (outs.empty() || outs.back().second != &a)
          diags_.error("ST212", a.loc, "method " + m->name + " has no parameter '" + a.name->text + "'");
        else
          pos = next_position(by_position, outs.back().first, pos);
        named_before = true;
        continue;
      }
      pos = next_position(by_position, params[idx], pos);
      named_before = true;
    } else {
      if (named_before && !positional_after_named_ok(a.loc)) continue;
      if (pos >= by_position.size()) {
        diags_.error("ST210", a.loc, "too many arguments for method " + m->name);
        break;
      }
      Symbol* p = by_position[pos++];
      if (p->section == VarSection::Output) {
        outs.emplace_back(p, &a);
        continue;
      }
      idx = static_cast<size_t>(std::find(params.begin(), params.end(), p) - params.begin());
    }
    if (bound[idx]) {
      diags_.error("ST212", a.loc, "'" + params[idx]->name + "' of " + m->name + " is given twice");
      continue;
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
    std::vector<Slot> bounds;  // ARRAY[*] in-out: the argument's bounds
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
      if (!stage_inout(p, *a->value, &st.v.slot, &st.bounds)) continue;
      st.v.type = elem(TypeKind::UDInt);
    } else if (is_reference(p->type)) {  // a REFERENCE TO input is bound to the argument
      st.v = reference_to_var(p->type, *a->value);
      if (!st.v.ok) continue;
    } else {
      st.v = expr_for(*a->value, p->type);
      if (!st.v.ok) continue;
    }
    st.ok = true;
    bool from_variable = !st.v.is_const && (st.v.slot.kind == SK::Var || st.v.slot.kind == SK::Hidden);
    if (from_variable && call_after[k]) {
      const Type* t = p->where == Where::InOut ? elem(TypeKind::UDInt) : p->type;
      Slot copy = t->is_string() ? temp(t->size, t->align) : temp_for(t);
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
        diags_.error("ST224", loc, "VAR_IN_OUT '" + p->name + "' of method " + m->name + " must be passed");
        continue;
      }
      if (staged[i].ok) store_inout(field, staged[i].v.slot, staged[i].bounds);
      continue;
    }
    if (const FixedArg* f = fixed_of(p)) {
      assign(field, f->v, loc);
    } else if (bound[i] && bound[i]->value) {
      if (!staged[i].ok) continue;
      if (staged[i].direct) assign(field, staged[i].v, bound[i]->loc);
      else store(field, staged[i].v.slot);
    } else if (is_tcunit_method(m) && iequals(p->name, "_tcuAt")) {
      store(field, konst_i64(pack_location(loc)));  // where the assertion is, for its failure
    } else {
      store(field, konst_bytes(p->init.data(), static_cast<uint32_t>(p->init.size()), p->type->align));
    }
  }
  mark(loc);
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
  store_outputs(outs, out_vals);
  return r;
}

Val Compiler::property_get(const Place& inst, PouInfo* getter, Slot this_ptr, SourceLoc loc) {
  CallExpr c(loc);
  bool virt = !inst.ok || inst.type == nullptr || inst.type->kind != TypeKind::Pou ||
              (b_->this_type && inst.type == b_->this_type) || (inst.k == Place::K::Ind && has_derived(inst.type->pou));
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

// __QUERYINTERFACE(itfSource, itfDest) (CODESYS): itfDest := the instance behind
// itfSource when its FB implements itfDest's interface, else 0; TRUE when it does.
// __QUERYPOINTER(itfSource, pDest): pDest := the instance's address; TRUE when not 0.
// An interface value is the instance's address; the instance starts with its type's id.
Val Compiler::query_interface(const CallExpr& c, bool pointer) {
  const std::string name = pointer ? "__QUERYPOINTER" : "__QUERYINTERFACE";
  auto args = positional(c, 2, 2, name);
  if (args.size() != 2) return bad();
  if (opt_.dialect == Dialect::Iec) {
    diags_.error("ST241", c.loc, name + " is CODESYS, not IEC 61131-3: use --dialect codesys");
    return bad();
  }
  Val src = expr(*args[0], nullptr);
  if (!src.ok) return bad();
  if (!src.type || src.type->kind != TypeKind::Interface) {
    diags_.error("ST203", args[0]->loc, name + " needs an interface variable first, not " +
                                            (src.type ? src.type->name : std::string("a literal")));
    return bad();
  }
  Place dst = place(*args[1], true);
  if (!dst.ok) return bad();
  if (pointer ? dst.type->kind != TypeKind::Ref : dst.type->kind != TypeKind::Interface) {
    diags_.error("ST203", args[1]->loc, name + (pointer ? " writes the instance's address into a POINTER or REFERENCE, not "
                                                        : " writes into a variable of an interface, not ") + dst.type->name);
    return bad();
  }
  const Type* udint = elem(TypeKind::UDInt);
  const Type* boolean = elem(TypeKind::Bool);
  Slot addr = to_slot(src, src.type, args[0]->loc);
  Val addr_val;
  addr_val.type = udint;
  addr_val.slot = addr;
  auto konst_of = [&](const Type* t, ConstV::K k, int64_t i) {
    Val v;
    v.type = t;
    v.is_const = true;
    v.c.k = k;
    v.c.i = i;
    return v;
  };
  Slot result = temp(1, 1);
  Place result_place = frame_place(result, boolean);
  Val null_val = konst_of(udint, ConstV::K::Int, 0);
  Place dst_word = dst;
  dst_word.type = udint;
  if (pointer) {  // the address itself, whatever the instance
    store(dst_word, addr);
    assign(result_place, combine(BinaryOp::Ne, addr_val, null_val, c.loc), c.loc);
    return load(result_place);
  }
  assign(result_place, konst_of(boolean, ConstV::K::Bool, 0), c.loc);
  assign(dst_word, null_val, c.loc);
  Label done = new_label();
  branch_on(combine(BinaryOp::Ne, addr_val, null_val, c.loc), c.loc, done, false);
  Place header;
  header.k = Place::K::Ind;
  header.ptr = addr;
  header.type = elem(TypeKind::UInt);
  Val type_id = load(header);
  for (const auto& p : app_->pous) {
    if (!p->type_id || p->kind != PouKind::FunctionBlock || !implements(p.get(), dst.type->pou)) continue;
    Label next = new_label();
    branch_on(combine(BinaryOp::Eq, type_id, konst_of(elem(TypeKind::UInt), ConstV::K::Int, p->type_id), c.loc), c.loc,
              next, false);
    store(dst_word, addr);
    assign(result_place, konst_of(boolean, ConstV::K::Bool, 1), c.loc);
    emit(Op::JMP, {Arg::target(done.id)});
    bind(next);
  }
  bind(done);
  return load(result_place);
}

}  // namespace plcfi::st::detail

namespace plcfi::st::detail {

// IEC 61131-3 calls are formal or non-formal, never both; CODESYS takes a positional
// argument after named ones (see next_position).
bool Compiler::positional_after_named_ok(SourceLoc loc) {
  if (opt_.dialect == Dialect::Codesys) return true;
  diags_.error("ST241", loc, "a positional argument after named ones is CODESYS, not IEC 61131-3: name it, or use --dialect codesys");
  return false;
}

}  // namespace plcfi::st::detail
