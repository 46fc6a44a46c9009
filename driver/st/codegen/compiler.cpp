// Compiler driver: indexing order, POU bodies, code emission, frame finalization,
// configuration (tasks and program instances), test fixtures and the final link.
#include <algorithm>
#include <set>
#include <cstring>
#include <filesystem>
#include <functional>
#include <type_traits>

#include <fmt/format.h>

#include "compiler_impl.hpp"
#include "vm/memory.hpp"
#include "syntax/parser.hpp"

namespace plcfi::st {

// ------------------------------------------------------------------ Application

SourceLoc Application::loc_of(uint32_t pc) const {
  auto it = std::upper_bound(lines.begin(), lines.end(), pc,
                             [](uint32_t v, const std::pair<uint32_t, SourceLoc>& e) { return v < e.first; });
  if (it == lines.begin()) return {};
  return std::prev(it)->second;
}

int32_t Application::index_shift(uint32_t pc) const {
  auto it = std::lower_bound(index_shifts.begin(), index_shifts.end(), pc,
                             [](const std::pair<uint32_t, int32_t>& e, uint32_t v) { return e.first < v; });
  return it != index_shifts.end() && it->first == pc ? it->second : 0;
}

std::string Application::index_message(uint32_t pc, int64_t v, int32_t lo, uint32_t count) const {
  const int64_t k = index_shift(pc);
  // The index as the source computes it: v + K in DINT arithmetic (wrapping).
  const int64_t index = k == 0 ? v : static_cast<int32_t>(static_cast<uint32_t>(static_cast<int32_t>(v)) + static_cast<uint32_t>(k));
  return fmt::format("index {} outside {}..{}", index, int64_t{lo} + k, int64_t{lo} + k + count - 1);
}

std::string Application::where(SourceLoc loc) const {
  std::string f = loc.file < file_paths.size() ? file_paths[loc.file] : "<input>";
  if (!loc.valid()) return f;
  return f + ":" + std::to_string(loc.line) + ":" + std::to_string(loc.col);
}

PouInfo* Application::find_pou(std::string_view name) const {
  for (const auto& p : pous)
    if (iequals(p->name, name)) return p.get();
  return nullptr;
}

const ImageArea* Application::image(char area) const {
  switch (area) {
    case 'I': case 'i': return &image_i;
    case 'Q': case 'q': return &image_q;
    case 'M': case 'm': return &image_m;
    default: return nullptr;
  }
}

Symbol* PouInfo::find_var(std::string_view n) const {
  for (const auto& v : vars)
    if (iequals(v->name, n)) return v.get();
  return base ? base->find_var(n) : nullptr;
}

PouInfo* PouInfo::find_method(std::string_view n) const {
  for (const auto& m : methods)
    if (iequals(m->name, n)) return m.get();
  if (base) return base->find_method(n);
  for (auto* i : interfaces)
    if (PouInfo* m = i->find_method(n)) return m;
  return nullptr;
}

namespace detail {

uint32_t storage_index(Storage s) { return static_cast<uint32_t>(s); }

Op num_op(Op i8_variant, Storage s) {
  constexpr uint32_t stride = static_cast<uint32_t>(Op::ADD_I16) - static_cast<uint32_t>(Op::ADD_I8);
  return static_cast<Op>(static_cast<uint32_t>(i8_variant) + storage_index(s) * stride);
}

Op int_op(Op i8_variant, Storage s) {
  constexpr uint32_t stride = static_cast<uint32_t>(Op::MOD_I16) - static_cast<uint32_t>(Op::MOD_I8);
  return static_cast<Op>(static_cast<uint32_t>(i8_variant) + storage_index(s) * stride);
}

Op cvt_op(Storage from, Storage to) {
  return static_cast<Op>(static_cast<uint32_t>(num_op(Op::CVT_I8_I8, from)) + storage_index(to));
}

Op mov_op(uint32_t size) {
  switch (size) {
    case 1: return Op::MOV1;
    case 2: return Op::MOV2;
    case 4: return Op::MOV4;
    case 8: return Op::MOV8;
    default: return Op::MOVN;
  }
}

Op sel_op(uint32_t size) {
  switch (size) {
    case 1: return Op::SEL1;
    case 2: return Op::SEL2;
    case 4: return Op::SEL4;
    default: return Op::SEL8;
  }
}

ValueKind value_kind(const Type* t) {
  switch (t->kind) {
    case TypeKind::Bool: return ValueKind::Bool;
    case TypeKind::LTime: return t->unsigned_count ? ValueKind::UTime : ValueKind::Time;
    case TypeKind::Time: return ValueKind::Time;
    case TypeKind::Date: return ValueKind::Date;
    case TypeKind::TimeOfDay: return ValueKind::Tod;
    case TypeKind::DateTime: return ValueKind::Dt;
    case TypeKind::String: return ValueKind::String;
    case TypeKind::WString: return ValueKind::WString;
    case TypeKind::Ref: case TypeKind::Interface: return ValueKind::Ref;
    default: break;
  }
  switch (t->storage()) {
    case Storage::I8: return ValueKind::I8;
    case Storage::I16: return ValueKind::I16;
    case Storage::I32: return ValueKind::I32;
    case Storage::I64: return ValueKind::I64;
    case Storage::U8: return ValueKind::U8;
    case Storage::U16: return ValueKind::U16;
    case Storage::U32: return ValueKind::U32;
    case Storage::U64: return ValueKind::U64;
    case Storage::F32: return ValueKind::F32;
    case Storage::F64: return ValueKind::F64;
    default: return ValueKind::U8;
  }
}

namespace {
template <class T>
void put(uint8_t* p, T v) {
  store_as<T>(p, v);
}
}  // namespace

Compiler::Compiler(const SourceManager& sm, DiagEngine& diags, const CompileOptions& opt)
    : sm_(sm), diags_(diags), opt_(opt) {}

// ------------------------------------------------------------------ emission

// A finished body's code, lines and layout tables were copied into the application by
// finish_body, and its lookup tables only serve the compilation of its own statements:
// all of it is freed, so a large application never holds every POU's tables at once.
// The symbols it made (methods' This-symbols) live on, because PouInfo and the
// diagnostics point to them.
static void drop_finished_tables(Body& b) {
  auto drop = [](auto& v) { std::remove_reference_t<decltype(v)>().swap(v); };
  drop(b.code);
  drop(b.lines);
  drop(b.index_shifts);
  drop(b.label_pos);
  drop(b.label_refs);
  drop(b.target_fix);
  drop(b.slot_fix);
  drop(b.entry_fix);
  drop(b.template_fix);
  drop(b.consts);
  drop(b.const_index);
  drop(b.cvt_cache);
  drop(b.locals);
  drop(b.goto_labels);
  drop(b.loops);
}

void Compiler::emit(Op op, std::initializer_list<Arg> args) { emit_list(op, std::vector<Arg>(args)); }

void Compiler::def(Slot dst, uint32_t operand) {
  b_->last_def = dst;
  b_->last_def_operand = operand;
  // The instruction just emitted starts at code.size() - 1 - operands.
  b_->last_def_pos = b_->last_instr;
}

bool Compiler::retarget(Slot from, Slot to) {
  if (b_->last_def_pos != b_->last_instr || b_->last_label_pos > b_->last_instr) return false;
  if (b_->last_def.off != from.off || b_->last_def.kind != from.kind || from.kind != SK::Temp) return false;
  uint32_t word = b_->last_def_pos + b_->last_def_operand;
  auto it = std::find_if(b_->slot_fix.begin(), b_->slot_fix.end(), [&](const auto& e) { return e.first == word; });
  if (it != b_->slot_fix.end()) b_->slot_fix.erase(it);
  b_->code[word] = to.off;
  for (auto& w : b_->flag_watches)
    if (to.kind == SK::Var && to.off == w.off) w.dirty = w.ever = true;
  if (to.kind != SK::Var) b_->slot_fix.emplace_back(word, to.kind);
  b_->last_def_pos = UINT32_MAX;
  return true;
}

void Compiler::emit_list(Op op, const std::vector<Arg>& args) {
  auto& code = b_->code;
  // A call may change any variable: cached conversions are stale after it; so are they
  // after a store into a variable (the cache holds conversions of variables).
  if (op == Op::CALL || op == Op::CALLA || op == Op::CALLP || op == Op::CALLS || op == Op::CALLV || op == Op::NATIVE)
    b_->cvt_cache.clear();
  if (!b_->flag_watches.empty()) watch_writes(op, args);
  b_->prev2_instr = b_->prev_instr < code.size() && b_->last_instr < code.size() ? b_->prev_instr : UINT32_MAX;
  b_->prev_instr = b_->last_instr < code.size() ? b_->last_instr : UINT32_MAX;
  b_->last_instr = static_cast<uint32_t>(code.size());
  code.push_back(static_cast<uint32_t>(op));
  for (const Arg& a : args) {
    switch (a.k) {
      case Arg::K::Imm: break;
      case Arg::K::Slot:
        if (a.sk != SK::Var) b_->slot_fix.emplace_back(static_cast<uint32_t>(code.size()), a.sk);
        break;
      case Arg::K::Target:
        b_->target_fix.emplace_back(static_cast<uint32_t>(code.size()), a.v);
        if (a.v < b_->label_refs.size()) ++b_->label_refs[a.v];
        break;
      case Arg::K::Entry: b_->entry_fix.push_back({static_cast<uint32_t>(code.size()), a.pou, static_cast<EntryKind>(a.v)}); break;
    }
    code.push_back(a.k == Arg::K::Slot || a.k == Arg::K::Imm ? a.v : 0);
  }
}

Label Compiler::new_label() {
  b_->label_pos.push_back(UINT32_MAX);
  b_->label_refs.push_back(0);
  return Label{static_cast<uint32_t>(b_->label_pos.size() - 1)};
}

void Compiler::bind(Label l) {
  b_->label_pos[l.id] = static_cast<uint32_t>(b_->code.size());
  b_->last_label_pos = static_cast<uint32_t>(b_->code.size());
}

void Compiler::bind_forward(Label l) {
  if (b_->label_refs[l.id] != 0) bind(l);
  else b_->label_pos[l.id] = static_cast<uint32_t>(b_->code.size());
}

void Compiler::mark(SourceLoc loc) {
  if (!loc.valid() || !b_) return;
  auto& lines = b_->lines;
  uint32_t pc = static_cast<uint32_t>(b_->code.size());
  if (!lines.empty() && lines.back().first == pc) {
    lines.back().second = loc;
    return;
  }
  lines.emplace_back(pc, loc);
}

Slot Compiler::temp(uint32_t size, uint32_t align) {
  uint32_t off = align_up(b_->temp_top, align);
  b_->temp_top = off + size;
  b_->temp_max = std::max(b_->temp_max, b_->temp_top);
  return Slot{off, SK::Temp};
}

Slot Compiler::konst_bytes(const void* data, uint32_t size, uint32_t align) {
  std::string key(static_cast<const char*>(data), size);
  auto it = b_->const_index.find({key, align});
  if (it != b_->const_index.end()) return Slot{it->second, SK::Const};
  uint32_t off = align_up(static_cast<uint32_t>(b_->consts.size()), std::min<uint32_t>(align, 8));
  b_->consts.resize(off + size, 0);
  std::memcpy(b_->consts.data() + off, data, size);
  b_->const_index[{key, align}] = off;
  return Slot{off, SK::Const};
}

Slot Compiler::konst(const Type* t, const ConstV& c, SourceLoc loc) {
  std::vector<uint8_t> buf(t->size ? t->size : 1, 0);
  write_const(buf.data(), t, c, loc);
  return konst_bytes(buf.data(), static_cast<uint32_t>(buf.size()), t->align);
}

Slot Compiler::konst_i64(int64_t v) { return konst_bytes(&v, 8, 8); }

Slot Compiler::hidden(uint32_t size, uint32_t align) {
  uint32_t off = align_up(b_->hidden_size, std::min<uint32_t>(align, 8));
  b_->hidden_size = off + size;
  return Slot{off, SK::Hidden};
}
Slot Compiler::konst_u32(uint32_t v) { return konst_bytes(&v, 4, 4); }

// ------------------------------------------------------------------ POU bodies

void Compiler::compile_pou(PouInfo* p) {
  if (p->compiled) return;
  compiling_.push_back(p);
  Body* saved_b = b_;
  uint32_t saved_file = file_;
  b_ = nullptr;
  file_ = p->file;
  const Pou* decl = decl_of(p);

  declare_pou(p);
  if (p->kind == PouKind::Interface || (p->kind == PouKind::Method && !p->has_body) ||
      (p->kind == PouKind::Method && p->owner && p->owner->kind == PouKind::Interface)) {
    p->compiled = true;
    compiling_.pop_back();
    b_ = saved_b;
    file_ = saved_file;
    return;
  }
  if (p->kind == PouKind::Method && p->owner) ensure_compiled(p->owner, decl ? decl->loc : SourceLoc{});

  auto body = std::make_unique<Body>();
  b_ = body.get();
  b_->pou = p;
  b_->file = p->file;
  b_->vars_end = p->frame_size;
  b_->temp_top = 0;
  for (const auto& v : p->vars) b_->locals[canon(v->name)] = v.get();
  if (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program) {
    b_->this_type = p->type;
    for (PouInfo* base = p->base; base; base = base->base)
      for (const auto& v : base->vars)
        if (!b_->locals.count(canon(v->name))) b_->locals[canon(v->name)] = v.get();
  }
  if (p->kind == PouKind::Method && p->owner && p->owner->type) {
    b_->is_method = true;
    b_->this_type = p->owner->type;
    for (PouInfo* o = p->owner; o; o = o->base)
      for (const auto& v : o->vars) {
        std::string key = canon(v->name);
        if (b_->locals.count(key)) continue;
        auto s = std::make_unique<Symbol>(*v);
        s->where = v->where == Where::Frame ? Where::This : v->where;
        if (v->where == Where::InOut) {
          // In-out of the owner seen from a method: a pointer in the instance.
          s->where = Where::This;
          s->type = tt_->ref_to(v->type);
        }
        b_->locals[key] = s.get();
        b_->owned.push_back(std::move(s));
      }
  }

  std::vector<uint32_t> entries;
  // Prologue.
  mark(decl ? decl->loc : SourceLoc{});
  if (p->kind == PouKind::Method) {
    emit(Op::ENTER, {0u});
    b_->template_fix.push_back(static_cast<uint32_t>(b_->code.size() - 1) | 0x80000000u);  // frame size
  }
  if (opt_.test_mode && (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program))
    emit(Op::FBENTER, {});
  if (opt_.test_mode && p->kind == PouKind::Function && !p->is_stdlib) {
    uint32_t rsize = p->result ? p->result->size : 0;
    p->mock_addr = alloc(8 + rsize, 8);
    emit(Op::FNMOCK, {p->mock_addr, p->result_offset, rsize});
  }
  bool has_temp_vars = std::any_of(p->vars.begin(), p->vars.end(), [](const auto& v) { return v->section == VarSection::Temp; });
  bool has_tmpl = p->kind == PouKind::Method || ((p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program) && has_temp_vars);
  if (has_tmpl) {
    emit(Op::INITBLK, {p->init_from, 0u, 0u});
    b_->template_fix.push_back(static_cast<uint32_t>(b_->code.size() - 2));
    b_->template_fix.push_back(static_cast<uint32_t>(b_->code.size() - 1) | 0x40000000u);  // length
  }
  entries.push_back(0);
  // Monitors: the first evaluation of a new state (input __state differs from the last
  // one seen) first shifts the temporal operators' values (previous := current); later
  // evaluations of the same state (one per timer point) see the same previous values.
  const Symbol* state_in = is_late(p) && p->kind == PouKind::Program ? lookup("__STATE") : nullptr;
  Label shift = new_label(), body_start = new_label();
  Slot seen;
  if (state_in) {
    seen = hidden(8, 8);
    b_->state_seen = seen;
    emit(Op::JNE_I64, {Arg::target(shift.id), Slot{state_in->offset, SK::Var}, seen});
    bind(body_start);
  }
  if (p->kind == PouKind::Function || p->kind == PouKind::Method) emit_runtime_inits(runtime_inits(p));
  if (decl) stmts(decl->body);
  mark(decl ? decl->end_loc : SourceLoc{});
  emit(Op::RET, {});
  if (state_in) {
    bind(shift);
    if (!b_->edges.empty()) {
      // The first state has no previous one: the operators stay FALSE until a shift
      // from a state that was evaluated.
      Label skip = new_label();
      Slot zero = konst_i64(0);
      if (!b_->started) b_->started = hidden(1, 1);
      emit(Op::JLT_I64, {Arg::target(skip.id), seen, zero});
      emit(Op::MOV1, {*b_->started, konst(elem(TypeKind::Bool), ConstV{ConstV::K::Bool, 1, 0, {}}, p->loc)});
      bind(skip);
      for (const auto& e : b_->edges) {
        if (e.size == 1 || e.size == 2 || e.size == 4 || e.size == 8) emit(mov_op(e.size), {e.prev, e.cur});
        else emit(Op::MOVN, {e.prev, e.cur, e.size});
      }
    }
    emit(Op::MOV8, {seen, Slot{state_in->offset, SK::Var}});
    emit(Op::JMP, {Arg::target(body_start.id)});
  }
  size_t init_at = 0, exit_at = 0;
  if (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program) lifecycle_entries(p, &entries, &init_at, &exit_at);
  finish_body(*body, p, &entries);
  p->entry = entries[0];
  if (init_at) p->init_entry = entries[init_at];
  if (exit_at) p->exit_entry = entries[exit_at];
  p->has_init = init_at != 0;
  p->has_exit = exit_at != 0;
  p->compiled = true;
  compiling_.pop_back();

  // Warnings: variables never used (not parameters, not stdlib).
  if (opt_.warnings && !p->is_stdlib) {
    for (const auto& v : p->vars) {
      const SymbolSource& vs = sym_src(v.get());
      if (vs.reads || vs.writes) continue;
      if (v->section != VarSection::Var && v->section != VarSection::Temp) continue;
      if (v->where == Where::Abs || v->where == Where::AbsBit) continue;  // I/O mapping
      if (p->kind == PouKind::Program || p->kind == PouKind::FunctionBlock) {
        // Instance variables are observable through paths and by test files; only
        // temporaries are certainly dead.
        if (v->section != VarSection::Temp) continue;
      }
      diags_.warning("ST400", v->loc, "variable '" + v->name + "' is declared but never used");
    }
  }
  drop_finished_tables(*body);
  bodies_.push_back(std::move(body));
  b_ = saved_b;
  file_ = saved_file;
}

// Lays out constants and temporaries, patches operands and appends the body to the code.
void Compiler::finish_body(Body& b, PouInfo* p, std::vector<uint32_t>* entries) {
  uint32_t hidden_base = align_up(b.vars_end, 8);
  uint32_t const_base = align_up(hidden_base + b.hidden_size, 8);
  uint32_t temp_base = align_up(const_base + static_cast<uint32_t>(b.consts.size()), 8);
  uint32_t frame_size = align_up(temp_base + b.temp_max, 8);
  for (auto [idx, kind] : b.slot_fix) b.code[idx] += kind == SK::Const ? const_base : kind == SK::Hidden ? hidden_base : temp_base;
  p->frame_size = frame_size;
  p->const_from = const_base;
  p->consts = b.consts;
  // Monitors: where the state shift works, so a caller can do it natively (StateShift).
  if (is_late(p) && p->kind == PouKind::Program && b.state_seen) {
    auto at = [&](Slot sl) { return sl.off + (sl.kind == SK::Hidden ? hidden_base : 0); };
    p->shift.present = true;
    p->shift.seen = at(*b.state_seen);
    p->shift.started = b.started ? static_cast<int32_t>(at(*b.started)) : -1;
    for (const auto& e : b.edges) p->shift.moves.push_back({at(e.cur), at(e.prev), e.size});
  }

  // The frame's initial image: header, variables' initial values, constants.
  std::vector<uint8_t> image(frame_size, 0);
  // Monitors: the last state seen starts at -1 (no state evaluated yet).
  if (is_late(p) && p->kind == PouKind::Program && b.hidden_size >= 8) {
    int64_t minus_one = -1;
    std::memcpy(image.data() + hidden_base, &minus_one, 8);
  }
  if (p->base && p->base->type) std::copy(p->base->type->init.begin(), p->base->type->init.end(), image.begin());
  if (p->type_id) put<uint16_t>(image.data(), static_cast<uint16_t>(p->type_id));
  for (const auto& v : p->vars) {
    const VarDecl* vd = decl_of(v.get());
    const bool at_run_time = std::find(runtime_inits(p).begin(), runtime_inits(p).end(), v.get()) != runtime_inits(p).end();
    if (v->where == Where::Frame) write_init(image, v->offset, v->type, vd && !at_run_time ? vd->init.get() : nullptr, p->file);
  }
  std::copy(b.consts.begin(), b.consts.end(), image.begin() + const_base);

  if (p->kind == PouKind::FunctionBlock || p->kind == PouKind::Program) {
    p->type->size = frame_size;
    p->type->align = 8;
    p->type->init = image;
    bool has_temp_vars = std::any_of(p->vars.begin(), p->vars.end(), [](const auto& v) { return v->section == VarSection::Temp; });
    p->tmpl_from = p->init_from;
    p->tmpl_to = has_temp_vars ? b.vars_end : p->init_from;
  } else if (p->kind == PouKind::Function) {
    p->tmpl_from = 0;
    p->tmpl_to = temp_base;
  } else {
    p->tmpl_from = p->init_from;
    p->tmpl_to = temp_base;
  }
  p->init_to = temp_base;
  if (p->tmpl_to > p->tmpl_from) {
    p->template_addr = alloc(p->tmpl_to - p->tmpl_from, 8);
    std::copy(image.begin() + p->tmpl_from, image.begin() + p->tmpl_to,
              app_->init_image.begin() + p->template_addr);
  }
  for (uint32_t f : b.template_fix) {
    if (f & 0x80000000u) b.code[f & 0x3fffffffu] = frame_size;
    else if (f & 0x40000000u) b.code[f & 0x3fffffffu] = p->tmpl_to - p->tmpl_from;
    else b.code[f] = p->template_addr;
  }

  uint32_t base = static_cast<uint32_t>(app_->code.size());
  for (auto [idx, label] : b.target_fix) {
    // Jump threading: a jump to an unconditional jump goes straight to its target.
    uint32_t target = b.label_pos[label];
    for (int hops = 0; hops < 8 && target < b.code.size() && b.code[target] == static_cast<uint32_t>(Op::JMP); ++hops) {
      auto it = std::find_if(b.target_fix.begin(), b.target_fix.end(), [&](const auto& f) { return f.first == target + 1; });
      if (it == b.target_fix.end()) break;
      target = b.label_pos[it->second];
    }
    b.code[idx] = base + target;
  }
  for (EntryFix f : b.entry_fix) entry_fix_.push_back({base + f.at, f.pou, f.kind});
  for (auto [pc, loc] : b.lines) app_->lines.emplace_back(base + pc, loc);
  for (auto [pc, k] : b.index_shifts) app_->index_shifts.emplace_back(base + pc, k);
  app_->code.insert(app_->code.end(), b.code.begin(), b.code.end());
  p->code_begin = base;
  p->code_end = static_cast<uint32_t>(app_->code.size());
  if (entries)
    for (auto& e : *entries) e += base;
}

// One TEST becomes a PROGRAM-like POU whose variables are SETUP's and the test's own;
// its three bodies (setup, test, teardown) share that frame.
void Compiler::compile_test(const TestFile& tf, const TestCase& tc) {
  auto pi = std::make_unique<PouInfo>();
  PouInfo* p = pi.get();
  p->kind = PouKind::Program;
  p->name = "TEST '" + tc.name + "'";
  p->file = tf.file;
  p->type = tt_->make(TypeKind::Pou, p->name);
  p->type->pou = p;
  p->type_id = next_type_id_++;
  p->loc = tc.loc;
  p->is_test = true;
  PouSource& ps = src(p);
  if (tf.setup)
    for (const auto& blk : tf.setup->var_blocks) ps.blocks.push_back(&blk);
  for (const auto& blk : tc.var_blocks) ps.blocks.push_back(&blk);
  ps.declared = true;
  Body* saved_b = b_;
  b_ = nullptr;
  file_ = tf.file;
  declare_vars(p);

  auto body = std::make_unique<Body>();
  b_ = body.get();
  b_->pou = p;
  b_->file = tf.file;
  b_->vars_end = p->frame_size;
  b_->this_type = p->type;
  b_->in_test = true;
  for (const auto& v : p->vars) b_->locals[canon(v->name)] = v.get();
  std::vector<uint32_t> entries;
  const StmtList* parts[3] = {tf.setup ? &tf.setup->body : nullptr, &tc.body, tf.teardown ? &tf.teardown->body : nullptr};
  for (const StmtList* part : parts) {
    entries.push_back(static_cast<uint32_t>(b_->code.size()));
    if (part) stmts(*part);
    emit(Op::RET, {});
  }
  size_t init_at = 0, exit_at = 0;
  lifecycle_entries(p, &entries, &init_at, &exit_at);
  finish_body(*body, p, &entries);
  if (init_at) p->init_entry = entries[init_at];
  if (exit_at) p->exit_entry = entries[exit_at];
  p->has_init = init_at != 0;
  p->has_exit = exit_at != 0;
  p->compiled = true;
  drop_finished_tables(*body);
  bodies_.push_back(std::move(body));
  b_ = saved_b;

  TestEntry te;
  te.name = tc.name;
  te.loc = tc.loc;
  te.instance_addr = alloc(p->frame_size, 8);
  std::copy(p->type->init.begin(), p->type->init.end(), app_->init_image.begin() + te.instance_addr);
  te.setup_entry = entries[0];
  te.body_entry = entries[1];
  te.teardown_entry = entries[2];
  te.has_setup = tf.setup.has_value();
  te.has_teardown = tf.teardown.has_value();
  te.has_init = p->has_init;
  te.has_exit = p->has_exit;
  te.init_entry = p->init_entry;
  te.exit_entry = p->exit_entry;
  app_->tests.push_back(te);
  app_->pous.push_back(std::move(pi));
}

// ------------------------------------------------------------------ the whole run

// ------------------------------------------------------------------ the whole run

// A new, empty program: the type table, the null reference, the I/O image areas.
void Compiler::start_program() {
  owned_ = std::make_unique<Application>();
  app_ = owned_.get();
  app_->types = std::make_unique<TypeTable>();
  tt_ = app_->types.get();
  if (opt_.dialect == Dialect::Codesys) tt_->make_ltime_unsigned();
  null_type_ = tt_->null_ref();
  for (size_t i = 0; i < sm_.size(); ++i) add_file_path(*app_, static_cast<uint32_t>(i));
  alloc(16, 16);  // address 0 stays invalid: it is the null reference
  app_->image_i = {'I', alloc(opt_.image_size_i, 8), opt_.image_size_i, 0};
  app_->image_q = {'Q', alloc(opt_.image_size_q, 8), opt_.image_size_q, 0};
  app_->image_m = {'M', alloc(opt_.image_size_m, 8), opt_.image_size_m, 0};
}

// A program compiled before, to link more units onto: its names are found again from
// its own symbol table (POUs, globals, declared types, method selectors), not from the
// syntax tree it came from.
void Compiler::start_from(Application& app) {
  app_ = &app;
  tt_ = app.types.get();
  null_type_ = tt_->null_ref();
  for (size_t i = app.file_paths.size(); i < sm_.size(); ++i) add_file_path(app, static_cast<uint32_t>(i));
  for (const auto& p : app.pous) {
    src(p.get()).declared = true;  // and compiled: nothing of it is redone
    if (p->is_test) continue;
    pous_[canon(p->name)] = p.get();
    for (const auto& m : p->methods) {
      src(m.get()).declared = true;
      selectors_[canon(m->name)] = m->selector;
      next_selector_ = std::max(next_selector_, m->selector + 1);
    }
  }
  for (const auto& g : app.global_syms) globals_[canon(g->name)] = g.get();
  for (const auto& [name, t] : app.type_names) {
    types_[canon(name)] = TypeEntry{nullptr, 0, t, false};
    if (t->kind == TypeKind::Enum)
      for (const auto& [v, n] : t->enum_values) enum_values_[canon(v)].push_back(t);
  }
  next_type_id_ = app.n_types;
}

// Declarations of the units whose POUs start at app_->pous[first_pou]: inheritance,
// global constants and variables, types.
void Compiler::declare_units(const std::vector<const CompilationUnit*>& all, size_t first_pou) {
  // Inheritance and interfaces.
  auto link = [&](PouInfo* p) {
    const Pou* d = decl_of(p);
    if (!d) return;
    if (d->extends) {
      auto it = pous_.find(canon(d->extends->text));
      if (it == pous_.end() || (p->kind == PouKind::FunctionBlock && it->second->kind != PouKind::FunctionBlock) ||
          (p->kind == PouKind::Interface && it->second->kind != PouKind::Interface)) {
        diags_.error("ST226", d->extends->loc, "'" + d->extends->text + "' is not " +
                                                   (p->kind == PouKind::Interface ? "an interface" : "a function block"));
      } else if (p->kind == PouKind::Interface) {
        p->interfaces.push_back(it->second);
      } else {
        p->base = it->second;
      }
    }
    for (const auto& i : d->implements) {
      auto it = pous_.find(canon(i.text));
      if (it == pous_.end() || it->second->kind != PouKind::Interface) {
        diags_.error("ST226", i.loc, "'" + i.text + "' is not an interface");
        continue;
      }
      p->interfaces.push_back(it->second);
    }
  };
  for (size_t i = first_pou; i < app_->pous.size(); ++i) link(app_->pous[i].get());
  // Inheritance cycles would make layouts infinite.
  for (size_t i = first_pou; i < app_->pous.size(); ++i) {
    const auto& p = app_->pous[i];
    size_t depth = 0;
    for (PouInfo* b = p->base; b; b = b->base)
      if (++depth > app_->pous.size()) {
        diags_.error("ST226", p->loc, "'" + p->name + "' inherits from itself");
        p->base = nullptr;
        break;
      }
  }

  // An interface extending itself (directly or through others) has its EXTENDS cut, so
  // that every later walk of the graph ends.
  for (size_t k = first_pou; k < app_->pous.size(); ++k) {
    const auto& p = app_->pous[k];
    if (p->kind != PouKind::Interface) continue;
    std::vector<const PouInfo*> todo(p->interfaces.begin(), p->interfaces.end()), seen;
    bool cycle = false;
    while (!todo.empty() && !cycle) {
      const PouInfo* i = todo.back();
      todo.pop_back();
      if (i == p.get()) cycle = true;
      if (std::find(seen.begin(), seen.end(), i) != seen.end()) continue;
      seen.push_back(i);
      todo.insert(todo.end(), i->interfaces.begin(), i->interfaces.end());
    }
    if (cycle) {
      const Pou& d = *decl_of(p.get());
      SourceLoc at = d.extends ? d.extends->loc : !d.implements.empty() ? d.implements[0].loc : d.name.loc;
      diags_.error("ST226", at, "interface '" + p->name + "' extends itself");
      p->interfaces.clear();
    }
  }

  // Global constants are known by name before any declaration needs them (array bounds),
  // also qualified by their list's name (`Params.MaxAxes`, as TwinCAT writes them).
  for (const auto* u : all) {
    const std::string list = canon(std::filesystem::path(sm_.file(u->file).path).stem().string());
    auto note = [&](const std::vector<VarBlock>& blocks, const std::string& scope) {
      for (const auto& blk : blocks)
        for (const auto& d : blk.decls)
          if (d.constant)
            for (const auto& n : d.names) {
              global_consts_[canon(n.text)] = {&d, u->file};
              global_consts_[scope + "." + canon(n.text)] = {&d, u->file};
            }
    };
    note(u->globals, list);
    for (const auto& c : u->configs) {
      note(c.globals, canon(c.name.text));
      for (const auto& r : c.resources) note(r.globals, canon(r.name.text));
    }
  }

  // Globals: global variable lists (scope: file stem), configurations and resources.
  for (const auto* u : all) {
    std::string stem = std::filesystem::path(sm_.file(u->file).path).stem().string();
    declare_globals(u->globals, stem, u->file);
    for (const auto& c : u->configs) {
      declare_globals(c.globals, c.name.text, u->file);
      for (const auto& r : c.resources) declare_globals(r.globals, r.name.text, u->file);
    }
  }

  // Every declared type is resolved (and so checked), used or not.
  for (auto& [key, te] : types_)
    if (!te.type) named_type(Ident{te.decl->name.text, te.decl->name.loc}, te.file);
}

void Compiler::check_interfaces(size_t first_pou) {
  // Interface conformance: every method of every implemented interface must exist.
  for (size_t i = first_pou; i < app_->pous.size(); ++i) {
    const auto& p = app_->pous[i];
    if (p->kind != PouKind::FunctionBlock || p->is_abstract) continue;
    std::vector<const PouInfo*> checked;
    std::function<void(const PouInfo*)> check = [&](const PouInfo* itf) {
      if (std::find(checked.begin(), checked.end(), itf) != checked.end()) return;
      checked.push_back(itf);
      for (const auto& m : itf->methods) {
        PouInfo* impl = nullptr;
        for (PouInfo* f = p.get(); f && !impl; f = f->base)
          for (const auto& fm : f->methods)
            if (iequals(fm->name, m->name) && fm->has_body) impl = fm.get();
        if (!impl) {
          std::string what = !m->property.empty() ? "property '" + m->property + "'" : "method '" + m->name + "'";
          diags_.error("ST225", decl_of(p.get())->name.loc, p->name + " does not implement " + what + " of interface " + itf->name);
        } else if (impl->inputs.size() != m->inputs.size() || !same_type(impl->result, m->result)) {
          diags_.error("ST225", decl_of(impl)->name.loc, "method " + p->name + "." + impl->name + " does not match the signature in interface " + itf->name);
        }
      }
      for (const auto* e : itf->interfaces) check(e);
    };
    for (const auto* itf : p->interfaces) check(itf);
  }

}

void Compiler::configure(const std::vector<const CompilationUnit*>& units) {
  // Configuration: tasks and program instances.
  for (const auto* u : units) {
    std::set<std::string> refused_tasks;  // canonical names of tasks already reported
    for (const auto& c : u->configs) {
      app_->has_configuration = true;
      for (const auto& r : c.resources) {
        for (const auto& t : r.tasks) {
          TaskInfo ti;
          ti.name = t.name.text;
          ti.loc = t.loc;
          // A task refused here is remembered, so the programs bound to it are not
          // reported again as bound to an unknown task.
          if (t.single) {
            diags_.error("ST235", t.single->loc, "event tasks (SINGLE) are not supported; use INTERVAL");
            if (!t.interval) {
              refused_tasks.insert(canon(t.name.text));
              continue;
            }
          }
          if (!t.interval) {
            diags_.error("ST227", t.loc, "task '" + t.name.text + "' needs an INTERVAL");
            refused_tasks.insert(canon(t.name.text));
            continue;
          }
          auto iv = const_eval(*t.interval, u->file);
          if (iv && iv->k == ConstV::K::Int) ti.interval_ns = iv->i;
          if (ti.interval_ns <= 0) {
            diags_.error("ST227", t.interval->loc, "task interval must be a positive duration");
            refused_tasks.insert(canon(t.name.text));
            continue;
          }
          if (t.priority) {
            auto pr = const_int(*t.priority, u->file);
            if (pr) ti.priority = *pr;
          }
          for (const auto& other : app_->tasks)
            if (iequals(other.name, ti.name)) diags_.error("ST202", t.name.loc, "task '" + ti.name + "' is declared twice");
          app_->tasks.push_back(ti);
        }
        for (const auto& pd : r.programs) {
          auto it = pous_.find(canon(pd.type.text));
          if (it == pous_.end() || it->second->kind != PouKind::Program) {
            diags_.error("ST227", pd.type.loc, "'" + pd.type.text + "' is not a PROGRAM");
            continue;
          }
          if (!pd.args.empty()) diags_.error("ST235", pd.loc, "program arguments in the configuration are not supported; use VAR_EXTERNAL or located variables");
          ProgramInstance pi;
          pi.name = pd.instance.text;
          pi.pou = it->second;
          for (const auto& other : app_->programs)
            if (iequals(other.name, pi.name)) diags_.error("ST202", pd.instance.loc, "program instance '" + pi.name + "' is declared twice");
          if (pd.task) {
            bool found = false;
            for (size_t k = 0; k < app_->tasks.size(); ++k)
              if (iequals(app_->tasks[k].name, pd.task->text)) {
                found = true;
                app_->tasks[k].programs.push_back(app_->programs.size());
                pi.task = app_->tasks[k].name;
              }
            if (!found) {
              if (!refused_tasks.count(canon(pd.task->text)))
                diags_.error("ST227", pd.task->loc, "unknown task '" + pd.task->text + "'");
              continue;
            }
          }
          app_->programs.push_back(pi);
        }
      }
    }
  }
}

// Entries of called POUs, the dispatch table, and the declared types by name (for units
// linked later).
void Compiler::finish_link() {
  for (EntryFix f : entry_fix_)
    app_->code[f.at] = f.kind == EntryKind::Init ? f.pou->init_entry : f.kind == EntryKind::Exit ? f.pou->exit_entry : f.pou->entry;
  app_->n_types = next_type_id_;
  app_->vtable.assign(static_cast<size_t>(next_selector_) * app_->n_types, 0);
  for (const auto& p : app_->pous) {
    if (!p->type_id) continue;
    for (const PouInfo* f = p.get(); f; f = f->base)
      for (const auto& m : f->methods) {
        if (!m->has_body || !m->compiled) continue;
        uint32_t& slot = app_->vtable[static_cast<size_t>(m->selector) * app_->n_types + p->type_id];
        if (slot == 0) slot = m->entry;  // the most derived implementation wins
      }
  }
  for (const auto& [key, te] : types_)
    if (te.decl && te.type) app_->type_names.emplace_back(te.decl->name.text, te.type);
}

std::unique_ptr<Application> Compiler::run(const std::vector<const CompilationUnit*>& units,
                                           const std::vector<const TestFile*>& tests) {
  start_program();
  std::vector<const CompilationUnit*> all = units;
  for (const auto* t : tests) all.push_back(&t->decls);
  for (const auto* u : all) index_unit(*u, u->file < sm_.size() && is_library_path(sm_.file(u->file).path));
  declare_units(all, 0);

  // Every POU is compiled (and so checked), used or not.
  for (size_t i = 0; i < app_->pous.size(); ++i) ensure_compiled(app_->pous[i].get(), app_->pous[i]->loc);
  for (size_t i = 0; i < all_methods_.size(); ++i) ensure_compiled(all_methods_[i], all_methods_[i]->loc);
  check_interfaces(0);

  configure(units);
  // Without a configuration every PROGRAM gets an instance (also in test builds, where a
  // TcUnit run scans the program that calls TcUnit.RUN()).
  if (!app_->has_configuration) {
    for (const auto& p : app_->pous)
      if (p->kind == PouKind::Program && !p->is_stdlib) app_->programs.push_back(ProgramInstance{p->name, p.get(), 0, ""});
  }
  for (auto& pi : app_->programs) {
    if (!pi.pou->compiled) continue;
    // A PROGRAM other POUs name (MAIN.n) has its memory already: its one instance takes it.
    if (auto named = program_addr_.find(pi.pou); named != program_addr_.end()) {
      const auto copies = std::count_if(app_->programs.begin(), app_->programs.end(),
                                        [&](const ProgramInstance& o) { return o.pou == pi.pou; });
      if (copies > 1 && &pi == &*std::find_if(app_->programs.begin(), app_->programs.end(),
                                               [&](const ProgramInstance& o) { return o.pou == pi.pou; })) {
        diags_.error("ST223", named->second.second, pi.pou->name + " has " + std::to_string(copies) +
                                                        " instances in the configuration: which one this names is ambiguous");
      }
      pi.addr = named->second.first;
    } else {
      pi.addr = alloc(pi.pou->frame_size, 8);
      std::copy(pi.pou->type->init.begin(), pi.pou->type->init.end(), app_->init_image.begin() + pi.addr);
    }
    for (const auto& v : pi.pou->vars)
      if (v->retain && v->where == Where::Frame) app_->retain_ranges.emplace_back(pi.addr + v->offset, v->type->size);
  }

  for (const auto* tf : tests)
    for (const auto& tc : tf->tests) compile_test(*tf, tc);
  compile_lifecycle();

  // Method frames live on a small stack of their own.
  app_->mstack_size = 64 * 1024;
  app_->mstack_addr = alloc(app_->mstack_size, 16);

  finish_link();
  if (diags_.has_errors()) return nullptr;
  return std::move(owned_);
}

bool Compiler::link(Application& app, const std::vector<const CompilationUnit*>& units) {
  // What the program was, to put it back when the new units do not compile.
  const size_t n_code = app.code.size(), n_lines = app.lines.size(), n_shifts = app.index_shifts.size(), n_image = app.init_image.size(),
               n_pous = app.pous.size(), n_observers = app.observers.size(), n_branches = app.branches.size(),
               n_globals = app.globals.size(), n_global_syms = app.global_syms.size(),
               n_files = app.file_paths.size(), n_retain = app.retain_ranges.size(), n_type_names = app.type_names.size();
  const ImageArea image_i = app.image_i, image_q = app.image_q, image_m = app.image_m;

  start_from(app);
  for (const auto* u : units) index_unit(*u, false);
  for (size_t i = n_pous; i < app.pous.size(); ++i) src(app.pous[i].get()).late = true;
  declare_units(units, n_pous);

  // The new units see the program instances by path (Main.step).
  instance_paths_ = true;
  for (size_t i = n_pous; i < app.pous.size(); ++i) {
    PouInfo* p = app.pous[i].get();
    ensure_compiled(p, p->loc);
    for (const auto& m : p->methods) ensure_compiled(m.get(), m->loc);
  }
  check_interfaces(n_pous);
  for (size_t i = n_pous; i < app.pous.size(); ++i) {
    PouInfo* p = app.pous[i].get();
    if (p->kind == PouKind::Program && p->compiled) {
      ProgramInstance oi{p->name, p, alloc(p->frame_size, 8), ""};
      std::copy(p->type->init.begin(), p->type->init.end(), app.init_image.begin() + oi.addr);
      app.observers.push_back(oi);
    }
  }
  instance_paths_ = false;

  if (diags_.has_errors()) {
    app.code.resize(n_code);
    app.lines.resize(n_lines);
    app.index_shifts.resize(n_shifts);
    app.init_image.resize(n_image);
    app.pous.resize(n_pous);
    app.observers.resize(n_observers);
    app.branches.resize(n_branches);
    app.globals.resize(n_globals);
    app.global_syms.resize(n_global_syms);
    app.file_paths.resize(n_files);
    app.library_files.resize(n_files);
    app.retain_ranges.resize(n_retain);
    app.type_names.resize(n_type_names);
    app.image_i = image_i;
    app.image_q = image_q;
    app.image_m = image_m;
    return false;
  }
  finish_link();
  return true;
}

}  // namespace detail

const char* dialect_name(Dialect d) { return d == Dialect::Codesys ? "codesys" : "iec"; }

bool parse_dialect(std::string_view text, Dialect* out) {
  if (iequals(text, "iec")) *out = Dialect::Iec;
  else if (iequals(text, "codesys")) *out = Dialect::Codesys;
  else return false;
  return true;
}

std::unique_ptr<Application> compile(const SourceManager& sm, const std::vector<const CompilationUnit*>& units,
                                     const std::vector<const TestFile*>& tests, DiagEngine& diags,
                                     const CompileOptions& options) {
  detail::Compiler c(sm, diags, options);
  return c.run(units, tests);
}

bool link_units(Application& app, const SourceManager& sm, const std::vector<const CompilationUnit*>& units,
                DiagEngine& diags, const CompileOptions& options) {
  detail::Compiler c(sm, diags, options);
  return c.link(app, units);
}

}  // namespace plcfi::st
