// FB_init and FB_exit (CODESYS, TwinCAT). At every restart each FB instance's FB_init
// runs, with the arguments its declaration gives (`fb : FB_X(sName := 'a')`); before the
// memory of an application that ran is reset, each instance's FB_exit. FB_reinit belongs
// to online change, which plcfi does not do: it is never called.
//
// Every FUNCTION_BLOCK and PROGRAM that holds such instances (as variables, in arrays or
// structures, or through its base FB) gets two more entries after its body. Called on an
// instance, they run FB_init (FB_exit) of the instances it holds; the instance's own is
// run by whatever holds it, because only the holder's declaration has the arguments, and
// they are compiled in the holder's body, where that declaration is. One routine of the
// application does the same for the program instances and the global variables;
// Machine::cold_restart/warm_restart run it (vm/vm.hpp). A test case's frame has its own
// entries, which the test runner calls.
//
// Order, as CODESYS does it: an instance's members before the instance, a base FB's
// FB_init before the derived one's (the declaration's arguments go to the most derived
// FB_init; a base's gets its inputs' defaults); FB_exit in the opposite order.
#include <algorithm>

#include "codegen/compiler_impl.hpp"

namespace plcfi::st::detail {

namespace {

// The FB's own method `name` with a body (not an inherited one).
PouInfo* own_method(const PouInfo* fb, std::string_view name) {
  for (const auto& m : fb->methods)
    if (iequals(m->name, name) && m->has_body && m->property.empty()) return m.get();
  return nullptr;
}

// `name` along the EXTENDS chain, the base's first.
std::vector<PouInfo*> method_chain(const PouInfo* fb, std::string_view name) {
  std::vector<PouInfo*> out;
  for (const PouInfo* f = fb; f; f = f->base)
    if (PouInfo* m = own_method(f, name)) out.insert(out.begin(), m);
  return out;
}

// The part of `p` at a constant offset: an element or a member.
Place shifted(const Place& p, uint32_t delta, const Type* t) {
  Place q = p;
  q.off += delta;
  q.type = t;
  q.sym = nullptr;
  return q;
}

const char* method_name(bool exit) { return exit ? "FB_exit" : "FB_init"; }

}  // namespace

bool Compiler::lifecycle_needed(const Type* t, bool exit) {
  if (!t || opt_.dialect != Dialect::Codesys) return false;
  auto& memo = lifecycle_memo_[exit ? 1 : 0];
  if (auto it = memo.find(t); it != memo.end()) return it->second;
  memo[t] = false;  // a type that holds itself is an error reported elsewhere
  bool need = false;
  switch (t->kind) {
    case TypeKind::Pou:
      need = t->pou && (t->pou->kind == PouKind::FunctionBlock || t->pou->kind == PouKind::Program) &&
             (!method_chain(t->pou, method_name(exit)).empty() || members_need(t->pou, exit));
      break;
    case TypeKind::Array: need = lifecycle_needed(t->elem, exit); break;
    case TypeKind::Struct:
      for (const auto& f : t->fields) need = need || lifecycle_needed(f.type, exit);
      break;
    default: break;
  }
  memo[t] = need;
  return need;
}

bool Compiler::reads_variables(const Expr& e, const PouInfo* pou) {
  switch (e.kind) {
    case ExprKind::Name: {
      const std::string& n = static_cast<const NameExpr&>(e).name.text;
      if (const Symbol* s = pou ? pou->find_var(n) : nullptr) return !s->constant;
      auto g = globals_.find(canon(n));
      return g != globals_.end() && !g->second->constant;
    }
    case ExprKind::Call:
    case ExprKind::Deref: return true;  // ADR(x), a function's value, p^: known when run
    case ExprKind::Member: return reads_variables(*static_cast<const MemberExpr&>(e).base, pou);
    case ExprKind::Index: {
      const auto& ix = static_cast<const IndexExpr&>(e);
      for (const auto& i : ix.indices)
        if (i && reads_variables(*i, pou)) return true;
      return reads_variables(*ix.base, pou);
    }
    case ExprKind::Unary: return reads_variables(*static_cast<const UnaryExpr&>(e).operand, pou);
    case ExprKind::Binary: {
      const Expr* cur = &e;  // iterative over the left spine of long chains
      while (cur->kind == ExprKind::Binary) {
        const auto& b = static_cast<const BinaryExpr&>(*cur);
        if (reads_variables(*b.rhs, pou)) return true;
        cur = b.lhs.get();
      }
      return reads_variables(*cur, pou);
    }
    default: return false;
  }
}

bool Compiler::runtime_init(const Symbol* v, const VarDecl* d, uint32_t file, bool report, const PouInfo* pou) {
  // RETAIN variables keep their value over a warm restart: their initial value stays a constant.
  if (opt_.dialect != Dialect::Codesys || !d || !d->init || !v || !v->type || v->constant || v->retain) return false;
  const Expr& init = *d->init;
  if (init.kind == ExprKind::ArrayInit || init.kind == ExprKind::StructInit) return false;
  if (!v->type->is_elementary() && !v->type->is_string()) return false;
  if (v->section == VarSection::InOut || v->section == VarSection::External) return false;
  if (v->type->kind == TypeKind::Enum && init.kind == ExprKind::Name) return false;  // a value of the type
  if (const_eval(init, file, false)) return false;
  // Not a constant because it reads variables or calls (ADR): otherwise the expression is
  // wrong, and write_init reports why.
  if (!reads_variables(init, pou)) return false;
  if (report)
    diags_.warning("ST407", init.loc, "the initial value of '" + v->name +
                                         "' is not a constant expression: computed when the variable is initialised, "
                                         "in declaration order (CODESYS)");
  return true;
}

const std::vector<const Symbol*>& Compiler::runtime_inits(PouInfo* p) {
  auto found = runtime_inits_.find(p);
  if (found != runtime_inits_.end()) return found->second;
  auto& out = runtime_inits_[p];
  // A FUNCTION's inputs take their defaults where a call leaves them out: constants only.
  for (const auto& v : p->vars)
    if (v->where == Where::Frame && !(p->kind == PouKind::Function && v->section == VarSection::Input) &&
        runtime_init(v.get(), decl_of(v.get()), p->file, true, p))
      out.push_back(v.get());
  return out;
}

void Compiler::emit_runtime_inits(const std::vector<const Symbol*>& vars) {
  for (const Symbol* v : vars) {
    const VarDecl* d = decl_of(v);
    mark(d->init->loc);
    Place dst = symbol_place(v, d->init->loc);
    dst.readonly = false;  // initialising, not assigning
    Val val = expr_for(*d->init, v->type);
    if (!dst.ok || !val.ok) continue;
    assign(dst, val, d->init->loc);
  }
}

bool Compiler::members_need(PouInfo* p, bool exit) {
  if (opt_.dialect != Dialect::Codesys || is_late(p)) return false;
  if (p->base && members_need(p->base, exit)) return true;
  if (!exit && !runtime_inits(p).empty()) return true;
  for (const auto& v : p->vars)
    if (v->where == Where::Frame && v->section != VarSection::Temp && lifecycle_needed(v->type, exit)) return true;
  return false;
}

void Compiler::call_entry(const Place& at, PouInfo* pou, EntryKind which) {
  if (at.k == Place::K::Frame) emit(Op::CALL, {Slot{at.off, at.sk}, Arg::entry(pou, which)});
  else if (at.k == Place::K::Abs) emit(Op::CALLA, {at.off, Arg::entry(pou, which)});
}

void Compiler::instance_lifecycle(const Place& at, const Type* t, const VarDecl* d, bool exit, SourceLoc loc) {
  if (!lifecycle_needed(t, exit)) return;
  if (t->kind == TypeKind::Array || t->kind == TypeKind::Struct) {
    std::vector<std::pair<uint32_t, const Type*>> parts;
    if (t->kind == TypeKind::Array) {
      for (uint32_t off = 0; t->elem->size && off < t->size; off += t->elem->size) parts.emplace_back(off, t->elem);
    } else {
      for (const auto& f : t->fields) parts.emplace_back(f.offset, f.type);
    }
    if (exit) std::reverse(parts.begin(), parts.end());
    for (auto [off, pt] : parts) instance_lifecycle(shifted(at, off, pt), pt, nullptr, exit, loc);
    return;
  }
  PouInfo* fb = t->pou;
  const EntryKind which = exit ? EntryKind::Exit : EntryKind::Init;
  std::vector<PouInfo*> chain = method_chain(fb, method_name(exit));
  if (exit) std::reverse(chain.begin(), chain.end());
  if (!exit && members_need(fb, false)) call_entry(at, fb, which);
  if (!chain.empty()) {
    Slot self = addr_of(at, loc);
    Place flag;
    flag.k = Place::K::Abs;
    flag.off = init_flag_addr();
    flag.type = elem(TypeKind::Bool);
    Val no;
    no.type = elem(TypeKind::Bool);
    no.is_const = true;
    no.c.k = ConstV::K::Bool;
    const std::vector<CallArg>* given = d && d->type && d->type->has_init_args ? &d->type->init_args : nullptr;
    for (PouInfo* m : chain) {
      declare_pou(m);
      std::vector<FixedArg> fixed;
      for (Symbol* in : m->inputs) {
        if (iequals(in->name, "bInitRetains")) fixed.push_back({in, load(flag)});
        else if (iequals(in->name, "bInCopyCode")) fixed.push_back({in, no});
      }
      // The arguments are the most derived FB_init's; a base's gets its defaults.
      static const std::vector<CallArg> none;
      const bool derived = m == (exit ? chain.front() : chain.back());
      call_method(given && derived ? *given : none, d ? d->loc : loc, m, self, false, fixed);
    }
  }
  if (exit && members_need(fb, true)) call_entry(at, fb, which);
}

uint32_t Compiler::init_flag_addr() {
  if (!app_->init_flag_addr) app_->init_flag_addr = alloc(1, 1);
  return app_->init_flag_addr;
}

void Compiler::lifecycle_entries(PouInfo* p, std::vector<uint32_t>* entries, size_t* init_at, size_t* exit_at) {
  for (bool exit : {false, true}) {
    if (!members_need(p, exit)) continue;
    (exit ? *exit_at : *init_at) = entries->size();
    entries->push_back(static_cast<uint32_t>(b_->code.size()));
    std::vector<const Symbol*> held;
    for (const auto& v : p->vars)
      if (v->where == Where::Frame && v->section != VarSection::Temp && lifecycle_needed(v->type, exit)) held.push_back(v.get());
    if (exit) std::reverse(held.begin(), held.end());
    const bool base_too = p->base && members_need(p->base, exit);
    // The base's part of the instance is at offset 0: its entry runs on this instance.
    if (base_too && !exit) emit(Op::CALL, {Slot{0, SK::Var}, Arg::entry(p->base, EntryKind::Init)});
    if (!exit) emit_runtime_inits(runtime_inits(p));
    for (const Symbol* v : held) {
      mark(v->loc);
      instance_lifecycle(symbol_place(v, v->loc), v->type, decl_of(v), exit, v->loc);
    }
    if (base_too && exit) emit(Op::CALL, {Slot{0, SK::Var}, Arg::entry(p->base, EntryKind::Exit)});
    emit(Op::RET, {});
  }
}

void Compiler::compile_lifecycle() {
  if (opt_.dialect != Dialect::Codesys) return;
  struct Root {
    Place at;
    const Type* type;
    const VarDecl* decl;
    SourceLoc loc;
  };
  std::vector<Root> roots;
  auto abs = [](uint32_t addr, const Type* t) {
    Place at;
    at.k = Place::K::Abs;
    at.off = addr;
    at.type = t;
    return at;
  };
  for (const auto& pi : app_->programs)
    if (pi.pou->compiled) roots.push_back({abs(pi.addr, pi.pou->type), pi.pou->type, nullptr, pi.pou->loc});
  // A PROGRAM that only a test names (Main.x in a TEST) has an instance of its own.
  std::vector<std::pair<uint32_t, const PouInfo*>> named_only;
  for (const auto& [p, at] : program_addr_)
    if (std::none_of(app_->programs.begin(), app_->programs.end(), [&, addr = at.first](const ProgramInstance& pi) { return pi.addr == addr; }))
      named_only.emplace_back(at.first, p);
  std::sort(named_only.begin(), named_only.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [addr, p] : named_only) roots.push_back({abs(addr, p->type), p->type, nullptr, p->loc});
  for (const auto& g : app_->globals)
    if (g.sym->where == Where::Abs) roots.push_back({abs(g.sym->offset, g.sym->type), g.sym->type, decl_of(g.sym), g.sym->loc});
  for (const auto& p : app_->pous)  // VAR_STAT: one per POU, like a global
    for (const auto& v : p->vars)
      if (v->section == VarSection::Stat && v->where == Where::Abs) roots.push_back({abs(v->offset, v->type), v->type, nullptr, v->loc});
  const bool any_init = !global_runtime_inits_.empty() ||
                        std::any_of(roots.begin(), roots.end(), [&](const Root& r) { return lifecycle_needed(r.type, false); });
  const bool any_exit = std::any_of(roots.begin(), roots.end(), [&](const Root& r) { return lifecycle_needed(r.type, true); });
  if (!any_init && !any_exit) return;

  auto pi = std::make_unique<PouInfo>();
  PouInfo* p = pi.get();
  p->kind = PouKind::Program;
  p->name = "(FB_init and FB_exit of every instance)";
  p->type = tt_->make(TypeKind::Pou, p->name);
  p->type->pou = p;
  p->is_stdlib = true;  // not the user's: no listing of its own, no coverage
  src(p).declared = true;
  p->frame_size = 8;
  Body* saved_b = b_;
  auto body = std::make_unique<Body>();
  b_ = body.get();
  b_->pou = p;
  b_->vars_end = p->frame_size;
  std::vector<uint32_t> entries;
  for (bool exit : {false, true}) {
    entries.push_back(static_cast<uint32_t>(b_->code.size()));
    if (exit) std::reverse(roots.begin(), roots.end());
    for (const Symbol* g : exit ? std::vector<const Symbol*>{} : global_runtime_inits_) {
      file_ = g->loc.file;
      emit_runtime_inits({g});
    }
    for (const Root& r : roots) {
      if (!lifecycle_needed(r.type, exit)) continue;
      mark(r.loc);
      file_ = r.loc.file;
      instance_lifecycle(r.at, r.type, r.decl, exit, r.loc);
    }
    emit(Op::RET, {});
  }
  finish_body(*body, p, &entries);
  p->entry = entries[0];
  p->compiled = true;
  bodies_.push_back(std::move(body));
  b_ = saved_b;
  app_->lifecycle_addr = alloc(p->frame_size, 8);
  std::copy(p->type->init.begin(), p->type->init.end(), app_->init_image.begin() + app_->lifecycle_addr);
  app_->has_init = any_init;
  app_->has_exit = any_exit;
  app_->init_entry = entries[0];
  app_->exit_entry = entries[1];
  if (any_init) init_flag_addr();
  app_->pous.push_back(std::move(pi));
}

}  // namespace plcfi::st::detail
