// Declarations: the index of types and POUs, type resolution, memory layout of
// structs, instances and frames, global variables, and constant evaluation.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <unordered_set>

#include "compiler_impl.hpp"
#include "vm/memory.hpp"

namespace plcfi::st::detail {

namespace {
constexpr int64_t kMaxCodesysTimeNs = int64_t{0xFFFFFFFF} * 1'000'000;  // T#49d17h2m47s295ms
}  // namespace

namespace {

template <class T>
void put(uint8_t* p, T v) {
  store_as<T>(p, v);
}
}  // namespace

uint32_t Compiler::alloc(uint32_t size, uint32_t align) {
  auto& img = app_->init_image;
  uint32_t addr = align_up(static_cast<uint32_t>(img.size()), align < 1 ? 1 : align);
  img.resize(addr + size, 0);
  return addr;
}

uint32_t Compiler::selector(const std::string& method_canon) {
  auto it = selectors_.find(method_canon);
  if (it != selectors_.end()) return it->second;
  uint32_t id = next_selector_++;
  selectors_[method_canon] = id;
  return id;
}

// ------------------------------------------------------------------ index

void Compiler::index_unit(const CompilationUnit& u, bool stdlib) {
  for (const auto& td : u.types) {
    std::string key = canon(td.name.text);
    if (types_.count(key) || tt_->by_name(key)) {
      diags_.error("ST202", td.name.loc, "type '" + td.name.text + "' is declared twice");
      continue;
    }
    types_[key] = TypeEntry{&td, u.file, nullptr, false};
  }
  for (const auto& p : u.pous) index_pou(*p, u.file, stdlib, nullptr);
}

void Compiler::index_pou(const Pou& p, uint32_t file, bool stdlib, PouInfo* owner) {
  auto info = std::make_unique<PouInfo>();
  PouInfo* pi = info.get();
  pi->kind = p.kind;
  pi->name = p.name.text;
  pi->loc = p.loc;
  pi->file = file;
  pi->is_stdlib = stdlib;
  pi->owner = owner;
  pi->has_body = p.has_body;
  pi->access = p.access;
  pi->is_abstract = p.is_abstract;
  PouSource& ps = src(pi);
  ps.decl = &p;
  for (const auto& blk : p.var_blocks) ps.blocks.push_back(&blk);
  if (p.kind == PouKind::Program || p.kind == PouKind::FunctionBlock) {
    pi->type = tt_->make(TypeKind::Pou, p.name.text);
    pi->type->pou = pi;
    pi->type->align = 8;
    pi->type_id = next_type_id_++;
  } else if (p.kind == PouKind::Interface) {
    pi->type = tt_->make(TypeKind::Interface, p.name.text);
    pi->type->pou = pi;
    pi->type->size = 4;
    pi->type->align = 4;
    pi->type->init.assign(4, 0);
  }
  if (owner) {
    for (const auto& m : owner->methods)
      if (iequals(m->name, pi->name)) diags_.error("ST202", p.name.loc, "method '" + pi->name + "' is declared twice in '" + owner->name + "'");
    owner->methods.push_back(std::move(info));
    pi->selector = selector(canon(pi->name));
    all_methods_.push_back(pi);
  } else {
    std::string key = canon(p.name.text);
    if (pous_.count(key) || types_.count(key)) {
      diags_.error("ST202", p.name.loc, "'" + p.name.text + "' is declared twice");
    } else {
      pous_[key] = pi;
    }
    app_->pous.push_back(std::move(info));
  }
  for (const auto& m : p.methods) index_pou(*m, file, stdlib, pi);
  for (const auto& prop : p.properties) {
    for (int k = 0; k < 2; ++k) {
      const PouPtr& acc = k == 0 ? prop->getter : prop->setter;
      if (!acc) continue;
      auto a = std::make_unique<PouInfo>();
      a->kind = PouKind::Method;
      a->name = std::string(k == 0 ? "__GET_" : "__SET_") + canon(prop->name.text);
      a->loc = acc->loc;
      a->file = file;
      a->is_stdlib = stdlib;
      a->owner = pi;
      a->has_body = acc->has_body;
      a->access = acc->access;
      a->property = prop->name.text;
      PouSource& as = src(a.get());
      as.decl = acc.get();
      for (const auto& blk : acc->var_blocks) as.blocks.push_back(&blk);
      as.property = prop.get();
      a->is_setter = k == 1;
      a->selector = selector(a->name);
      all_methods_.push_back(a.get());
      pi->methods.push_back(std::move(a));
    }
  }
}

// ------------------------------------------------------------------ types

const Type* Compiler::named_type(const Ident& name, uint32_t file, bool report) {
  if (const Type* t = tt_->by_name(name.text)) return t;
  std::string key = canon(name.text);
  auto it = types_.find(key);
  if (it != types_.end()) {
    TypeEntry& te = it->second;
    if (te.type) return te.type;
    if (te.resolving) {
      diags_.error("ST201", name.loc, "type '" + name.text + "' is defined in terms of itself");
      return nullptr;
    }
    te.resolving = true;
    const Type* t = resolve_type(*te.decl->spec, te.file, te.decl->name.text);
    if (t && te.decl->init) {
      // TYPE T : INT := 5; END_TYPE -> a copy of the type with its own default.
      Type* c = tt_->make(t->kind, te.decl->name.text);
      *c = *t;
      c->name = te.decl->name.text;
      c->init.assign(c->size, 0);
      std::copy(t->init.begin(), t->init.end(), c->init.begin());
      write_init(c->init, 0, t, te.decl->init.get(), te.file);
      t = c;
    }
    te.type = t;
    te.resolving = false;
    return t;
  }
  auto pit = pous_.find(key);
  if (pit != pous_.end()) {
    PouInfo* p = pit->second;
    if (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program) {
      ensure_compiled(p, name.loc);
      return p->type;
    }
    if (p->kind == PouKind::Interface) return p->type;
    if (report) diags_.error("ST201", name.loc, "'" + name.text + "' is a function, not a type");
    return nullptr;
  }
  if (report) {
    const auto& tc2 = tc2_types();
    const auto& sys = tc2_system_items();
    const bool is_tc2 = std::any_of(tc2.begin(), tc2.end(), [&](const Tc2Type& t) { return iequals(t.name, name.text); }) ||
                        std::any_of(sys.begin(), sys.end(), [&](const Tc2Item& t) { return iequals(t.name, name.text); });
    const char* lib = unprovided_library(name.text);
    diags_.error("ST201", name.loc, "unknown type '" + name.text + "'" +
                                        (is_tc2 && opt_.dialect == Dialect::Iec ? " (a type of TwinCAT's Tc2 libraries: --dialect codesys)"
                                         : lib ? ": " + name.text + " is from " + std::string(lib) + ", which plcfi does not provide"
                                               : std::string()));
  }
  return nullptr;
}

const Type* Compiler::resolve_type(const TypeSpec& spec, uint32_t file, const std::string& name_hint) {
  // Named types are resolved on demand, so a STRUCT holding a STRUCT holding ... recurses
  // once per level; the parser's limit covers only types written inside one another.
  struct Depth {
    explicit Depth(uint32_t& d) : d_(d) { ++d_; }
    ~Depth() { --d_; }
    Depth(const Depth&) = delete;
    Depth& operator=(const Depth&) = delete;
    uint32_t& d_;
  } depth(type_depth_);
  if (type_depth_ > kMaxTypeDepth) {
    if (!type_depth_reported_) {
      type_depth_reported_ = true;
      diags_.error("ST117", spec.loc, "types nested too deep (more than " + std::to_string(kMaxTypeDepth) +
                                          " levels of types holding other types)");
    }
    return nullptr;
  }
  uint32_t saved = file_;
  file_ = file;
  const Type* result = nullptr;
  // FB_init arguments are taken only by the declaration a caller allowed them in, never by
  // a type inside it (ARRAY OF FB_X(...), a structure's member).
  const bool init_args_ok = init_args_ok_;
  init_args_ok_ = false;
  switch (spec.kind) {
    case TypeSpecKind::Named: {
      std::string c = canon(spec.name.text);
      if ((c == "STRING" || c == "WSTRING") && spec.string_length) {
        auto n = const_int(*spec.string_length, file);
        if (!n) break;
        if (*n < 1 || *n > 65535) {
          diags_.error("ST238", spec.string_length->loc, "string length must be 1..65535, not " + std::to_string(*n));
          break;
        }
        result = tt_->string_type(static_cast<uint32_t>(*n), c == "WSTRING");
        break;
      }
      result = named_type(spec.name, file);
      if (result && spec.has_init_args) check_init_args(spec, result, init_args_ok);
      break;
    }
    case TypeSpecKind::Array: {
      if (!spec.element) break;
      const bool open_ok = open_array_ok_;
      open_array_ok_ = false;  // not for the element type
      const Type* el = resolve_type(*spec.element, file);
      open_array_ok_ = open_ok;
      if (!el) break;
      std::vector<Type::Dim> dims;
      uint64_t count = 1;
      bool ok = true;
      const size_t open = static_cast<size_t>(std::count_if(spec.dims.begin(), spec.dims.end(), [](const auto& r) { return r.open; }));
      if (open) {
        // ARRAY[*]: the bounds are the argument's (a VAR_IN_OUT only, checked where declared).
        if (open != spec.dims.size()) {
          diags_.error("ST229", spec.loc, "ARRAY[*] has '*' for every dimension or for none");
          break;
        }
        if (!open_ok) {
          diags_.error("ST229", spec.loc, "ARRAY[*] is the type of a VAR_IN_OUT only: its bounds are the argument's");
          break;
        }
        std::string nm = "ARRAY [*";
        for (size_t i = 1; i < open; ++i) nm += ", *";
        nm += "] OF " + el->name;
        Type* t = tt_->make(TypeKind::Array, nm);
        t->elem = el;
        t->dims.assign(open, Type::Dim{0, 0});
        t->open = true;
        t->align = el->align;
        result = t;
        break;
      }
      for (const auto& r : spec.dims) {
        if (!r.lo || !r.hi) {
          ok = false;
          break;
        }
        std::optional<int64_t> lo_opt = const_int(*r.lo, file), hi_opt = const_int(*r.hi, file);
        if (!lo_opt || !hi_opt) {
          ok = false;
          break;
        }
        int64_t lo = *lo_opt, hi = *hi_opt;
        if (hi < lo || lo < INT32_MIN || hi > INT32_MAX) {
          diags_.error("ST229", r.lo->loc, "invalid array bounds " + std::to_string(lo) + ".." + std::to_string(hi));
          ok = false;
          break;
        }
        dims.push_back({lo, hi});
        count *= static_cast<uint64_t>(hi - lo + 1);
      }
      if (!ok) break;
      if (count * el->size > (64u << 20)) {
        diags_.error("ST229", spec.loc, "array of " + std::to_string(count) + " elements is too large");
        break;
      }
      std::string nm = "ARRAY [";
      for (size_t i = 0; i < dims.size(); ++i)
        nm += (i ? ", " : "") + std::to_string(dims[i].lo) + ".." + std::to_string(dims[i].hi);
      nm += "] OF " + el->name;
      Type* t = tt_->make(TypeKind::Array, name_hint.empty() ? nm : name_hint);
      t->elem = el;
      t->dims = dims;
      t->align = el->align;
      t->size = static_cast<uint32_t>(count) * el->size;
      t->init.resize(t->size);
      for (uint64_t i = 0; i < count; ++i)
        std::copy(el->init.begin(), el->init.end(), t->init.begin() + static_cast<long>(i * el->size));
      result = t;
      break;
    }
    case TypeSpecKind::Struct: {
      if (spec.is_union && opt_.dialect == Dialect::Iec)
        diags_.error("ST241", spec.loc, "UNION is CODESYS, not IEC 61131-3: declare a STRUCT, or use --dialect codesys");
      Type* t = tt_->make(TypeKind::Struct, name_hint.empty() ? (spec.is_union ? "UNION" : "STRUCT") : name_hint);
      t->is_union = spec.is_union;
      // Registered before its members so a member REF_TO the struct itself resolves.
      if (!name_hint.empty()) {
        auto it = types_.find(canon(name_hint));
        if (it != types_.end() && !it->second.type) it->second.type = t;
      }
      laying_out_.push_back(t);
      if (spec.struct_base) {
        // STRUCT EXTENDS (CODESYS): the base's members first, at their offsets.
        if (opt_.dialect == Dialect::Iec)
          diags_.error("ST241", spec.struct_base->loc, "STRUCT EXTENDS is CODESYS, not IEC 61131-3: declare the base as "
                                                       "a member, or use --dialect codesys");
        const Type* base = named_type(*spec.struct_base, file);
        if (base && (base->kind != TypeKind::Struct || base->is_union)) {
          diags_.error("ST226", spec.struct_base->loc, "'" + spec.struct_base->text + "' is not a STRUCT");
        } else if (base && std::find(laying_out_.begin(), laying_out_.end(), base) != laying_out_.end()) {
          diags_.error("ST226", spec.struct_base->loc, "STRUCT '" + t->name + "' extends itself");
        } else if (base) {
          t->fields = base->fields;
          t->size = base->size;
          t->align = base->align;
          t->init = base->init;
        }
      }
      layout_struct(t, spec.members, file);
      laying_out_.pop_back();
      result = t;
      break;
    }
    case TypeSpecKind::Enum: {
      const Type* base = spec.element ? resolve_type(*spec.element, file) : elem(TypeKind::Int);
      if (!base) break;
      if (!base->is_integer() && !base->is_bitstring()) {
        diags_.error("ST201", spec.loc, "the base type of an enumeration must be an integer type, not " + base->name);
        break;
      }
      Type* t = tt_->make(TypeKind::Enum, name_hint.empty() ? "<enum>" : name_hint);
      t->base = base;
      t->size = base->size;
      t->align = base->align;
      int64_t next = 0;
      for (const auto& v : spec.enum_values) {
        if (v.value) {
          auto x = const_int(*v.value, file);
          if (x) next = *x;
        }
        for (const auto& [n, _] : t->enum_values)
          if (iequals(n, v.name.text)) diags_.error("ST202", v.name.loc, "enumeration value '" + v.name.text + "' is declared twice");
        t->enum_values.emplace_back(v.name.text, next);
        enum_values_[canon(v.name.text)].push_back(t);
        ++next;
      }
      t->init.assign(t->size, 0);
      if (!t->enum_values.empty()) write_const(t->init.data(), base, ConstV{ConstV::K::Int, t->enum_values[0].second, 0, {}}, spec.loc);
      result = t;
      break;
    }
    case TypeSpecKind::Subrange: {
      const Type* base = spec.element ? resolve_type(*spec.element, file) : nullptr;
      if (!base) break;
      if (!base->is_integer()) {
        diags_.error("ST229", spec.loc, "a subrange needs an integer base type, not " + base->name);
        break;
      }
      auto lo_opt = spec.sub_lo ? const_int(*spec.sub_lo, file) : std::nullopt;
      auto hi_opt = spec.sub_hi ? const_int(*spec.sub_hi, file) : std::nullopt;
      if (!lo_opt || !hi_opt) break;
      // Plain values: GCC 12 misreads the optionals as maybe uninitialized here.
      const int64_t lo_v = lo_opt.value_or(0), hi_v = hi_opt.value_or(0);
      const int64_t* lo = &lo_v;
      const int64_t* hi = &hi_v;
      if (*hi < *lo) {
        diags_.error("ST229", spec.loc, "empty subrange " + std::to_string(*lo) + ".." + std::to_string(*hi));
        break;
      }
      Type* t = tt_->make(base->kind, name_hint.empty() ? base->name + " (" + std::to_string(*lo) + ".." + std::to_string(*hi) + ")" : name_hint);
      t->size = base->size;
      t->align = base->align;
      t->ranged = true;
      t->lo = *lo;
      t->hi = *hi;
      t->init.assign(t->size, 0);
      // IEC 61131-3: a subrange's default initial value is its lower limit.
      write_const(t->init.data(), base, ConstV{ConstV::K::Int, *lo, 0, {}}, spec.loc);
      result = t;
      break;
    }
    case TypeSpecKind::Ref: {
      if (!spec.element) break;
      // REF_TO a type being declared (linked lists): resolve lazily through the entry.
      const Type* target = resolve_type(*spec.element, file);
      if (spec.is_reference) {
        if (opt_.dialect == Dialect::Iec) {
          // Reported once here; the declaration still gets its type, so its uses add no errors.
          diags_.error("ST241", spec.loc, "REFERENCE TO is CODESYS, not IEC 61131-3: declare a REF_TO and "
                                          "dereference it with '^', or use --dialect codesys");
        }
        if (target && target->kind == TypeKind::Ref && target->implicit_deref) {
          diags_.error("ST232", spec.loc, "a REFERENCE TO cannot refer to another REFERENCE TO");
          break;
        }
        if (target) result = tt_->reference_to(target);
        break;
      }
      if (target) result = tt_->ref_to(target);
      break;
    }
  }
  file_ = saved;
  return result;
}

void Compiler::layout_struct(Type* t, const std::vector<VarDecl>& members, uint32_t file) {
  // A STRUCT that EXTENDS another holds the base's fields, size and image already.
  uint32_t off = t->fields.empty() ? 0 : t->size, align = t->fields.empty() ? 1 : t->align;
  const std::vector<uint8_t> base_init = t->init;
  struct Pending {
    uint32_t offset;
    const Type* type;
    const Expr* init;
  };
  std::vector<Pending> inits;
  std::unordered_set<std::string> names;  // canonical member names (a linear search was quadratic)
  for (const auto& f : t->fields) names.insert(canon(f.name));
  for (const auto& d : members) {
    const Type* ft = d.type ? resolve_type(*d.type, file) : nullptr;
    if (!ft) continue;
    // A member of a STRUCT still being laid out (itself, or one that holds this one), or an
    // array of it, would make the STRUCT infinitely large; only a REF_TO may point back.
    const Type* held = ft;
    while (held->kind == TypeKind::Array && held->elem) held = held->elem;
    if (held->kind == TypeKind::Struct && std::find(laying_out_.begin(), laying_out_.end(), held) != laying_out_.end()) {
      diags_.error("ST201", d.type->loc, "STRUCT '" + t->name + "' contains " +
                                             (held == t ? std::string("itself") : "'" + held->name + "', which contains it") +
                                             " (use REF_TO for a link back)");
      continue;
    }
    if (t->is_union && (held->kind == TypeKind::Pou || held->kind == TypeKind::Interface)) {
      // An instance shares no storage: its state and hidden fields would be overwritten.
      diags_.error("ST201", d.type->loc, "a UNION cannot hold " + std::string(held->kind == TypeKind::Pou ? "function block instances" : "interface references") +
                                             " ('" + held->name + "'): use a STRUCT");
      continue;
    }
    if (t->is_union && d.init && !t->fields.empty())
      diags_.error("ST209", d.init->loc, "only the first member of a UNION can have an initial value (it and "
                                         "the others share their storage)");
    for (const auto& n : d.names) {
      if (!names.insert(canon(n.text)).second) {
        diags_.error("ST202", n.loc, "member '" + n.text + "' is declared twice");
        continue;
      }
      if (t->is_union) {  // every member at offset 0; the union is as large as its largest
        t->fields.push_back(Field{n.text, ft, 0, n.loc});
        if (t->fields.size() == 1) inits.push_back({0, ft, d.init.get()});
        off = std::max(off, ft->size);
        align = std::max(align, ft->align);
        continue;
      }
      off = align_up(off, ft->align);
      t->fields.push_back(Field{n.text, ft, off, n.loc});
      inits.push_back({off, ft, d.init.get()});
      off += ft->size;
      align = std::max(align, ft->align);
    }
  }
  t->fields.shrink_to_fit();
  t->align = std::min<uint32_t>(align, 8);
  t->size = align_up(off, t->align);
  t->init.assign(t->size, 0);
  std::copy(base_init.begin(), base_init.begin() + std::min(base_init.size(), t->init.size()), t->init.begin());
  for (const auto& p : inits) write_init(t->init, p.offset, p.type, p.init, file);
}

// ------------------------------------------------------------------ constants

std::optional<int64_t> Compiler::const_int(const Expr& e, uint32_t file) {
  auto c = const_eval(e, file);
  if (!c) return std::nullopt;
  if (c->k != ConstV::K::Int) {
    diags_.error("ST215", e.loc, "an integer constant is required here");
    return std::nullopt;
  }
  return c->i;
}

std::optional<Compiler::EnumValueRef> Compiler::qualified_enum(const MemberExpr& m, uint32_t file, bool report, bool* reported) {
  if (reported) *reported = false;
  if (m.base->kind != ExprKind::Name) return std::nullopt;
  const Ident& tn = static_cast<const NameExpr&>(*m.base).name;
  std::string key = canon(tn.text);
  if (lookup(key) || !types_.count(key)) return std::nullopt;
  const Type* t = named_type(tn, file, report);
  if (!t || t->kind != TypeKind::Enum) return std::nullopt;
  for (const auto& [n, v] : t->enum_values)
    if (iequals(n, m.member.text)) return EnumValueRef{t, v};
  if (report) diags_.error("ST230", m.member.loc, "'" + m.member.text + "' is not a value of " + t->name);
  if (reported) *reported = true;
  return std::nullopt;
}

std::optional<ConstV> Compiler::const_eval(const Expr& e, uint32_t file, bool report) {
  auto fail = [&](const std::string& msg) -> std::optional<ConstV> {
    if (report) diags_.error("ST215", e.loc, msg);
    return std::nullopt;
  };
  // Constants defined through constants (C0 := C1 + 1, C1 := C2 + 1, ...) recurse once per
  // link, and a cycle would never end: both stop at a fixed depth.
  struct Depth {
    explicit Depth(uint32_t& d) : d_(d) { ++d_; }
    ~Depth() { --d_; }
    Depth(const Depth&) = delete;
    Depth& operator=(const Depth&) = delete;
    uint32_t& d_;
  } depth(const_depth_);
  if (const_depth_ > kMaxConstDepth) {
    ++const_depth_hits_;
    if (report && !const_depth_reported_) {
      const_depth_reported_ = true;
      diags_.error("ST117", e.loc, "constant defined through more than " + std::to_string(kMaxConstDepth) +
                                       " levels of other constants, or through itself");
    }
    return std::nullopt;
  }
  switch (e.kind) {
    case ExprKind::Literal: {
      const auto& l = static_cast<const LiteralExpr&>(e);
      ConstV c;
      switch (l.lit) {
        case LiteralKind::Int:
          c.k = ConstV::K::Int;
          c.i = static_cast<int64_t>(l.int_value);
          if (!l.type_prefix.empty()) {
            const Type* t = tt_->by_name(l.type_prefix);
            if (t && t->is_real()) {
              c.k = ConstV::K::Real;
              c.r = static_cast<double>(l.int_value);
            } else if (t && t->kind == TypeKind::Bool) {
              c.k = ConstV::K::Bool;
            }
          }
          return c;
        case LiteralKind::Real: c.k = ConstV::K::Real; c.r = l.real_value; return c;
        case LiteralKind::Bool: c.k = ConstV::K::Bool; c.i = l.int_value ? 1 : 0; return c;
        case LiteralKind::String: case LiteralKind::WString: c.k = ConstV::K::Str; c.s = l.str_value; return c;
        default:
          if (l.beyond_signed && opt_.dialect != Dialect::Codesys) {
            if (report)
              diags_.error("ST241", e.loc, "an LTIME beyond LTIME#106751d23h47m16s854ms775us807ns is CODESYS, not IEC 61131-3 "
                                           "(whose LTIME is signed): use --dialect codesys, where LTIME is unsigned up to 2^64 - 1 ns");
            return std::nullopt;
          }
          // CODESYS's TIME is a 32-bit count of milliseconds: a literal beyond it is an error
          // there, and here rather than a value the PLC cannot hold.
          if (l.lit == LiteralKind::Time && !l.is_long && opt_.dialect == Dialect::Codesys &&
              (l.time_ns > kMaxCodesysTimeNs || l.time_ns < -kMaxCodesysTimeNs)) {
            if (report)
              diags_.error("ST008", e.loc, "a TIME holds at most T#49d17h2m47s295ms under --dialect codesys (a 32-bit count "
                                           "of milliseconds, as on CODESYS and TwinCAT): use an LTIME# literal");
            return std::nullopt;
          }
          c.k = ConstV::K::Int;
          c.i = l.time_ns;
          return c;
      }
    }
    case ExprKind::EnumLiteral: {
      const auto& el = static_cast<const EnumLiteralExpr&>(e);
      const Type* t = named_type(el.type_name, file, report);
      if (!t) return std::nullopt;
      if (t->kind == TypeKind::Enum) {
        for (const auto& [n, v] : t->enum_values)
          if (iequals(n, el.value.text)) return ConstV{ConstV::K::Int, v, 0, {}};
        return fail("'" + el.value.text + "' is not a value of " + t->name);
      }
      return fail("'" + el.type_name.text + "' is not an enumeration");
    }
    case ExprKind::Member: {
      bool reported = false;
      const auto& m = static_cast<const MemberExpr&>(e);
      if (auto ev = qualified_enum(m, file, report, &reported))
        return ConstV{ConstV::K::Int, ev->value, 0, {}};
      if (reported) return std::nullopt;
      // A global constant qualified by its list's name: Params.MaxAxes.
      // And by a library's namespace too: TcUnit.GVL_Param_TcUnit.MaxNumberOfTestSuites.
      const Expr* list = m.base.get();
      if (list->kind == ExprKind::Member) {
        const auto& lib = static_cast<const MemberExpr&>(*list);
        if (lib.base->kind == ExprKind::Name && !lookup(canon(static_cast<const NameExpr&>(*lib.base).name.text))) {
          auto it = global_consts_.find(canon(lib.member.text) + "." + canon(m.member.text));
          if (it != global_consts_.end() && it->second.first->init) return const_eval(*it->second.first->init, it->second.second, report);
        }
      }
      if (m.base->kind == ExprKind::Name) {
        auto it = global_consts_.find(canon(static_cast<const NameExpr&>(*m.base).name.text) + "." + canon(m.member.text));
        if (it != global_consts_.end() && it->second.first->init) return const_eval(*it->second.first->init, it->second.second, report);
      }
      return fail("a constant expression is required here");
    }
    case ExprKind::Name: {
      const auto& n = static_cast<const NameExpr&>(e);
      std::string key = canon(n.name.text);
      const Symbol* s = lookup(key);
      if (s && s->kind == SymKind::EnumValue) return ConstV{ConstV::K::Int, s->enum_value, 0, {}};
      // A constant found too deep is remembered: a chain of 10,000 constants would
      // otherwise be followed 512 links deep again from each of its links. (Values are
      // not kept: a name in an initializer resolves where it is evaluated.)
      auto init_value = [&](const Expr& init, uint32_t f) -> std::optional<ConstV> {
        if (too_deep_consts_.count(&init)) return std::nullopt;
        const uint32_t hits = const_depth_hits_;
        auto c = const_eval(init, f, report);
        if (!c && const_depth_hits_ != hits) too_deep_consts_.insert(&init);
        return c;
      };
      if (s && s->kind == SymKind::Var && s->constant && is_parameter(*s))
        return fail("'" + n.name.text + "' is a constant input: its value comes with each call, it is not known here");
      const VarDecl* sd = s && s->kind == SymKind::Var && s->constant ? decl_of(s) : nullptr;
      if (sd && sd->init) {
        auto c = init_value(*sd->init, file);
        if (c && s->type && s->type->is_real() && c->k == ConstV::K::Int) {
          c->k = ConstV::K::Real;
          c->r = static_cast<double>(c->i);
        }
        return c;
      }
      if (!s || s->kind != SymKind::Var) {
        // Constants not laid out yet: the POU's own (ARRAY[1..N] before N's block) and globals.
        auto const_init = [&](const VarDecl& d) -> const Expr* {
          if (!d.constant || !d.init || d.section == VarSection::Input || d.section == VarSection::InOut) return nullptr;
          for (const auto& nm : d.names)
            if (iequals(nm.text, n.name.text)) return d.init.get();
          return nullptr;
        };
        if (decl_pou_)
          for (const VarBlock* blk : src(decl_pou_).blocks)
            for (const auto& d : blk->decls)
              if (const Expr* init = const_init(d)) return init_value(*init, decl_pou_->file);
        auto gc = global_consts_.find(key);
        if (gc != global_consts_.end() && const_init(*gc->second.first))
          return init_value(*const_init(*gc->second.first), gc->second.second);
      }
      if (!s) {
        auto it = enum_values_.find(key);
        if (it != enum_values_.end() && it->second.size() == 1) {
          for (const auto& [vn, v] : it->second[0]->enum_values)
            if (iequals(vn, n.name.text)) return ConstV{ConstV::K::Int, v, 0, {}};
        }
      }
      return fail("'" + n.name.text + "' is not a constant");
    }
    case ExprKind::Unary: {
      const auto& u = static_cast<const UnaryExpr&>(e);
      auto c = const_eval(*u.operand, file, report);
      if (!c) return std::nullopt;
      if (u.op == UnaryOp::Plus) return c;
      if (u.op == UnaryOp::Neg) {
        if (c->k == ConstV::K::Int) c->i = static_cast<int64_t>(0ULL - static_cast<uint64_t>(c->i));
        else if (c->k == ConstV::K::Real) c->r = -c->r;
        else return fail("cannot negate this constant");
        return c;
      }
      if (c->k == ConstV::K::Bool) c->i = !c->i;
      else if (c->k == ConstV::K::Int) c->i = ~c->i;
      else return fail("NOT needs a BOOL or bit-string constant");
      return c;
    }
    case ExprKind::Binary: {
      // A left-associative chain is folded in a loop along its left spine (see binary()).
      std::vector<const BinaryExpr*> spine{static_cast<const BinaryExpr*>(&e)};
      while (spine.back()->lhs->kind == ExprKind::Binary) spine.push_back(static_cast<const BinaryExpr*>(spine.back()->lhs.get()));
      auto l = const_eval(*spine.back()->lhs, file, report);
      bool ok = l.has_value();
      for (size_t k = spine.size(); k-- > 0;) {
        const BinaryExpr& b = *spine[k];
        auto r = const_eval(*b.rhs, file, report);
        if (!ok || !r) {
          ok = false;
          continue;  // still check the other operands
        }
        std::string why;
        l = fold_binary(b.op, *l, *r, &why);
        if (!l) {
          if (report) diags_.error(why.find("zero") != std::string::npos ? "ST217" : "ST215",
                                   why.find("zero") != std::string::npos ? b.rhs->loc : b.loc, why);
          ok = false;
        }
      }
      return ok ? l : std::nullopt;
    }
    default: return fail("a constant expression is required here");
  }
}

bool Compiler::write_const(uint8_t* dst, const Type* t, const ConstV& c, SourceLoc loc) {
  auto range_error = [&](const std::string& v) {
    diags_.error("ST216", loc, "constant " + v + " does not fit " + t->name);
    return false;
  };
  if (t->kind == TypeKind::Enum) return write_const(dst, t->base, c, loc);
  if (t->is_string()) {
    if (c.k != ConstV::K::Str) {
      diags_.error("ST203", loc, "a string is required for " + t->name);
      return false;
    }
    if (t->kind == TypeKind::WString) {  // source text is UTF-8, a WSTRING UTF-16
      store_wstring(dst, t->str_len, utf8_to_utf16(c.s));
      return true;
    }
    size_t n = std::min<size_t>(c.s.size(), t->str_len);
    std::memcpy(dst, c.s.data(), n);
    dst[n] = 0;
    return true;
  }
  if (t->kind == TypeKind::Bool) {
    if (c.k == ConstV::K::Bool || (c.k == ConstV::K::Int && (c.i == 0 || c.i == 1))) {
      dst[0] = c.i ? 1 : 0;
      return true;
    }
    diags_.error("ST203", loc, "a BOOL value is required");
    return false;
  }
  if (t->is_real()) {
    double v = c.k == ConstV::K::Real ? c.r : static_cast<double>(c.i);
    if (c.k != ConstV::K::Real && c.k != ConstV::K::Int) {
      diags_.error("ST203", loc, "a number is required for " + t->name);
      return false;
    }
    if (t->kind == TypeKind::Real) put<float>(dst, static_cast<float>(v));
    else put<double>(dst, v);
    return true;
  }
  if (t->kind == TypeKind::Ref || t->kind == TypeKind::Interface) {
    put<uint32_t>(dst, 0);
    return true;
  }
  if (c.k != ConstV::K::Int && !(c.k == ConstV::K::Bool && t->is_anybit())) {
    diags_.error("ST203", loc, std::string("a ") + (t->is_time_like() ? "duration/date" : "integer") + " constant is required for " + t->name);
    return false;
  }
  int64_t v = c.i;
  switch (t->storage()) {
    case Storage::I8: if (v < INT8_MIN || v > INT8_MAX) return range_error(std::to_string(v)); put<int8_t>(dst, static_cast<int8_t>(v)); break;
    case Storage::I16: if (v < INT16_MIN || v > INT16_MAX) return range_error(std::to_string(v)); put<int16_t>(dst, static_cast<int16_t>(v)); break;
    case Storage::I32: if (v < INT32_MIN || v > INT32_MAX) return range_error(std::to_string(v)); put<int32_t>(dst, static_cast<int32_t>(v)); break;
    case Storage::I64: put<int64_t>(dst, v); break;
    case Storage::U8: if (v < 0 || v > UINT8_MAX) return range_error(std::to_string(v)); put<uint8_t>(dst, static_cast<uint8_t>(v)); break;
    case Storage::U16: if (v < 0 || v > UINT16_MAX) return range_error(std::to_string(v)); put<uint16_t>(dst, static_cast<uint16_t>(v)); break;
    case Storage::U32: if (v < 0 || v > UINT32_MAX) return range_error(std::to_string(v)); put<uint32_t>(dst, static_cast<uint32_t>(v)); break;
    case Storage::U64: put<uint64_t>(dst, static_cast<uint64_t>(v)); break;
    default: return false;
  }
  if (t->ranged && (v < t->lo || v > t->hi))
    return range_error(std::to_string(v) + " (subrange " + std::to_string(t->lo) + ".." + std::to_string(t->hi) + ")");
  return true;
}

void Compiler::write_init(std::vector<uint8_t>& image, uint32_t offset, const Type* t, const Expr* init, uint32_t file) {
  if (!t || offset + t->size > image.size()) return;
  std::copy(t->init.begin(), t->init.end(), image.begin() + offset);
  if (!init) return;
  if (init->kind == ExprKind::ArrayInit) {
    if (t->kind != TypeKind::Array) {
      diags_.error("ST203", init->loc, "an array initializer needs an array, not " + t->name);
      return;
    }
    const auto& ai = static_cast<const ArrayInitExpr&>(*init);
    // Multi-dimensional arrays take a flat list (row-major) or nested lists per row.
    uint64_t count = t->size / (t->elem->size ? t->elem->size : 1);
    uint64_t idx = 0;
    for (const auto& item : ai.items) {
      int64_t rep = 1;
      if (item.repeat) {
        auto r = const_int(*item.repeat, file);
        if (!r) return;
        rep = *r;
      }
      for (int64_t k = 0; k < rep; ++k) {
        if (idx >= count) {
          diags_.error("ST209", init->loc, "too many initial values: " + t->name + " has " + std::to_string(count) + " elements");
          return;
        }
        uint32_t eo = offset + static_cast<uint32_t>(idx * t->elem->size);
        if (item.value && item.value->kind == ExprKind::ArrayInit && t->dims.size() > 1) {
          // Nested row: fill the row's elements.
          const auto& row = static_cast<const ArrayInitExpr&>(*item.value);
          uint64_t row_len = static_cast<uint64_t>(t->dims.back().hi - t->dims.back().lo + 1);
          uint64_t j = 0;
          for (const auto& ri : row.items) {
            int64_t rr = 1;
            if (ri.repeat) {
              auto r2 = const_int(*ri.repeat, file);
              if (!r2) return;
              rr = *r2;
            }
            for (int64_t q = 0; q < rr; ++q) {
              if (j >= row_len || idx + j >= count) {
                diags_.error("ST209", row.loc, "too many initial values in this row");
                return;
              }
              write_init(image, offset + static_cast<uint32_t>((idx + j) * t->elem->size), t->elem, ri.value.get(), file);
              ++j;
            }
          }
          idx += row_len;
          continue;
        }
        write_init(image, eo, t->elem, item.value.get(), file);
        ++idx;
      }
    }
    return;
  }
  if (init->kind == ExprKind::StructInit) {
    if (t->kind != TypeKind::Struct && t->kind != TypeKind::Pou) {
      diags_.error("ST203", init->loc, "a structure initializer needs a structure or FB instance, not " + t->name);
      return;
    }
    const auto& items = static_cast<const StructInitExpr&>(*init).items;
    if (t->is_union && !t->fields.empty() &&
        (items.size() > 1 || (items.size() == 1 && !iequals(items[0].field.text, t->fields[0].name)))) {
      diags_.error("ST209", init->loc, "a UNION initializer sets its first member only: (" + t->fields[0].name + " := ...)");
      return;
    }
    for (const auto& item : items) {
      const Field* f = t->field(item.field.text);
      if (!f) {
        diags_.error("ST207", item.field.loc, "'" + t->name + "' has no member '" + item.field.text + "'");
        continue;
      }
      write_init(image, offset + f->offset, f->type, item.value.get(), file);
    }
    return;
  }
  if (!t->is_elementary() && !t->is_string()) {
    diags_.error("ST203", init->loc, "cannot initialize " + t->name + " with a single value");
    return;
  }
  // Enumeration values by bare name resolve against the target enum first.
  if (t->kind == TypeKind::Enum && init->kind == ExprKind::Name) {
    const auto& n = static_cast<const NameExpr&>(*init);
    for (const auto& [vn, v] : t->enum_values)
      if (iequals(vn, n.name.text)) {
        write_const(image.data() + offset, t->base, ConstV{ConstV::K::Int, v, 0, {}}, init->loc);
        return;
      }
  }
  auto c = const_eval(*init, file);
  if (!c) return;
  write_const(image.data() + offset, t, *c, init->loc);
}

// ------------------------------------------------------------------ addresses

bool Compiler::locate(const DirectAddrExpr& a, const Type* t, uint32_t* addr, uint8_t* bit, bool* is_bit) {
  ImageArea* area = a.area == 'I' ? &app_->image_i : a.area == 'Q' ? &app_->image_q : a.area == 'M' ? &app_->image_m : nullptr;
  if (!area) {
    diags_.error("ST218", a.loc, "unknown address area in " + a.text);
    return false;
  }
  *is_bit = false;
  *bit = 0;
  uint32_t unit = 1;
  switch (a.size) {
    case 'X':
      if (a.parts.size() != 2 || a.parts[1] > 7) {
        diags_.error("ST218", a.loc, a.text + ": a bit address is byte.bit with bit 0..7");
        return false;
      }
      *is_bit = true;
      *bit = static_cast<uint8_t>(a.parts[1]);
      unit = 1;
      break;
    case 'B': unit = 1; break;
    case 'W': unit = 2; break;
    case 'D': unit = 4; break;
    case 'L': unit = 8; break;
    default:
      diags_.error("ST218", a.loc, "unknown size prefix in " + a.text);
      return false;
  }
  if (!*is_bit && a.parts.size() != 1) {
    diags_.error("ST218", a.loc, a.text + ": a byte/word address has a single number");
    return false;
  }
  uint64_t byte = static_cast<uint64_t>(a.parts.empty() ? 0 : a.parts[0]) * unit;
  if (byte + unit > area->size) {
    diags_.error("ST218", a.loc, a.text + " is outside the %" + std::string(1, a.area) + " image (" + std::to_string(area->size) + " bytes)");
    return false;
  }
  if (t) {
    if (*is_bit && t->kind != TypeKind::Bool) {
      diags_.error("ST218", a.loc, a.text + " is a bit address; it needs a BOOL variable, not " + t->name);
      return false;
    }
    if (!*is_bit && t->size != unit) {
      diags_.error("ST218", a.loc, a.text + " addresses " + std::to_string(unit * 8) + " bits; " + t->name + " has " + std::to_string(t->size * 8));
      return false;
    }
  }
  *addr = area->addr + static_cast<uint32_t>(byte);
  area->used = std::max<uint32_t>(area->used, static_cast<uint32_t>(byte + unit));
  return true;
}

// ------------------------------------------------------------------ variables

void Compiler::declare_globals(const std::vector<VarBlock>& blocks, const std::string& scope, uint32_t file) {
  for (const auto& blk : blocks) {
    for (const auto& d : blk.decls) {
      init_args_ok_ = !d.location || is_unmapped(*d.location);
      const Type* t = d.type ? resolve_type(*d.type, file) : nullptr;
      init_args_ok_ = false;
      if (!t) continue;
      for (const auto& n : d.names) {
        std::string key = canon(n.text);
        if (globals_.count(key)) {
          diags_.error("ST202", n.loc, "global variable '" + n.text + "' is declared twice");
          continue;
        }
        auto s = std::make_unique<Symbol>();
        s->name = n.text;
        s->type = t;
        s->section = VarSection::Global;
        s->constant = d.constant;
        s->retain = d.retain;
        s->loc = n.loc;
        sym_src(s.get()).decl = &d;
        if (d.location && !is_unmapped(*d.location)) {
          bool is_bit = false;
          if (!locate(*d.location, t, &s->offset, &s->bit, &is_bit)) continue;
          s->where = is_bit ? Where::AbsBit : Where::Abs;
          if (d.init) {
            auto c = const_eval(*d.init, file);
            if (c) {
              if (is_bit) {
                if (c->i) app_->init_image[s->offset] |= static_cast<uint8_t>(1u << s->bit);
              } else {
                write_const(app_->init_image.data() + s->offset, t, *c, d.init->loc);
              }
            }
          }
        } else {
          s->where = Where::Abs;
          s->offset = alloc(t->size, t->align);
          const bool at_run_time = runtime_init(s.get(), &d, file, true, nullptr);
          if (at_run_time) global_runtime_inits_.push_back(s.get());
          write_init(app_->init_image, s->offset, t, at_run_time ? nullptr : d.init.get(), file);
          if (d.retain) app_->retain_ranges.emplace_back(s->offset, t->size);
        }
        globals_[key] = s.get();
        app_->globals.push_back(GlobalVar{scope, s.get()});
        app_->global_syms.push_back(std::move(s));
      }
    }
  }
}

void Compiler::check_init_args(const TypeSpec& spec, const Type* t, bool allowed) {
  const SourceLoc at = spec.init_args.empty() ? spec.loc : spec.init_args.front().loc;
  if (!allowed) {
    diags_.error("ST243", at, "FB_init arguments can be given only to an instance declared in a PROGRAM's or "
                              "FUNCTION_BLOCK's VAR, VAR_INPUT or VAR_OUTPUT block or in a global variable list");
    return;
  }
  if (opt_.dialect == Dialect::Iec) {
    diags_.error("ST241", at, "FB_init arguments in a declaration are CODESYS, not IEC 61131-3: use --dialect codesys");
    return;
  }
  if (t->kind != TypeKind::Pou || !t->pou || t->pou->kind != PouKind::FunctionBlock) {
    diags_.error("ST243", at, "'" + spec.name.text + "' is not a function block: only an instance takes FB_init arguments");
    return;
  }
  for (const PouInfo* f = t->pou; f; f = f->base)
    for (const auto& m : f->methods)
      if (iequals(m->name, "FB_init") && m->has_body) return;
  // `fb : R_TRIG();`: an empty list asks for nothing beyond the implicit initialisation.
  if (spec.init_args.empty()) return;
  diags_.error("ST243", at, t->pou->name + " has no FB_init method to take these arguments");
}

std::string Compiler::inst_var_name(const PouInfo* method, const std::string& var) {
  return method->owner->name + "." + method->name + "." + var;
}

// Creates the symbols of a POU's variables and lays out its instance or frame.
void Compiler::declare_vars(PouInfo* p) {
  const PouInfo* saved_decl_pou = decl_pou_;
  decl_pou_ = p;
  uint32_t off = 8;
  if (p->kind == PouKind::Method) off = 12;  // [8..12): THIS
  if (p->base) off = align_up(p->base->frame_size, 8);
  // Names declared so far, canonical: a search of p->vars per declaration made a block of
  // 40,000 variables quadratic (6.6 s to check).
  std::unordered_set<std::string> declared;
  for (const auto& v : p->vars) declared.insert(canon(v->name));
  std::unordered_set<std::string> inherited;
  if (p->base && p->base->type)
    for (const auto& f : p->base->type->fields) inherited.insert(canon(f.name));
  const bool result_name_taken = (p->kind == PouKind::Function || p->kind == PouKind::Method) &&
                                 (p->is_setter || (p->result && p->result->kind != TypeKind::Void));
  auto add = [&](const VarDecl& d, const Ident& n, const Type* t) -> Symbol* {
    std::string key = canon(n.text);
    if (declared.count(key)) {
      diags_.error("ST202", n.loc, "'" + n.text + "' is declared twice in " + p->name);
      return nullptr;
    }
    if (inherited.count(key)) {
      diags_.error("ST202", n.loc, "'" + n.text + "' is already declared in the base FB " + p->base->name);
      return nullptr;
    }
    // Names are case-insensitive: `m0` in METHOD M0 would be its result variable.
    const std::string& result_name = p->property.empty() ? p->name : p->property;
    if (result_name_taken && iequals(n.text, result_name)) {
      diags_.error("ST202", n.loc, "'" + n.text + "' is declared twice in " + result_name + ": it is the result variable");
      return nullptr;
    }
    auto s = std::make_unique<Symbol>();
    s->name = n.text;
    s->type = t;
    s->section = d.section;
    s->constant = d.constant;
    s->retain = d.retain;
    s->loc = n.loc;
    sym_src(s.get()).decl = &d;
    Symbol* raw = s.get();
    p->vars.push_back(std::move(s));
    declared.insert(std::move(key));
    return raw;
  };
  auto place_var = [&](Symbol* s, uint32_t size, uint32_t align) {
    off = align_up(off, std::min<uint32_t>(align, 8));
    s->where = Where::Frame;
    s->offset = off;
    off += size;
  };
  // Parameters first (their order is the calling convention), then result, then the rest.
  static constexpr VarSection kOrder[] = {VarSection::Input, VarSection::InOut, VarSection::Output,
                                          VarSection::Var,   VarSection::Stat,  VarSection::Inst,
                                          VarSection::External, VarSection::Global, VarSection::Config,
                                          VarSection::Temp};
  // A method's VAR_INST lives in its owner's instance: the owner is laid out first.
  if (p->kind == PouKind::Method && p->owner) declare_pou(p->owner);
  bool is_callable = p->kind == PouKind::Function || p->kind == PouKind::Method;
  for (VarSection sec : kOrder) {
    if (is_callable && sec == VarSection::Output) {
      // Result slot between in-outs and outputs: the part from here on is (re)initialized per call.
      p->init_from = off;
      const Type* rt = p->result;
      if (rt && rt->kind != TypeKind::Void) {
        off = align_up(off, std::min<uint32_t>(rt->align, 8));
        p->result_offset = off;
        off += rt->size;
      }
    }
    if (!is_callable && sec == VarSection::Temp) p->init_from = off;
    const PropertyDecl* prop = src(p).property;
    if (sec == VarSection::Input && p->is_setter && prop) {
      // A property setter receives the new value under the property's name.
      const Type* t = prop->type ? resolve_type(*prop->type, p->file) : nullptr;
      if (t) {
        auto s = std::make_unique<Symbol>();
        s->name = prop->name.text;
        s->type = t;
        s->section = VarSection::Input;
        s->loc = prop->name.loc;
        sym_src(s.get()).reads = 1;
        place_var(s.get(), t->size, t->align);
        p->inputs.push_back(s.get());
        p->vars.push_back(std::move(s));
      }
    }
    for (const VarBlock* blkp : src(p).blocks) {
      const VarBlock& blk = *blkp;
      if (blk.section != sec) continue;
      for (const auto& d : blk.decls) {
        if (sec == VarSection::Global) {
          diags_.error("ST235", d.loc, "VAR_GLOBAL belongs in a CONFIGURATION, RESOURCE or a global variable list, not in " + p->name);
          continue;
        }
        if (sec == VarSection::Config) continue;
        if ((sec == VarSection::Stat || (sec == VarSection::Inst && p->kind == PouKind::Method)) &&
            opt_.dialect == Dialect::Iec &&
            &d == &blk.decls.front())  // once per block
          diags_.error("ST241", blk.loc, sec == VarSection::Stat
                                             ? "VAR_STAT is CODESYS, not IEC 61131-3: declare a VAR_GLOBAL, or use --dialect codesys"
                                             : "VAR_INST is CODESYS, not IEC 61131-3: declare the variable in the method's "
                                               "function block or program, or use --dialect codesys");
        if (sec == VarSection::Inst) {
          // Laid out by the owner (see below): here the method's name for that storage.
          if (p->kind != PouKind::Method || !p->owner) continue;  // the parser reported it
          for (const auto& n : d.names) {
            Symbol* kept = p->owner->find_var(inst_var_name(p, n.text));
            if (!kept) continue;  // its type did not resolve: reported with the owner
            Symbol* s = add(d, n, kept->type);
            if (!s) continue;
            s->where = Where::This;
            s->offset = kept->offset;
          }
          continue;
        }
        if (sec == VarSection::External) {
          for (const auto& n : d.names) {
            auto it = globals_.find(canon(n.text));
            if (it == globals_.end()) {
              diags_.error("ST228", n.loc, "VAR_EXTERNAL '" + n.text + "' has no matching VAR_GLOBAL");
              continue;
            }
            const Type* t = d.type ? resolve_type(*d.type, p->file) : nullptr;
            if (t && !same_type(t, it->second->type) && t != it->second->type) {
              diags_.error("ST228", n.loc, "VAR_EXTERNAL '" + n.text + "' is declared " + t->name + " but the global is " + it->second->type->name);
              continue;
            }
            Symbol* s = add(d, n, it->second->type);
            if (!s) continue;
            s->where = it->second->where;
            s->offset = it->second->offset;
            s->bit = it->second->bit;
            s->constant = d.constant || it->second->constant;
            SymbolSource& ss = sym_src(s);
            if (!ss.decl->init && decl_of(it->second)) ss.decl = decl_of(it->second);
          }
          continue;
        }
        // An instance of the POU being declared, by name: said once, here, before resolving
        // the type would report the same cycle again as a recursive use (ST214).
        if (d.type && d.type->kind == TypeSpecKind::Named && iequals(d.type->name.text, p->name) &&
            (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program)) {
          diags_.error("ST240", d.loc, p->name + " cannot contain an instance of itself");
          continue;
        }
        init_args_ok_ = (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program) &&
                        (sec == VarSection::Var || sec == VarSection::Input || sec == VarSection::Output);
        open_array_ok_ = sec == VarSection::InOut;
        const Type* t = d.type ? resolve_type(*d.type, p->file) : nullptr;
        init_args_ok_ = false;
        open_array_ok_ = false;
        if (!t) continue;
        if (t->kind == TypeKind::Pou && t->pou == p) {
          diags_.error("ST240", d.loc, p->name + " cannot contain an instance of itself");
          continue;
        }
        if (t->kind == TypeKind::Pou && is_callable && sec != VarSection::InOut) {
          // FB instances inside functions would lose their state: IEC forbids it.
          if (p->kind == PouKind::Function) {
            diags_.error("ST239", d.loc, "a FUNCTION cannot declare function block instances (they would not keep their state)");
            continue;
          }
        }
        for (const auto& n : d.names) {
          Symbol* s = add(d, n, t);
          if (!s) continue;
          if (d.location && !is_unmapped(*d.location)) {
            bool is_bit = false;
            if (!locate(*d.location, t, &s->offset, &s->bit, &is_bit)) continue;
            s->where = is_bit ? Where::AbsBit : Where::Abs;
            continue;
          }
          if (sec == VarSection::InOut) {
            place_var(s, inout_slot_size(t), 4);
            s->where = Where::InOut;
          } else if (sec == VarSection::Stat) {
            // One per POU, shared by every instance and call: laid out like a global.
            s->where = Where::Abs;
            s->offset = alloc(t->size, t->align);
            write_init(app_->init_image, s->offset, t, d.init.get(), p->file);
          } else {
            place_var(s, t->size, t->align);
          }
          if (sec == VarSection::Input) p->inputs.push_back(s);
          else if (sec == VarSection::Output) p->outputs.push_back(s);
          else if (sec == VarSection::InOut) p->inouts.push_back(s);
        }
      }
    }
  }
  // The VAR_INST of its methods: kept in this instance under a name no source can spell
  // (Owner.Method.x), so the body does not see them; each method reaches its own through THIS.
  if (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program)
    for (const auto& m : p->methods)
      for (const VarBlock* blkp : src(m.get()).blocks) {
        if (blkp->section != VarSection::Inst) continue;
        for (const auto& d : blkp->decls) {
          const Type* t = d.type ? resolve_type(*d.type, m->file) : nullptr;
          if (!t) continue;
          if (t->kind == TypeKind::Pou && t->pou == p) {
            diags_.error("ST240", d.loc, p->name + " cannot contain an instance of itself");
            continue;
          }
          for (const auto& n : d.names) {
            Symbol* s = add(d, Ident{inst_var_name(m.get(), n.text), n.loc}, t);
            if (!s) continue;
            sym_src(s).reads = 1;  // used by the method, through its own symbol
            place_var(s, t->size, t->align);
          }
        }
      }
  p->frame_size = align_up(off, 8);
  decl_pou_ = saved_decl_pou;
  order_positional(p);
  // A variable of an FB and one of its methods or properties spelt alike would each hide
  // the other in the bodies.
  for (const auto& m : p->methods) {
    const std::string& member = m->property.empty() ? m->name : m->property;
    for (const auto& v : p->vars)
      if (iequals(v->name, member))
        diags_.error("ST202", v->loc, "'" + v->name + "' is declared twice in " + p->name + ": as a variable and as a " +
                                          (m->property.empty() ? "method" : "property"));
  }
  // FB and PROGRAM types expose their variables as fields (paths, member access).
  if (p->type && p->kind != PouKind::Interface) {
    Type* t = p->type;
    if (p->base) t->fields = p->base->type->fields;
    for (const auto& s : p->vars)
      if (s->where == Where::Frame || s->where == Where::InOut)
        t->fields.push_back(Field{s->name, s->where == Where::InOut ? tt_->ref_to(s->type) : s->type, s->offset, s->loc});
    t->fields.shrink_to_fit();  // kept for the whole run: no growth slack
  }
}

void Compiler::ensure_layout(PouInfo* p, SourceLoc use) { ensure_compiled(p, use); }

void Compiler::ensure_compiled(PouInfo* p, SourceLoc use) {
  if (p->compiled) return;
  // POUs are compiled when first needed (an instance's size, a function's frame), which
  // recurses once per POU in a chain of instances inside instances.
  if (compiling_.size() >= kMaxPouDepth) {
    if (!pou_depth_reported_) {
      pou_depth_reported_ = true;
      diags_.error("ST117", use, "'" + p->name + "' is used more than " + std::to_string(kMaxPouDepth) +
                                     " levels deep (instances inside instances, or calls through calls)");
    }
    return;
  }
  if (std::find(compiling_.begin(), compiling_.end(), p) != compiling_.end()) {
    std::string chain;
    for (auto* c : compiling_) chain += c->name + " -> ";
    auto& d = diags_.error("ST214", use, "recursive use of '" + p->name + "' (" + chain + p->name +
                                             "); IEC 61131-3 forbids recursion and instances containing themselves");
    if (const Pou* pd = decl_of(p)) d.notes.emplace_back(pd->name.loc, "'" + p->name + "' is declared here");
    return;
  }
  compile_pou(p);
}

bool Compiler::derives(const Type* from, const Type* to) const {
  if (!from || !to || from->kind != TypeKind::Pou || to->kind != TypeKind::Pou || !to->pou) return false;
  for (const PouInfo* f = from->pou; f; f = f->base)
    if (f == to->pou) return true;
  return false;
}

bool Compiler::has_derived(const PouInfo* fb) const {
  if (!fb) return false;
  for (const auto& [name, p] : pous_)
    if (p->base == fb) return true;
  return false;
}

bool Compiler::implements(const PouInfo* fb, const PouInfo* itf) const {
  // Iterative over the interfaces' EXTENDS graph (cycles were cut when linking).
  std::vector<const PouInfo*> todo;
  for (const PouInfo* f = fb; f; f = f->base) todo.insert(todo.end(), f->interfaces.begin(), f->interfaces.end());
  std::vector<const PouInfo*> seen;
  while (!todo.empty()) {
    const PouInfo* i = todo.back();
    todo.pop_back();
    if (i == itf) return true;
    if (std::find(seen.begin(), seen.end(), i) != seen.end()) continue;
    seen.push_back(i);
    todo.insert(todo.end(), i->interfaces.begin(), i->interfaces.end());
  }
  return fb == itf;
}

// The parameters in the order they are written: sections are laid out input, in-out,
// output whatever their order in the source, but a non-formal call follows the source.
void Compiler::order_positional(PouInfo* p) {
  p->positional.clear();
  std::vector<Symbol*> params = p->inputs;
  params.insert(params.end(), p->inouts.begin(), p->inouts.end());
  params.insert(params.end(), p->outputs.begin(), p->outputs.end());
  // A property setter's value has no declaration of its own: it is the only parameter.
  for (Symbol* s : params)
    if (!sym_src(s).decl) p->positional.push_back(s);
  for (const VarBlock* blk : src(p).blocks) {
    if (blk->section != VarSection::Input && blk->section != VarSection::InOut && blk->section != VarSection::Output) continue;
    for (const auto& d : blk->decls)
      for (Symbol* s : params)
        if (sym_src(s).decl == &d) p->positional.push_back(s);
  }
}


// The order a non-formal call binds in: an FB's inherited parameters first, base FB first.
std::vector<Symbol*> Compiler::positional_params(const PouInfo* p) const {
  std::vector<Symbol*> out;
  for (const PouInfo* f = p; f; f = f->kind == PouKind::Method ? nullptr : f->base)
    out.insert(out.begin(), f->positional.begin(), f->positional.end());
  return out;
}

}  // namespace plcfi::st::detail
