// The reference evaluator: IEC 61131-3 semantics written plainly over the parsed AST, with
// plcfi's documented choices where the standard leaves them open (wraparound, REAL_TO_INT
// halves to even and saturating, string functions clamping their lengths).
#include "reference.hpp"

#include <cmath>
#include <limits>

namespace plcfi::oracle {

using st::canon;

namespace {

// Loops of a generated program are bounded; this guards the evaluator against its own bugs.
constexpr uint64_t kMaxSteps = 50'000'000;

int64_t norm(const RType* t, uint64_t bits) {
  if (t->bits == 64) return static_cast<int64_t>(bits);
  uint64_t mask = (uint64_t{1} << t->bits) - 1;
  bits &= mask;
  if (t->is_signed && (bits >> (t->bits - 1)) != 0) bits |= ~mask;
  return static_cast<int64_t>(bits);
}

// Float to integer as the engine converts: NaN -> 0, saturating at the type's limits,
// truncating otherwise (the caller has rounded first).
template <class F>
int64_t saturate(F x, const RType* to) {
  if (std::isnan(x)) return 0;
  if (to->is_signed) {
    int64_t mn = to->bits == 64 ? std::numeric_limits<int64_t>::min() : -(int64_t{1} << (to->bits - 1));
    int64_t mx = to->bits == 64 ? std::numeric_limits<int64_t>::max() : (int64_t{1} << (to->bits - 1)) - 1;
    if (x <= static_cast<F>(mn)) return mn;
    if (x >= static_cast<F>(mx)) return mx;
    return static_cast<int64_t>(x);
  }
  uint64_t mx = to->bits == 64 ? std::numeric_limits<uint64_t>::max() : (uint64_t{1} << to->bits) - 1;
  if (x <= F(0)) return 0;
  if (x >= static_cast<F>(mx)) return static_cast<int64_t>(mx);
  return static_cast<int64_t>(static_cast<uint64_t>(x));
}

}  // namespace

Value& Vars::add(const std::string& name, Value v) {
  std::string c = canon(name);
  if (by_name.count(c) == 0) order.push_back(name);
  return by_name[c] = std::move(v);
}

Value* Vars::find(const std::string& canon_name) {
  if (auto a = aliases.find(canon_name); a != aliases.end()) return a->second;
  auto it = by_name.find(canon_name);
  return it == by_name.end() ? nullptr : &it->second;
}

// A name resolves in the call frame, then the instance (FB body, method), then globals.
struct Reference::Env {
  Vars* locals = nullptr;
  Instance* self = nullptr;
  const st::Pou* owner = nullptr;  // the FB declaring the running body or method (for SUPER)
};

Reference::Reference(const std::vector<const st::CompilationUnit*>& units) {
  struct Elem {
    const char* name;
    VK kind;
    int bits;
    bool is_signed;
  };
  static const Elem kElems[] = {
      {"BOOL", VK::Bool, 8, false},   {"SINT", VK::Int, 8, true},     {"INT", VK::Int, 16, true},
      {"DINT", VK::Int, 32, true},    {"LINT", VK::Int, 64, true},    {"USINT", VK::Int, 8, false},
      {"UINT", VK::Int, 16, false},   {"UDINT", VK::Int, 32, false},  {"ULINT", VK::Int, 64, false},
      {"BYTE", VK::Int, 8, false},    {"WORD", VK::Int, 16, false},   {"DWORD", VK::Int, 32, false},
      {"LWORD", VK::Int, 64, false},  {"REAL", VK::Real, 32, false},  {"LREAL", VK::LReal, 64, false},
      {"TIME", VK::Time, 64, true},   {"DATE", VK::Date, 64, true},   {"TOD", VK::Date, 64, true},
      {"DT", VK::Date, 64, true},
  };
  for (const auto& e : kElems) {
    auto t = std::make_unique<RType>();
    t->kind = e.kind;
    t->name = e.name;
    t->bits = e.bits;
    t->is_signed = e.is_signed;
    named_[e.name] = t.get();
    owned_.push_back(std::move(t));
  }
  auto s = std::make_unique<RType>();
  s->kind = VK::String;
  s->name = "STRING[255]";
  s->max_len = 255;
  string255_ = s.get();
  owned_.push_back(std::move(s));

  for (const auto* u : units) {
    if (!u->configs.empty()) throw Unsupported("CONFIGURATION");
    for (const auto& p : u->pous) pous_[canon(p->name.text)] = p.get();
    for (const auto& t : u->types) type_decls_[canon(t.name.text)] = &t;
  }
  Env none;
  for (const auto* u : units) declare(globals_, u->globals, &none);
  for (const auto* u : units)
    for (const auto& p : u->pous)
      if (p->kind == st::PouKind::Program) programs_.emplace_back(p->name.text, instantiate(p.get()));
}

Reference::~Reference() = default;

// Nanoseconds per count when a date converts to a number: DATE and DT count seconds since
// 1970-01-01 in both dialects, TIME_OF_DAY milliseconds (CODESYS) or seconds (MATIEC).
int64_t Reference::count_unit(const RType* t) const {
  if (t->name == "TOD") return codesys_ ? 1'000'000 : 1'000'000'000;
  return 1'000'000'000;
}

const RType* Reference::elementary(const std::string& c) const {
  auto it = named_.find(c);
  return it == named_.end() ? nullptr : it->second;
}

const RType* Reference::type_of(const st::TypeSpec& spec) {
  auto int_const = [&](const st::ExprPtr& e) {
    Env none;
    Value v = eval(*e, none);
    if (v.t->kind != VK::Int) throw Unsupported("non-integer constant");
    return v.i;
  };
  switch (spec.kind) {
    case st::TypeSpecKind::Named: {
      std::string c = canon(spec.name.text);
      if (c == "STRING") {
        if (!spec.string_length) return string255_;  // not emitted by the generator
        int64_t n = int_const(spec.string_length);
        std::string key = "STRING[" + std::to_string(n) + "]";
        if (auto* t = elementary(key)) return t;
        auto t = std::make_unique<RType>();
        t->kind = VK::String;
        t->name = key;
        t->max_len = static_cast<size_t>(n);
        named_[key] = t.get();
        owned_.push_back(std::move(t));
        return named_[key];
      }
      if (auto* t = elementary(c)) return t;
      if (auto d = type_decls_.find(c); d != type_decls_.end()) {
        const RType* t = type_of(*d->second->spec);
        named_[c] = t;
        return t;
      }
      if (auto p = pous_.find(c); p != pous_.end()) {
        auto t = std::make_unique<RType>();
        t->name = p->second->name.text;
        t->pou = p->second;
        if (p->second->kind == st::PouKind::FunctionBlock) t->kind = VK::Fb;
        else if (p->second->kind == st::PouKind::Interface) t->kind = VK::Itf;
        else throw Unsupported("POU used as a type: " + t->name);
        named_[c] = t.get();
        owned_.push_back(std::move(t));
        return named_[c];
      }
      throw Unsupported("type " + spec.name.text);
    }
    case st::TypeSpecKind::Array: {
      if (spec.dims.size() != 1) throw Unsupported("multi-dimensional array");
      auto t = std::make_unique<RType>();
      t->kind = VK::Array;
      t->lo = int_const(spec.dims[0].lo);
      t->hi = int_const(spec.dims[0].hi);
      t->elem = type_of(*spec.element);
      t->name = "ARRAY";
      owned_.push_back(std::move(t));
      return owned_.back().get();
    }
    case st::TypeSpecKind::Struct: {
      auto t = std::make_unique<RType>();
      t->kind = VK::Struct;
      t->name = "STRUCT";
      for (const auto& d : spec.members) {
        if (d.init) throw Unsupported("structure member initializer");
        for (const auto& n : d.names) t->fields.emplace_back(n.text, type_of(*d.type));
      }
      owned_.push_back(std::move(t));
      return owned_.back().get();
    }
    case st::TypeSpecKind::Ref:
      return ref_to(type_of(*spec.element));
    default:
      throw Unsupported("type specification kind");
  }
}

const RType* Reference::ref_to(const RType* target) {
  auto& t = ref_types_[target];
  if (!t) {
    auto r = std::make_unique<RType>();
    r->kind = VK::Ref;
    r->name = "REF_TO " + target->name;
    r->elem = target;
    t = r.get();
    owned_.push_back(std::move(r));
  }
  return t;
}

Value Reference::make(const RType* t) {
  Value v;
  v.t = t;
  switch (t->kind) {
    case VK::Array:
      for (int64_t i = t->lo; i <= t->hi; ++i) v.elems.push_back(make(t->elem));
      break;
    case VK::Struct:
      for (const auto& f : t->fields) v.elems.push_back(make(f.second));
      break;
    case VK::Fb:
      v.fb = instantiate(t->pou);
      break;
    default:
      break;
  }
  return v;
}

void Reference::declare(Vars& vars, const std::vector<st::VarBlock>& blocks, Env* env) {
  for (const auto& b : blocks) {
    for (const auto& d : b.decls) {
      if (d.location) throw Unsupported("located variable");
      const RType* t = type_of(*d.type);
      for (const auto& n : d.names) {
        Value v = make(t);
        if (d.init) {
          if (d.init->kind == st::ExprKind::ArrayInit || d.init->kind == st::ExprKind::StructInit)
            throw Unsupported("aggregate initializer");
          assign(v, eval(*d.init, *env));
        }
        vars.add(n.text, std::move(v));
      }
    }
  }
}

const st::Pou* Reference::base_of(const st::Pou* fb) const {
  if (!fb->extends) return nullptr;
  auto it = pous_.find(canon(fb->extends->text));
  if (it == pous_.end() || it->second->kind != st::PouKind::FunctionBlock) throw Unsupported("EXTENDS of a non-FB");
  return it->second;
}

std::shared_ptr<Instance> Reference::instantiate(const st::Pou* pou) {
  auto inst = std::make_shared<Instance>();
  inst->pou = pou;
  // Inherited variables first, from the root of the chain down.
  std::vector<const st::Pou*> chain;
  for (const st::Pou* p = pou; p; p = base_of(p)) chain.insert(chain.begin(), p);
  Env env;
  for (const st::Pou* p : chain) declare(inst->vars, p->var_blocks, &env);
  return inst;
}

void Reference::scan() {
  for (auto& [name, inst] : programs_) {
    Env env;
    Vars temps;
    env.locals = &temps;
    env.self = inst.get();
    env.owner = inst->pou;
    exec(inst->pou->body, env);
  }
}

// ---------------------------------------------------------------- statements

Reference::Flow Reference::exec(const st::StmtList& list, Env& env) {
  for (const auto& s : list) {
    Flow f = exec(*s, env);
    if (f != Flow::Normal) return f;
  }
  return Flow::Normal;
}

Reference::Flow Reference::exec(const st::Stmt& s, Env& env) {
  if (++steps_ > kMaxSteps) throw RefTrap("step limit exceeded");
  switch (s.kind) {
    case st::StmtKind::Assign: {
      const auto& a = static_cast<const st::AssignStmt&>(s);
      if (a.is_ref_assign) throw Unsupported("REF=");
      // A property on the left is a setter call.
      if (a.lhs->kind == st::ExprKind::Member) {
        const auto& m = static_cast<const st::MemberExpr&>(*a.lhs);
        if (Instance* inst = as_instance(*m.base, env)) {
          const st::Pou* owner = nullptr;
          if (const auto* p = find_property(inst->pou, canon(m.member.text), &owner)) {
            if (!p->setter) throw Unsupported("property without setter");
            Value v = eval(*a.rhs, env);
            run_pou(*p->setter, inst, owner, nullptr, env, p->name.text, p->type.get(), &v);
            return Flow::Normal;
          }
        }
      }
      Value v = eval(*a.rhs, env);
      store(*a.lhs, v, env);
      return Flow::Normal;
    }
    case st::StmtKind::Call:
      call(*static_cast<const st::CallStmt&>(s).call, env);
      return Flow::Normal;
    case st::StmtKind::If: {
      const auto& i = static_cast<const st::IfStmt&>(s);
      for (const auto& arm : i.arms)
        if (eval(*arm.cond, env).i != 0) return exec(arm.body, env);
      if (i.else_body) return exec(*i.else_body, env);
      return Flow::Normal;
    }
    case st::StmtKind::Case: {
      const auto& c = static_cast<const st::CaseStmt&>(s);
      Value sel = eval(*c.selector, env);
      if (sel.t->kind != VK::Int) throw Unsupported("CASE on a non-integer");
      for (const auto& arm : c.arms) {
        for (const auto& l : arm.labels) {
          Value lo = convert(eval(*l.lo, env), sel.t);
          bool hit = lo.i == sel.i;
          if (l.hi) {
            Value hi = convert(eval(*l.hi, env), sel.t);
            hit = sel.t->is_signed ? (lo.i <= sel.i && sel.i <= hi.i)
                                   : (static_cast<uint64_t>(lo.i) <= static_cast<uint64_t>(sel.i) &&
                                      static_cast<uint64_t>(sel.i) <= static_cast<uint64_t>(hi.i));
          }
          if (hit) return exec(arm.body, env);
        }
      }
      if (c.else_body) return exec(*c.else_body, env);
      return Flow::Normal;
    }
    case st::StmtKind::For: {
      const auto& f = static_cast<const st::ForStmt&>(s);
      if (f.var->kind != st::ExprKind::Name) throw Unsupported("FOR variable");
      for_vars_[canon(static_cast<const st::NameExpr&>(*f.var).name.text)] = true;
      Value* var = lvalue(*f.var, env);
      if (var->t->kind != VK::Int || !var->t->is_signed) throw Unsupported("FOR over an unsigned variable");
      Value from = eval(*f.from, env), to = eval(*f.to, env);
      int64_t by = f.by ? eval(*f.by, env).i : 1;
      if (by == 0) throw Unsupported("FOR step 0");
      assign(*var, from);
      // The generator keeps bounds far from the type's limits, so i + by cannot wrap.
      while (by > 0 ? var->i <= to.i : var->i >= to.i) {
        Flow fl = exec(f.body, env);
        if (fl == Flow::Exit) break;
        if (fl == Flow::Return) return fl;
        var->i = norm(var->t, static_cast<uint64_t>(var->i) + static_cast<uint64_t>(by));
        if (++steps_ > kMaxSteps) throw RefTrap("step limit exceeded");
      }
      return Flow::Normal;
    }
    case st::StmtKind::While: {
      const auto& w = static_cast<const st::WhileStmt&>(s);
      while (eval(*w.cond, env).i != 0) {
        Flow fl = exec(w.body, env);
        if (fl == Flow::Exit) break;
        if (fl == Flow::Return) return fl;
        if (++steps_ > kMaxSteps) throw RefTrap("step limit exceeded");
      }
      return Flow::Normal;
    }
    case st::StmtKind::Repeat: {
      const auto& r = static_cast<const st::RepeatStmt&>(s);
      for (;;) {
        Flow fl = exec(r.body, env);
        if (fl == Flow::Exit) break;
        if (fl == Flow::Return) return fl;
        if (eval(*r.until, env).i != 0) break;
        if (++steps_ > kMaxSteps) throw RefTrap("step limit exceeded");
      }
      return Flow::Normal;
    }
    case st::StmtKind::Exit:
      return Flow::Exit;
    case st::StmtKind::Continue:
      return Flow::Continue;
    case st::StmtKind::Return:
      return Flow::Return;
    case st::StmtKind::Empty:
      return Flow::Normal;
    default:
      throw Unsupported("statement kind");
  }
}

// ---------------------------------------------------------------- places

Instance* Reference::as_instance(const st::Expr& e, Env& env) {
  if (e.kind == st::ExprKind::This || e.kind == st::ExprKind::Super) return env.self;
  if (e.kind == st::ExprKind::Deref && (static_cast<const st::DerefExpr&>(e).base->kind == st::ExprKind::This ||
                                        static_cast<const st::DerefExpr&>(e).base->kind == st::ExprKind::Super))
    return env.self;
  if (e.kind != st::ExprKind::Name && e.kind != st::ExprKind::Member && e.kind != st::ExprKind::Index) return nullptr;
  if (e.kind == st::ExprKind::Name) {
    // A FUNCTION name is not a place.
    std::string c = canon(static_cast<const st::NameExpr&>(e).name.text);
    if ((!env.locals || !env.locals->find(c)) && (!env.self || !env.self->vars.find(c)) && !globals_.find(c))
      return nullptr;
  }
  if (e.kind == st::ExprKind::Member) {
    const auto& m = static_cast<const st::MemberExpr&>(e);
    Instance* base = as_instance(*m.base, env);
    if (base && find_property(base->pou, canon(m.member.text), nullptr)) return nullptr;
  }
  Value* v = lvalue(e, env);
  if (v->t->kind == VK::Fb) return v->fb.get();
  if (v->t->kind == VK::Itf) {
    if (!v->ref) throw RefTrap("call through an unassigned interface");
    return v->ref;
  }
  return nullptr;
}

Value* Reference::lvalue(const st::Expr& e, Env& env) {
  switch (e.kind) {
    case st::ExprKind::Name: {
      std::string c = canon(static_cast<const st::NameExpr&>(e).name.text);
      if (env.locals)
        if (Value* v = env.locals->find(c)) return v;
      if (env.self)
        if (Value* v = env.self->vars.find(c)) return v;
      if (Value* v = globals_.find(c)) return v;
      throw Unsupported("unknown name " + c);
    }
    case st::ExprKind::Member: {
      const auto& m = static_cast<const st::MemberExpr&>(e);
      std::string c = canon(m.member.text);
      if (Instance* inst = as_instance(*m.base, env)) {
        if (Value* v = inst->vars.find(c)) return v;
        throw Unsupported("unknown member " + c);
      }
      Value* base = lvalue(*m.base, env);
      if (base->t->kind != VK::Struct) throw Unsupported("member of a non-structure");
      for (size_t i = 0; i < base->t->fields.size(); ++i)
        if (canon(base->t->fields[i].first) == c) return &base->elems[i];
      throw Unsupported("unknown field " + c);
    }
    case st::ExprKind::Index: {
      const auto& x = static_cast<const st::IndexExpr&>(e);
      if (x.indices.size() != 1) throw Unsupported("several indices");
      Value* base = lvalue(*x.base, env);
      if (base->t->kind != VK::Array) throw Unsupported("index of a non-array");
      Value i = eval(*x.indices[0], env);
      if (i.t->kind != VK::Int) throw Unsupported("non-integer index");
      if (i.i < base->t->lo || i.i > base->t->hi)
        throw RefTrap("index " + std::to_string(i.i) + " outside " + std::to_string(base->t->lo) + ".." +
                      std::to_string(base->t->hi));
      return &base->elems[static_cast<size_t>(i.i - base->t->lo)];
    }
    case st::ExprKind::Deref: {
      Value* r = lvalue(*static_cast<const st::DerefExpr&>(e).base, env);
      if (r->t->kind != VK::Ref) throw Unsupported("^ of a non-reference");
      if (!r->ptr) throw RefTrap("dereference of a null reference");
      return r->ptr;
    }
    default:
      throw Unsupported("not a place");
  }
}

void Reference::store(const st::Expr& place, const Value& v, Env& env) {
  if (place.kind == st::ExprKind::BitAccess) {  // w.3 := b sets one bit of w
    const auto& b = static_cast<const st::BitAccessExpr&>(place);
    Value* w = lvalue(*b.base, env);
    if (w->t->kind != VK::Int || v.t->kind != VK::Bool || static_cast<int>(b.bit) >= w->t->bits)
      throw Unsupported("bit assignment");
    uint64_t mask = uint64_t{1} << b.bit;
    uint64_t bits = static_cast<uint64_t>(w->i);
    w->i = norm(w->t, v.i ? (bits | mask) : (bits & ~mask));
    return;
  }
  assign(*lvalue(place, env), v);
}

void Reference::assign(Value& dst, const Value& src) {
  switch (dst.t->kind) {
    case VK::Bool:
      if (src.t->kind != VK::Bool) throw Unsupported("assignment to BOOL from " + src.t->name);
      dst.i = src.i;
      return;
    case VK::Int:
      if (src.t->kind != VK::Int) throw Unsupported("assignment to " + dst.t->name + " from " + src.t->name);
      // Only widening reaches here in a well-typed program: the value is kept.
      dst.i = norm(dst.t, static_cast<uint64_t>(src.i));
      return;
    case VK::Real:
    case VK::LReal:
      if (src.t->kind == VK::Real || src.t->kind == VK::LReal) {
        dst.r = dst.t->kind == VK::Real ? static_cast<double>(static_cast<float>(src.r)) : src.r;
        return;
      }
      throw Unsupported("assignment to " + dst.t->name + " from " + src.t->name);
    case VK::Time:
      if (src.t->kind != VK::Time) throw Unsupported("assignment to TIME from " + src.t->name);
      dst.i = src.i;
      return;
    case VK::Date:
      if (src.t != dst.t) throw Unsupported("assignment to " + dst.t->name + " from " + src.t->name);
      dst.i = src.i;
      return;
    case VK::String:
      if (src.t->kind != VK::String) throw Unsupported("assignment to STRING from " + src.t->name);
      dst.s = src.s.substr(0, dst.t->max_len);
      return;
    case VK::Struct:
    case VK::Array:
      if (src.t != dst.t) throw Unsupported("aggregate assignment of another type");
      for (size_t i = 0; i < dst.elems.size(); ++i) assign(dst.elems[i], src.elems[i]);
      return;
    case VK::Itf:
      if (src.t->kind == VK::Fb) dst.ref = src.fb.get();
      else if (src.t->kind == VK::Itf) dst.ref = src.ref;
      else throw Unsupported("interface assignment");
      return;
    case VK::Ref:
      if (src.t->kind != VK::Ref || src.t->elem != dst.t->elem) throw Unsupported("reference assignment");
      dst.ptr = src.ptr;
      return;
    case VK::Fb:
      throw Unsupported("FB instance assignment");
  }
}

// ---------------------------------------------------------------- expressions

Value Reference::eval(const st::Expr& e, Env& env) {
  switch (e.kind) {
    case st::ExprKind::Literal: {
      const auto& l = static_cast<const st::LiteralExpr&>(e);
      Value v;
      std::string prefix = canon(l.type_prefix);
      switch (l.lit) {
        case st::LiteralKind::Int:
          v.t = elementary(prefix.empty() ? "DINT" : prefix);
          if (!v.t) throw Unsupported("literal prefix " + prefix);
          if (v.t->kind == VK::Real || v.t->kind == VK::LReal) {
            v.r = v.t->kind == VK::Real ? static_cast<float>(static_cast<double>(l.int_value))
                                        : static_cast<double>(l.int_value);
          } else {
            v.i = norm(v.t, l.int_value);
          }
          return v;
        case st::LiteralKind::Real:
          v.t = elementary(prefix.empty() ? "LREAL" : prefix);
          if (!v.t || (v.t->kind != VK::Real && v.t->kind != VK::LReal)) throw Unsupported("real literal prefix");
          v.r = v.t->kind == VK::Real ? static_cast<double>(static_cast<float>(l.real_value)) : l.real_value;
          return v;
        case st::LiteralKind::Bool:
          v.t = elementary("BOOL");
          v.i = l.int_value != 0;
          return v;
        case st::LiteralKind::Time:
          if (l.is_long) throw Unsupported("LTIME");
          v.t = elementary("TIME");
          v.i = l.time_ns;
          return v;
        case st::LiteralKind::Date:
        case st::LiteralKind::TimeOfDay:
        case st::LiteralKind::DateTime:
          if (l.is_long) throw Unsupported("long date literal");
          v.t = elementary(l.lit == st::LiteralKind::Date ? "DATE" : l.lit == st::LiteralKind::TimeOfDay ? "TOD" : "DT");
          v.i = l.time_ns;
          return v;
        case st::LiteralKind::String:
          v.t = string255_;
          v.s = l.str_value;
          return v;
        default:
          throw Unsupported("literal kind");
      }
    }
    case st::ExprKind::Name: {
      const auto& n = static_cast<const st::NameExpr&>(e);
      std::string c = canon(n.name.text);
      if (c == "TRUE" || c == "FALSE") {
        Value v;
        v.t = elementary("BOOL");
        v.i = c == "TRUE";
        return v;
      }
      return *lvalue(e, env);
    }
    case st::ExprKind::Member: {
      const auto& m = static_cast<const st::MemberExpr&>(e);
      if (Instance* inst = as_instance(*m.base, env)) {
        const st::Pou* owner = nullptr;
        if (const auto* p = find_property(inst->pou, canon(m.member.text), &owner)) {
          if (!p->getter) throw Unsupported("property without getter");
          return run_pou(*p->getter, inst, owner, nullptr, env, p->name.text, p->type.get(), nullptr);
        }
      }
      return *lvalue(e, env);
    }
    case st::ExprKind::Index:
    case st::ExprKind::Deref:
      return *lvalue(e, env);
    case st::ExprKind::BitAccess: {
      const auto& b = static_cast<const st::BitAccessExpr&>(e);
      Value w = eval(*b.base, env);
      if (w.t->kind != VK::Int || static_cast<int>(b.bit) >= w.t->bits) throw Unsupported("bit access");
      Value v;
      v.t = elementary("BOOL");
      v.i = (static_cast<uint64_t>(w.i) >> b.bit) & 1;
      return v;
    }
    case st::ExprKind::Call:
      return call(static_cast<const st::CallExpr&>(e), env);
    case st::ExprKind::Unary: {
      const auto& u = static_cast<const st::UnaryExpr&>(e);
      return unary(u.op, eval(*u.operand, env));
    }
    case st::ExprKind::Binary: {
      const auto& b = static_cast<const st::BinaryExpr&>(e);
      Value l = eval(*b.lhs, env);
      // AND/OR on BOOL: both sides are evaluated (ST has no short circuit); the generator's
      // expressions have no side effects either way.
      Value r = eval(*b.rhs, env);
      return binary(b.op, l, r);
    }
    default:
      throw Unsupported("expression kind");
  }
}

Value Reference::unary(st::UnaryOp op, const Value& a) {
  Value v;
  v.t = a.t;
  v.nominal = a.nominal;
  switch (op) {
    case st::UnaryOp::Plus:
      return a;
    case st::UnaryOp::Neg:
      if (a.t->kind == VK::Int || a.t->kind == VK::Time) v.i = norm(a.t->kind == VK::Time ? elementary("LINT") : a.t,
                                                                  uint64_t{0} - static_cast<uint64_t>(a.i));
      else if (a.t->kind == VK::Real) v.r = static_cast<double>(-static_cast<float>(a.r));
      else if (a.t->kind == VK::LReal) v.r = -a.r;
      else throw Unsupported("negation of " + a.t->name);
      return v;
    case st::UnaryOp::Not:
      if (a.t->kind == VK::Bool) v.i = a.i == 0;
      else if (a.t->kind == VK::Int) v.i = norm(a.t, ~static_cast<uint64_t>(a.i));
      else throw Unsupported("NOT of " + a.t->name);
      return v;
  }
  throw Unsupported("unary operator");
}

Value Reference::binary(st::BinaryOp op, const Value& a, const Value& b) {
  using B = st::BinaryOp;
  Value v;
  const RType* boolean = elementary("BOOL");
  auto cmp = [&](int c) {
    v.t = boolean;
    switch (op) {
      case B::Lt: v.i = c < 0; break;
      case B::Gt: v.i = c > 0; break;
      case B::Le: v.i = c <= 0; break;
      case B::Ge: v.i = c >= 0; break;
      case B::Eq: v.i = c == 0; break;
      case B::Ne: v.i = c != 0; break;
      default: throw Unsupported("comparison");
    }
    return v;
  };
  bool is_cmp = op == B::Lt || op == B::Gt || op == B::Le || op == B::Ge || op == B::Eq || op == B::Ne;
  // TIME * integer and TIME / integer.
  if (a.t->kind == VK::Time && b.t->kind == VK::Int && (op == B::Mul || op == B::Div)) {
    v.t = a.t;
    int64_t n = b.i;
    if (op == B::Mul) {
      v.i = static_cast<int64_t>(static_cast<uint64_t>(a.i) * static_cast<uint64_t>(n));
    } else {
      if (n == 0) throw RefTrap("division by zero");
      v.i = n == -1 ? static_cast<int64_t>(uint64_t{0} - static_cast<uint64_t>(a.i)) : a.i / n;
    }
    return v;
  }
  // Dates: DT/TOD +- TIME is a date of the same type, the difference of two dates a TIME.
  if (a.t->kind == VK::Date && b.t->kind == VK::Time && (op == B::Add || op == B::Sub) && a.t->name != "DATE") {
    v.t = a.t;
    v.i = static_cast<int64_t>(op == B::Add ? static_cast<uint64_t>(a.i) + static_cast<uint64_t>(b.i)
                                            : static_cast<uint64_t>(a.i) - static_cast<uint64_t>(b.i));
    return v;
  }
  if (a.t->kind == VK::Date && a.t == b.t && op == B::Sub) {
    v.t = elementary("TIME");
    v.i = static_cast<int64_t>(static_cast<uint64_t>(a.i) - static_cast<uint64_t>(b.i));
    return v;
  }
  if (a.t->kind == VK::Date && a.t == b.t && is_cmp) return cmp(a.i < b.i ? -1 : a.i > b.i ? 1 : 0);
  // CODESYS computes integers narrower than 32 bits in a 32-bit register (DINT, or UDINT
  // when unsigned) and cuts them only when they are stored or converted.
  // AND, OR and XOR cannot overflow: only an operand already in a register widens them.
  const bool logic = op == B::And || op == B::Or || op == B::Xor;
  if (codesys_ && a.t->kind == VK::Int && b.t->kind == VK::Int && (a.nominal || b.nominal || (!logic && !is_cmp))) {
    const RType* an = a.nominal ? a.nominal : a.t;
    const RType* bn = b.nominal ? b.nominal : b.t;
    auto widens_to = [](const RType* from, const RType* to) {
      return from == to || (from->bits < to->bits && (from->is_signed == to->is_signed || (!from->is_signed && to->is_signed)));
    };
    const RType* iec = widens_to(an, bn) ? bn : widens_to(bn, an) ? an : nullptr;
    if (iec && iec->bits >= 32 && (a.nominal || b.nominal)) {  // a register met a 32/64-bit operand: its bits are read in that type
      Value x = a, y = b;
      x.i = norm(iec, static_cast<uint64_t>(x.i));
      y.i = norm(iec, static_cast<uint64_t>(y.i));
      x.t = y.t = iec;
      x.nominal = y.nominal = nullptr;
      return binary(op, x, y);
    }
    if (iec && iec->bits < 32 && is_cmp) {  // compared in the register
      const RType* wide = a.nominal ? a.t : b.t;
      Value x = a, y = b;
      x.t = y.t = wide;
      x.nominal = y.nominal = nullptr;
      return binary(op, x, y);
    }
    if (iec && iec->bits < 32 && !is_cmp) {
      const RType* wide = elementary(iec->is_signed ? "DINT" : "UDINT");
      Value x = a, y = b;
      x.t = y.t = wide;
      x.nominal = y.nominal = nullptr;
      Value out = binary(op, x, y);
      out.nominal = iec;
      return out;
    }
  }
  // Implicit widening of integers (SINT -> INT -> DINT -> LINT, USINT -> ... -> ULINT, an
  // unsigned type to a wider signed one): the narrower operand takes the wider type.
  if (a.t->kind == VK::Int && b.t->kind == VK::Int && a.t != b.t) {
    auto widens = [](const RType* from, const RType* to) {
      return from->bits < to->bits && (from->is_signed == to->is_signed || (!from->is_signed && to->is_signed));
    };
    if (widens(a.t, b.t)) return binary(op, convert(a, b.t), b);
    if (widens(b.t, a.t)) return binary(op, a, convert(b, a.t));
  }
  if (a.t->kind != b.t->kind || (a.t->kind == VK::Int && a.t != b.t))
    throw Unsupported("operands of different types: " + a.t->name + ", " + b.t->name);
  switch (a.t->kind) {
    case VK::Bool: {
      if (is_cmp) return cmp(static_cast<int>(a.i) - static_cast<int>(b.i));
      v.t = boolean;
      if (op == B::And) v.i = a.i && b.i;
      else if (op == B::Or) v.i = a.i || b.i;
      else if (op == B::Xor) v.i = (a.i != 0) != (b.i != 0);
      else throw Unsupported("BOOL operator");
      return v;
    }
    case VK::Int:
    case VK::Time: {
      const RType* t = a.t->kind == VK::Time ? elementary("LINT") : a.t;
      bool sign = t->is_signed;
      uint64_t ua = static_cast<uint64_t>(a.i), ub = static_cast<uint64_t>(b.i);
      if (is_cmp) {
        if (sign) return cmp(a.i < b.i ? -1 : a.i > b.i ? 1 : 0);
        return cmp(ua < ub ? -1 : ua > ub ? 1 : 0);
      }
      v.t = a.t;
      switch (op) {
        case B::Add: v.i = norm(t, ua + ub + (wrong_addition_ ? 1 : 0)); return v;
        case B::Sub: v.i = norm(t, ua - ub); return v;
        case B::Mul: v.i = norm(t, ua * ub); return v;
        case B::Div:
        case B::Mod:
          if (b.i == 0 && op == B::Mod) {  // IEC 61131-3: IN1 MOD 0 = 0
            v.i = 0;
            return v;
          }
          if (b.i == 0) throw RefTrap("division by zero");
          if (sign) {
            if (b.i == -1) v.i = op == B::Div ? norm(t, uint64_t{0} - ua) : 0;
            else v.i = op == B::Div ? a.i / b.i : a.i % b.i;
          } else {
            v.i = norm(t, op == B::Div ? ua / ub : ua % ub);
          }
          return v;
        case B::And: v.i = norm(t, ua & ub); return v;
        case B::Or: v.i = norm(t, ua | ub); return v;
        case B::Xor: v.i = norm(t, ua ^ ub); return v;
        default: throw Unsupported("integer operator");
      }
    }
    case VK::Real:
    case VK::LReal: {
      if (is_cmp) return cmp(a.r < b.r ? -1 : a.r > b.r ? 1 : a.r == b.r ? 0 : 2);
      v.t = a.t;
      if (a.t->kind == VK::Real) {
        float x = static_cast<float>(a.r), y = static_cast<float>(b.r), z;
        switch (op) {
          case B::Add: z = x + y; break;
          case B::Sub: z = x - y; break;
          case B::Mul: z = x * y; break;
          case B::Div: z = x / y; break;
          default: throw Unsupported("REAL operator");
        }
        v.r = z;
      } else {
        switch (op) {
          case B::Add: v.r = a.r + b.r; break;
          case B::Sub: v.r = a.r - b.r; break;
          case B::Mul: v.r = a.r * b.r; break;
          case B::Div: v.r = a.r / b.r; break;
          default: throw Unsupported("LREAL operator");
        }
      }
      return v;
    }
    case VK::String:
      if (is_cmp) {
        int c = a.s.compare(b.s);  // byte order ('Z' < 'a'), a prefix before the longer string
        return cmp(c < 0 ? -1 : c > 0 ? 1 : 0);
      }
      throw Unsupported("string operator");
    default:
      throw Unsupported("operator on " + a.t->name);
  }
}

Value Reference::convert(const Value& v, const RType* to) {
  Value r;
  r.t = to;
  VK from = v.t->kind;
  switch (to->kind) {
    case VK::Bool:
      if (from == VK::Bool || from == VK::Int) {
        r.i = v.i != 0;
        return r;
      }
      break;
    case VK::Int:
      if (from == VK::Int || from == VK::Bool) {
        r.i = norm(to, static_cast<uint64_t>(v.i));
        return r;
      }
      if (from == VK::Date || from == VK::Time) {  // a count of the type's unit, truncated toward zero
        r.i = norm(to, static_cast<uint64_t>(v.i / (from == VK::Time ? 1'000'000 : count_unit(v.t))));
        return r;
      }
      if (from == VK::Real) {
        r.i = saturate<float>(std::nearbyint(static_cast<float>(v.r)), to);
        return r;
      }
      if (from == VK::LReal) {
        r.i = saturate<double>(std::nearbyint(v.r), to);
        return r;
      }
      break;
    case VK::Real:
    case VK::LReal: {
      double d;
      if (from == VK::Int) {
        bool u = !v.t->is_signed;
        if (to->kind == VK::Real)
          d = u ? static_cast<float>(static_cast<uint64_t>(v.i)) : static_cast<float>(v.i);
        else
          d = u ? static_cast<double>(static_cast<uint64_t>(v.i)) : static_cast<double>(v.i);
      } else if (from == VK::Real || from == VK::LReal) {
        d = v.r;
      } else {
        break;
      }
      r.r = to->kind == VK::Real ? static_cast<double>(static_cast<float>(d)) : d;
      return r;
    }
    case VK::Date:
      if (from == VK::Int && (v.t->is_signed ? v.t->bits <= 32 : v.t->bits < 64)) {
        r.i = v.i * count_unit(to);
        return r;
      }
      break;
    case VK::Time:
      // DINT_TO_TIME: the integer counts milliseconds.
      if (from == VK::Int && v.t->is_signed && v.t->bits <= 32) {
        r.i = v.i * 1'000'000;
        return r;
      }
      break;
    default:
      break;
  }
  throw Unsupported("conversion " + v.t->name + " to " + to->name);
}

// ---------------------------------------------------------------- calls

// What a call without a result yields (an FB call, a setter, a method without a type).
Value Reference::no_value() const {
  Value v;
  v.t = elementary("BOOL");
  return v;
}

// Methods are virtual: the search starts at the instance's own type and goes up the
// EXTENDS chain; *owner receives the FB that declares the method found.
const st::Pou* Reference::find_method(const st::Pou* fb, const std::string& c, const st::Pou** owner) const {
  for (const st::Pou* p = fb; p; p = base_of(p))
    for (const auto& m : p->methods)
      if (canon(m->name.text) == c) {
        if (owner) *owner = p;
        return m.get();
      }
  return nullptr;
}

const st::PropertyDecl* Reference::find_property(const st::Pou* fb, const std::string& c, const st::Pou** owner) const {
  for (const st::Pou* p = fb; p; p = base_of(p))
    for (const auto& q : p->properties)
      if (canon(q->name.text) == c) {
        if (owner) *owner = p;
        return q.get();
      }
  return nullptr;
}

Value Reference::run_pou(const st::Pou& pou, Instance* self, const st::Pou* owner, const st::CallExpr* c, Env& caller,
                         const std::string& result_name, const st::TypeSpec* result_type, const Value* setter_value) {
  // Arguments are evaluated in the caller's frame first, left to right, then bound.
  std::vector<std::pair<std::string, Value>> inputs;
  std::vector<std::pair<std::string, Value*>> in_outs;
  // A non-formal call binds its arguments in declaration order over inputs, in-outs and
  // outputs, whatever the order of the sections; an argument at an output receives it.
  std::vector<std::string> param_order;
  std::map<std::string, bool> is_in_out, is_output;
  for (const auto& b : pou.var_blocks)
    for (const auto& d : b.decls)
      for (const auto& n : d.names) {
        if (b.section == st::VarSection::Input || b.section == st::VarSection::InOut || b.section == st::VarSection::Output)
          param_order.push_back(canon(n.text));
        if (b.section == st::VarSection::InOut) is_in_out[canon(n.text)] = true;
        if (b.section == st::VarSection::Output) is_output[canon(n.text)] = true;
      }
  std::vector<std::pair<std::string, const st::Expr*>> out_args;  // output name, destination
  if (c) {
    size_t pos = 0;
    for (const auto& a : c->args) {
      if (a.negate) throw Unsupported("negated output argument");
      if (a.is_output) {  // stored after the call
        out_args.emplace_back(canon(a.name->text), a.value.get());
        continue;
      }
      std::string name = a.name ? canon(a.name->text) : (pos < param_order.size() ? param_order[pos] : "");
      if (name.empty()) throw Unsupported("too many positional arguments");
      if (!a.name) ++pos;
      if (is_output.count(name)) out_args.emplace_back(name, a.value.get());
      else if (is_in_out.count(name)) in_outs.emplace_back(name, lvalue(*a.value, caller));
      else inputs.emplace_back(name, eval(*a.value, caller));
    }
  }
  Vars frame;
  Env env;
  env.locals = &frame;
  env.self = self;
  env.owner = owner;
  declare(frame, pou.var_blocks, &env);  // every call starts from the declared initial values
  if (result_type) frame.add(result_name, make(type_of(*result_type)));
  if (setter_value) assign(*frame.find(canon(result_name)), *setter_value);
  for (auto& [name, v] : inputs) {
    Value* dst = frame.find(name);
    if (!dst) throw Unsupported("unknown input " + name);
    assign(*dst, v);
  }
  for (auto& [name, place] : in_outs) frame.aliases[name] = place;
  exec(pou.body, env);
  for (const auto& [name, dst] : out_args)
    if (dst) {
      Value* out = frame.find(name);
      if (!out) throw Unsupported("unknown output " + name);
      Value copy = *out;
      store(*dst, copy, caller);
    }
  if (!result_type || setter_value) return no_value();
  return *frame.find(canon(result_name));
}

Value Reference::call(const st::CallExpr& c, Env& env) {
  if (c.callee->kind == st::ExprKind::Member) {
    const auto& m = static_cast<const st::MemberExpr&>(*c.callee);
    Instance* inst = as_instance(*m.base, env);
    if (!inst) throw Unsupported("method call on a non-instance");
    // SUPER^.M() is bound statically: the search starts above the running method's FB.
    const st::Expr* b = m.base.get();
    if (b->kind == st::ExprKind::Deref) b = static_cast<const st::DerefExpr*>(b)->base.get();
    const st::Pou* start = inst->pou;
    if (b->kind == st::ExprKind::Super) {
      if (!env.owner || !(start = base_of(env.owner))) throw Unsupported("SUPER without a base");
    }
    const st::Pou* owner = nullptr;
    const st::Pou* method = find_method(start, canon(m.member.text), &owner);
    if (!method) {
      // A nested FB instance called as a.b(...) is not generated.
      throw Unsupported("unknown method " + m.member.text);
    }
    return run_pou(*method, inst, owner, &c, env, method->name.text, method->return_type.get(), nullptr);
  }
  if (c.callee->kind != st::ExprKind::Name) throw Unsupported("callee kind");
  std::string name = canon(static_cast<const st::NameExpr&>(*c.callee).name.text);
  bool found = false;
  Value v = standard(name, c, env, &found);
  if (found) return v;
  if (auto p = pous_.find(name); p != pous_.end() && p->second->kind == st::PouKind::Function)
    return run_pou(*p->second, nullptr, nullptr, &c, env, p->second->name.text, p->second->return_type.get(), nullptr);
  // An FB instance: inputs in, body, outputs out.
  Instance* inst = as_instance(*c.callee, env);
  if (!inst) throw Unsupported("unknown function " + name);
  std::vector<std::pair<std::string, Value>> inputs;
  for (const auto& a : c.args) {
    if (!a.name) throw Unsupported("positional FB argument");
    if (!a.is_output) inputs.emplace_back(canon(a.name->text), eval(*a.value, env));
  }
  for (auto& [n, val] : inputs) {
    Value* dst = inst->vars.find(n);
    if (!dst) throw Unsupported("unknown FB input " + n);
    assign(*dst, val);
  }
  Vars temps;
  Env fb_env;
  fb_env.locals = &temps;
  fb_env.self = inst;
  fb_env.owner = inst->pou;
  // A derived FB's call runs its own body only (the generator calls no derived FB).
  exec(inst->pou->body, fb_env);
  for (const auto& a : c.args) {
    if (!a.is_output || !a.value) continue;
    if (a.negate) throw Unsupported("negated output");
    Value out = *inst->vars.find(canon(a.name->text));
    store(*a.value, out, env);
  }
  return no_value();
}

Value Reference::standard(const std::string& name, const st::CallExpr& c, Env& env, bool* found) {
  *found = true;
  std::vector<Value> a;
  auto args = [&](size_t lo, size_t hi) {
    if (c.args.size() < lo || c.args.size() > hi) throw Unsupported(name + ": argument count");
    for (const auto& x : c.args) {
      if (x.is_output) throw Unsupported(name + ": output argument");
      a.push_back(eval(*x.value, env));
    }
  };
  auto less = [&](const Value& x, const Value& y) {
    return binary(st::BinaryOp::Lt, x, y).i != 0;
  };
  auto int_of = [&](const Value& v) {
    if (v.t->kind != VK::Int) throw Unsupported(name + ": integer argument expected");
    return v.i;
  };
  Value v;
  if (name == "REF") {  // the address of a variable: no value is read
    if (c.args.size() != 1 || c.args[0].is_output || c.args[0].name) throw Unsupported("REF arguments");
    Value* target = lvalue(*c.args[0].value, env);
    v.t = ref_to(target->t);
    v.ptr = target;
    return v;
  }
  if (name == "ABS") {
    args(1, 1);
    v = a[0];
    if (v.t->kind == VK::Int) {
      if (v.t->is_signed && v.i < 0) v.i = norm(v.t, uint64_t{0} - static_cast<uint64_t>(v.i));
    } else if (v.t->kind == VK::Real || v.t->kind == VK::LReal) {
      v.r = std::fabs(v.r);
    } else {
      throw Unsupported("ABS of " + v.t->name);
    }
    return v;
  }
  if (name == "SQRT") {
    args(1, 1);
    v = a[0];
    if (v.t->kind == VK::Real) v.r = std::sqrt(static_cast<float>(v.r));
    else if (v.t->kind == VK::LReal) v.r = std::sqrt(v.r);
    else throw Unsupported("SQRT of " + v.t->name);
    return v;
  }
  if (name == "MIN" || name == "MAX") {
    args(2, 16);
    v = a[0];
    for (size_t i = 1; i < a.size(); ++i)
      if (name == "MIN" ? less(a[i], v) : less(v, a[i])) v = a[i];
    return v;
  }
  if (name == "LIMIT") {
    args(3, 3);
    // LIMIT(MN, IN, MX); the generator keeps MN <= MX.
    v = a[1];
    if (less(v, a[0])) v = a[0];
    if (less(a[2], v)) v = a[2];
    return v;
  }
  if (name == "SEL") {
    args(3, 3);
    if (a[0].t->kind != VK::Bool) throw Unsupported("SEL selector");
    return a[0].i ? a[2] : a[1];
  }
  if (name == "MUX") {
    args(3, 32);
    int64_t k = int_of(a[0]);
    if (k < 0 || k >= static_cast<int64_t>(a.size()) - 1) throw RefTrap("MUX selector out of range");
    return a[static_cast<size_t>(k) + 1];
  }
  if (name == "SHL" || name == "SHR" || name == "ROL" || name == "ROR") {
    args(2, 2);
    v = a[0];
    if (v.nominal && (name == "ROL" || name == "ROR")) {  // a rotation has its IEC type's width
      v.i = norm(v.nominal, static_cast<uint64_t>(v.i));
      v.t = v.nominal;
      v.nominal = nullptr;
    }
    if (v.t->kind != VK::Int) throw Unsupported(name + " of " + v.t->name);
    auto n = static_cast<uint64_t>(int_of(a[1]));
    auto w = static_cast<uint64_t>(v.t->bits);
    uint64_t mask = w == 64 ? ~uint64_t{0} : (uint64_t{1} << w) - 1;
    uint64_t x = static_cast<uint64_t>(v.i) & mask;
    auto shl = [&](uint64_t y, uint64_t k) { return k >= w ? 0 : (y << k) & mask; };
    auto shr = [&](uint64_t y, uint64_t k) { return k >= w ? 0 : (y & mask) >> k; };
    uint64_t out;
    if (name == "SHL") out = shl(x, n);
    else if (name == "SHR") out = shr(x, n);
    else {
      n %= w;
      out = n == 0 ? x : name == "ROL" ? (shl(x, n) | shr(x, w - n)) : (shr(x, n) | shl(x, w - n));
    }
    v.i = norm(v.t, out);
    return v;
  }
  auto clamp = [](int64_t n, size_t max) -> size_t {
    if (n < 0) return 0;
    return static_cast<size_t>(std::min<uint64_t>(static_cast<uint64_t>(n), max));
  };
  auto str = [&](const Value& x) -> const std::string& {
    if (x.t->kind != VK::String) throw Unsupported(name + ": string argument expected");
    return x.s;
  };
  if (name == "LEN") {
    args(1, 1);
    v.t = elementary("INT");
    v.i = norm(v.t, str(a[0]).size());
    return v;
  }
  if (name == "CONCAT") {
    args(2, 32);
    v.t = string255_;
    v.s = str(a[0]);
    for (size_t i = 1; i < a.size(); ++i) v.s = (v.s + str(a[i])).substr(0, 255);
    return v;
  }
  if (name == "LEFT" || name == "RIGHT") {
    args(2, 2);
    const std::string& s = str(a[0]);
    size_t n = clamp(int_of(a[1]), s.size());
    v.t = string255_;
    v.s = name == "LEFT" ? s.substr(0, n) : s.substr(s.size() - n);
    return v;
  }
  if (name == "MID") {
    args(3, 3);
    const std::string& s = str(a[0]);
    int64_t p = int_of(a[2]);
    v.t = string255_;
    if (p >= 1 && static_cast<size_t>(p) <= s.size()) v.s = s.substr(static_cast<size_t>(p - 1), clamp(int_of(a[1]), s.size()));
    return v;
  }
  if (auto at = name.find("_TO_"); at != std::string::npos) {
    const RType* to = elementary(name.substr(at + 4));
    const RType* from = elementary(name.substr(0, at));
    if (!to || !from) throw Unsupported("conversion " + name);
    args(1, 1);
    if (a[0].nominal == from) {  // a register value converted: cut to its IEC type first
      a[0].i = norm(from, static_cast<uint64_t>(a[0].i));
      a[0].t = from;
      a[0].nominal = nullptr;
    }
    if (a[0].t != from) throw Unsupported(name + " applied to " + a[0].t->name);
    return convert(a[0], to);
  }
  *found = false;
  return v;
}

// ---------------------------------------------------------------- results

void Reference::collect(const std::string& path, const Value& v, std::vector<Leaf>& out) const {
  switch (v.t->kind) {
    case VK::Struct:
      for (size_t i = 0; i < v.elems.size(); ++i) collect(path + "." + v.t->fields[i].first, v.elems[i], out);
      return;
    case VK::Array:
      for (size_t i = 0; i < v.elems.size(); ++i)
        collect(path + "[" + std::to_string(v.t->lo + static_cast<int64_t>(i)) + "]", v.elems[i], out);
      return;
    case VK::Fb:
      for (const auto& n : v.fb->vars.order) collect(path + "." + n, v.fb->vars.by_name.at(canon(n)), out);
      return;
    case VK::Itf:
    case VK::Ref:
      return;  // a reference, not a value: what it refers to is compared where it is declared
    default:
      out.push_back(Leaf{path, v});
  }
}

std::vector<Leaf> Reference::leaves() const {
  std::vector<Leaf> out;
  auto skip = [&](const std::string& n) { return for_vars_.count(canon(n)) != 0; };
  for (const auto& n : globals_.order)
    if (!skip(n)) collect(n, globals_.by_name.at(canon(n)), out);
  for (const auto& [pname, inst] : programs_)
    for (const auto& n : inst->vars.order)
      if (!skip(n)) collect(pname + "." + n, inst->vars.by_name.at(canon(n)), out);
  return out;
}

std::string Reference::text(const Value& v) {
  switch (v.t->kind) {
    case VK::Bool: return v.i ? "TRUE" : "FALSE";
    case VK::Int:
      return v.t->is_signed ? std::to_string(v.i) : std::to_string(static_cast<uint64_t>(v.i));
    case VK::Real:
    case VK::LReal: {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.17g", v.r);
      return buf;
    }
    case VK::Time: case VK::Date: return std::to_string(v.i) + "ns";
    case VK::String: return "'" + v.s + "'";
    default: return "?";
  }
}

}  // namespace plcfi::oracle
