// Mutant generation: mutation points found in the compiled program's bytecode (stores to
// the alarm/stop variables, the conditional jumps guarding them, TIME constants feeding
// timer presets), each mutant a patch of code words or of a constant's cold-start bytes.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "mutate.hpp"

namespace plcfi::campaign {

const char* mutation_op_name(MutationOp op) {
  switch (op) {
    case MutationOp::RemoveAssign: return "remove-assign";
    case MutationOp::NegateCond: return "negate-cond";
    case MutationOp::DropCond: return "drop-cond";
    case MutationOp::ForceFalse: return "force-false";
    case MutationOp::ScaleTimer: return "scale-timer";
    case MutationOp::ClearLatch: return "clear-latch";
  }
  return "?";
}

void apply_mutant(CampaignBuild& cb, const Mutant& m, std::vector<CodePatch>* undo_code, std::vector<ImagePatch>* undo_image) {
  st::Application& app = *cb.build->app;
  undo_code->clear();
  undo_image->clear();
  for (const auto& p : m.code) {
    CodePatch u{p.pc, std::vector<uint32_t>(app.code.begin() + p.pc, app.code.begin() + p.pc + p.words.size())};
    std::copy(p.words.begin(), p.words.end(), app.code.begin() + p.pc);
    undo_code->push_back(std::move(u));
  }
  for (const auto& p : m.image) {
    ImagePatch u{p.addr, std::vector<uint8_t>(app.init_image.begin() + p.addr, app.init_image.begin() + p.addr + p.bytes.size())};
    std::copy(p.bytes.begin(), p.bytes.end(), app.init_image.begin() + p.addr);
    undo_image->push_back(std::move(u));
  }
}

void undo_mutant(CampaignBuild& cb, const std::vector<CodePatch>& undo_code, const std::vector<ImagePatch>& undo_image) {
  st::Application& app = *cb.build->app;
  for (auto it = undo_code.rbegin(); it != undo_code.rend(); ++it) std::copy(it->words.begin(), it->words.end(), app.code.begin() + it->pc);
  for (auto it = undo_image.rbegin(); it != undo_image.rend(); ++it)
    std::copy(it->bytes.begin(), it->bytes.end(), app.init_image.begin() + it->addr);
}

namespace {

// A variable as the code sees it: (POU, frame offset) for frame slots, (nullptr, absolute
// address) for globals and program-instance variables; bit >= 0 for a located BOOL bit.
using VarKey = std::tuple<const st::PouInfo*, uint32_t, int>;

// One operand reference of an instruction, read off its register-transfer text.
struct OperandRef {
  char space;  // 'R' frame, 'M' absolute
  int word;    // operand index (1 = a)
  bool dest;
};

std::vector<OperandRef> operand_refs(st::Op op) {
  static std::vector<std::vector<OperandRef>> cache;
  if (cache.empty()) {
    cache.resize(static_cast<size_t>(st::Op::Count_));
    for (size_t k = 0; k < cache.size(); ++k) {
      std::string rtl = st::op_info(static_cast<st::Op>(k)).rtl;
      // "R8[a] := ...", "R[a] := ...", "M16[a] := ...", "bit b of M8[a] := ...": the
      // destination is the first reference, before the first ":=" that is not "pc :=".
      size_t assign = rtl.find(" := ");
      bool bit_store = rtl.rfind("bit ", 0) == 0;
      for (size_t p = 0; p < rtl.size(); ++p) {
        char c = rtl[p];
        if ((c != 'R' && c != 'M') || (p > 0 && std::isalnum(static_cast<unsigned char>(rtl[p - 1])))) continue;
        size_t q = p + 1;
        while (q < rtl.size() && (std::isdigit(static_cast<unsigned char>(rtl[q])) || rtl[q] == 'f')) ++q;
        if (q + 2 >= rtl.size() || rtl[q] != '[' || rtl[q + 2] != ']' || rtl[q + 1] < 'a' || rtl[q + 1] > 'k') continue;
        bool dest = assign != std::string::npos && p < assign && rtl.compare(0, 3, "if ") != 0 &&
                    (p == 0 || (bit_store && p == rtl.find(c == 'R' ? " of R" : " of M") + 4));
        cache[k].push_back({c, rtl[q + 1] - 'a' + 1, dest});
      }
    }
  }
  return cache[static_cast<size_t>(op)];
}

const std::map<std::string, st::Op>& ops_by_name() {
  static std::map<std::string, st::Op> m;
  if (m.empty())
    for (uint32_t k = 0; k < static_cast<uint32_t>(st::Op::Count_); ++k) m[st::op_info(static_cast<st::Op>(k)).name] = static_cast<st::Op>(k);
  return m;
}

std::string op_name(st::Op op) { return st::op_info(op).name; }

st::Op negated_jump(st::Op op) {
  std::string n = op_name(op);
  static const std::pair<const char*, const char*> swaps[] = {{"JMPF", "JMPT"}, {"JMPT", "JMPF"}, {"JLT_", "JGE_"},
                                                             {"JGE_", "JLT_"}, {"JEQ_", "JNE_"}, {"JNE_", "JEQ_"},
                                                             {"JNLT_", "JLT_"}, {"JNGE_", "JGE_"}, {"JTZ_", "JTNZ_"},
                                                             {"JTNZ_", "JTZ_"}};
  for (auto [from, to] : swaps)
    if (n.rfind(from, 0) == 0) return ops_by_name().at(to + n.substr(std::strlen(from)));
  return op;
}

struct Insn {
  uint32_t pc = 0, len = 0;
  st::Op op = st::Op::NOP;
};

std::string trim_statement(std::string_view s) {
  std::string t(s);
  size_t c = t.find("(*");
  if (c != std::string::npos) t.resize(c);
  size_t b = t.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  t = t.substr(b);
  t.erase(t.find_last_not_of(" \t\r") + 1);
  return t;
}

std::string time_text(int64_t ns) { return st_duration(ns); }

class Generator {
 public:
  explicit Generator(const CampaignBuild& cb) : cb_(cb), app_(*cb.build->app) {}

  std::vector<Mutant> run() {
    collect_pous();
    for (const st::PouInfo* p : pous_) decode(p);
    for (const st::PouInfo* p : pous_) build_cfg(p);
    collect_labels();
    reachable_pous();
    collect_targets();
    find_guards();
    find_timer_constants();
    emit();
    prove();
    return std::move(out_);
  }

 private:
  void collect_pous() {
    std::set<uint32_t> files(cb_.program_files.begin(), cb_.program_files.end());
    std::vector<const st::PouInfo*> all;
    std::function<void(const st::PouInfo*)> add = [&](const st::PouInfo* p) {
      all.push_back(p);
      for (const auto& m : p->methods) add(m.get());
    };
    for (const auto& p : app_.pous) add(p.get());
    for (const st::PouInfo* p : all) {
      if (p->compiled) by_entry_[p->entry] = p;
      if (!p->compiled || p->is_stdlib || !files.count(p->loc.file) || p->code_end <= p->code_begin) continue;
      pous_.push_back(p);
    }
    std::sort(pous_.begin(), pous_.end(), [](auto* a, auto* b) { return a->code_begin < b->code_begin; });
  }

  void decode(const st::PouInfo* p) {
    auto& v = insns_[p];
    for (uint32_t pc = p->code_begin; pc < p->code_end;) {
      Insn i;
      i.pc = pc;
      i.op = static_cast<st::Op>(app_.code[pc]);
      i.len = st::op_length(&app_.code[pc]);
      v.push_back(i);
      pc += i.len;
    }
  }

  uint32_t word(const Insn& i, int k) const { return app_.code[i.pc + static_cast<uint32_t>(k)]; }

  void collect_labels() {
    for (const auto& [p, v] : insns_)
      for (const Insn& i : v) {
        std::string n = op_name(i.op), rtl = st::op_info(i.op).rtl;
        if (n == "JTAB") {
          uint32_t count = word(i, 3);
          labels_.insert(word(i, 4));
          for (uint32_t k = 0; k < count; ++k) labels_.insert(app_.code[i.pc + 5 + k]);
        } else if (rtl.find("pc := a") != std::string::npos) {
          labels_.insert(word(i, 1));
        } else if (rtl.find("pc := d") != std::string::npos) {
          labels_.insert(word(i, 4));
        }
      }
  }

  // POUs a task can reach: from the program instances (and the FB_init routine) over
  // every static call; a dynamic call (CALLV) makes every vtable entry reachable.
  void reachable_pous() {
    std::vector<uint32_t> work;
    for (const auto& pi : app_.programs) work.push_back(pi.pou->entry);
    if (app_.has_init) work.push_back(app_.init_entry);
    std::set<uint32_t> seen;
    bool dynamic = false;
    while (!work.empty()) {
      uint32_t e = work.back();
      work.pop_back();
      if (!seen.insert(e).second) continue;
      auto it = by_entry_.find(e);
      const st::PouInfo* p = it == by_entry_.end() ? nullptr : it->second;
      if (p) reached_.insert(p);
      // Scan the code from e to the POU's end (or to the next RET of an unnamed routine).
      uint32_t end = p ? p->code_end : static_cast<uint32_t>(app_.code.size());
      for (uint32_t pc = e; pc < end;) {
        st::Op op = static_cast<st::Op>(app_.code[pc]);
        std::string n = op_name(op);
        if (n == "CALL" || n == "CALLA" || n == "CALLP" || n == "CALLS") work.push_back(app_.code[pc + 2]);
        if (n == "CALLV") dynamic = true;
        if (!p && (n == "RET" || n == "HALT")) break;
        pc += st::op_length(&app_.code[pc]);
      }
      if (dynamic) {
        for (uint32_t t : app_.vtable)
          if (t) work.push_back(t);
        dynamic = false;
      }
    }
  }

  // The keys a frame write at `slot` of POU p is known by.
  std::vector<VarKey> frame_keys(const st::PouInfo* p, uint32_t slot) const {
    std::vector<VarKey> k = {{p, slot, -1}};
    if (p->kind == st::PouKind::Program)
      for (const auto& pi : app_.programs)
        if (pi.pou == p) k.push_back({nullptr, pi.addr + slot, -1});
    for (const auto& v : p->vars)
      if (v->where == st::Where::Frame && v->type && v->type->kind == st::TypeKind::Pou && v->type->pou && slot >= v->offset &&
          slot < v->offset + v->type->size)
        k.push_back({v->type->pou, slot - v->offset, -1});
    return k;
  }

  // Keys of the destination of a store instruction (empty: not a store we mutate).
  std::vector<VarKey> store_keys(const st::PouInfo* p, const Insn& i) const {
    std::string n = op_name(i.op);
    if (n == "STBIT") return {{nullptr, word(i, 1), static_cast<int>(word(i, 2))}};
    for (const auto& r : operand_refs(i.op))
      if (r.dest) return r.space == 'M' ? std::vector<VarKey>{{nullptr, word(i, r.word), -1}} : frame_keys(p, word(i, r.word));
    return {};
  }

  bool is_target(const std::vector<VarKey>& keys, std::string* name) const {
    for (const auto& k : keys) {
      auto it = targets_.find(k);
      if (it != targets_.end()) {
        *name = it->second;
        return true;
      }
    }
    return false;
  }

  void add_target(const std::string& path) {
    std::string e;
    auto h = st::resolve(app_, path, &e);
    if (!h || !h->type || !h->type->is_elementary()) return;
    targets_.emplace(VarKey{nullptr, h->addr, h->is_bit ? h->bit : -1}, path);
  }

  void collect_targets() {
    for (const auto& r : cb_.spec.fmea.rows) add_target(r.alarm);
    // Identifiers of the fault classes' own formulas (placeholders such as {start} stand
    // for TSD text, not for the reaction, and are skipped).
    for (const auto& fc : cb_.spec.classes.classes) {
      std::vector<const monitor::FormulaSource*> fs;
      for (const auto& cr : fc.requirements)
        for (const auto* f : {&cr.trigger, &cr.invariant, &cr.final, &cr.delay, &cr.reaction, &cr.release}) fs.push_back(f);
      for (const auto& fb : fc.forbidden) fs.push_back(&fb.formula);
      for (const auto* f : fs) {
        const std::string& t = f->text;
        for (size_t p = 0; p < t.size();) {
          if (t[p] == '{') {
            size_t e = t.find('}', p);
            p = e == std::string::npos ? t.size() : e + 1;
          } else if (std::isalpha(static_cast<unsigned char>(t[p])) || t[p] == '_') {
            size_t q = p;
            while (q < t.size() && (std::isalnum(static_cast<unsigned char>(t[q])) || t[q] == '_' || t[q] == '.')) ++q;
            if (q >= t.size() || t[q] != '#') add_target(t.substr(p, q - p));  // not T#..., E_Step#...
            p = q;
          } else {
            ++p;
          }
        }
      }
    }
  }

  // Control-flow successors of each instruction of a POU (indexes into its insns_).
  void build_cfg(const st::PouInfo* p) {
    const auto& v = insns_.at(p);
    std::map<uint32_t, size_t> at;
    for (size_t k = 0; k < v.size(); ++k) at[v[k].pc] = k;
    auto& succ = succ_[p];
    succ.assign(v.size(), {});
    auto to = [&](size_t k, uint32_t pc) {
      auto it = at.find(pc);
      if (it != at.end()) succ[k].push_back(it->second);
    };
    for (size_t k = 0; k < v.size(); ++k) {
      const Insn& i = v[k];
      std::string n = op_name(i.op), rtl = st::op_info(i.op).rtl;
      bool next = true;
      if (n == "RET" || n == "HALT" || n == "TRAP") {
        next = false;
      } else if (n == "JMP" || n == "JMPB") {
        to(k, word(i, 1));
        next = false;
      } else if (n == "JTAB") {
        uint32_t count = word(i, 3);
        to(k, word(i, 4));
        for (uint32_t c = 0; c < count; ++c) to(k, app_.code[i.pc + 5 + c]);
        next = false;
      } else if (rtl.find("pc := a") != std::string::npos) {
        to(k, word(i, 1));
      } else if (rtl.find("pc := d") != std::string::npos) {
        to(k, word(i, 4));
      }
      if (next && k + 1 < v.size()) succ[k].push_back(k + 1);
    }
    size_t entry = 0;
    auto e = at.find(p->entry);
    if (e != at.end()) entry = e->second;
    entry_[p] = entry;
  }

  // True when every path from the POU's entry to `target` (target = SIZE_MAX: to a
  // return) passes through instruction `through`.
  bool all_paths_through(const st::PouInfo* p, size_t through, size_t target) const {
    const auto& v = insns_.at(p);
    const auto& succ = succ_.at(p);
    std::vector<bool> seen(v.size(), false);
    std::vector<size_t> work = {entry_.at(p)};
    while (!work.empty()) {
      size_t k = work.back();
      work.pop_back();
      if (k == through || seen[k]) continue;
      seen[k] = true;
      if (k == target) return false;
      if (target == SIZE_MAX && succ[k].empty()) return false;  // a return reached around it
      for (size_t s : succ[k]) work.push_back(s);
    }
    return true;
  }

  // The branch whose body holds instruction idx: the nearest COV on every path from the
  // POU's entry to it, so when that branch was never taken, idx never ran. *known also
  // when idx runs on every call of its POU (branch -1).
  int32_t branch_of(const st::PouInfo* p, size_t idx, bool* known, size_t* cov_idx) const {
    const auto& v = insns_.at(p);
    *known = false;
    for (size_t k = idx; k-- > 0;) {
      if (op_name(v[k].op) != "COV" || !all_paths_through(p, k, idx)) continue;
      *known = true;
      *cov_idx = k;
      return static_cast<int32_t>(word(v[k], 1));
    }
    *known = all_paths_through(p, idx, SIZE_MAX);
    return -1;
  }

  // Frame slots read by the instructions of the statement that ends with v[idx].
  std::vector<uint32_t> condition_reads(const st::PouInfo* p, size_t idx) const {
    const auto& v = insns_.at(p);
    auto it = std::upper_bound(app_.lines.begin(), app_.lines.end(), v[idx].pc,
                               [](uint32_t pc, const auto& e) { return pc < e.first; });
    uint32_t from = it == app_.lines.begin() ? 0 : std::prev(it)->first;
    std::vector<uint32_t> slots;
    for (size_t k = idx + 1; k-- > 0 && v[k].pc >= from;)
      for (const auto& r : operand_refs(v[k].op))
        if (!r.dest && r.space == 'R') slots.push_back(word(v[k], r.word));
    return slots;
  }

  // A feeder of a guard of POU p: a BOOL local or output of p, or a BOOL output of a
  // user FB instance held by p.
  void add_feeder(const st::PouInfo* p, uint32_t slot, bool* grew) {
    for (const auto& v : p->vars) {
      if (v->where != st::Where::Frame || !v->type) continue;
      if (v->offset == slot && v->type->kind == st::TypeKind::Bool &&
          (v->section == st::VarSection::Var || v->section == st::VarSection::Output) && !v->constant) {
        if (targets_.emplace(VarKey{p, slot, -1}, p->name + "." + v->name).second) *grew = true;
        return;
      }
      if (v->type->kind == st::TypeKind::Pou && v->type->pou && !v->type->pou->is_stdlib && slot >= v->offset &&
          slot < v->offset + v->type->size) {
        const st::PouInfo* fb = v->type->pou;
        for (const auto& m : fb->vars)
          if (m->offset == slot - v->offset && m->section == st::VarSection::Output && m->type &&
              m->type->kind == st::TypeKind::Bool)
            if (targets_.emplace(VarKey{fb, m->offset, -1}, fb->name + "." + m->name).second) *grew = true;
        return;
      }
    }
  }

  void find_guards() {
    for (bool grew = true; grew;) {
      grew = false;
      guards_.clear();
      stores_.clear();
      for (const st::PouInfo* p : pous_) {
        const auto& v = insns_[p];
        for (size_t k = 0; k < v.size(); ++k) {
          std::string name;
          if (!is_target(store_keys(p, v[k]), &name)) continue;
          stores_.push_back({p, k, name});
          bool known = false;
          size_t cov = 0;
          int32_t b = branch_of(p, k, &known, &cov);
          if (b < 0 || cov == 0) continue;
          const Insn& j = v[cov - 1];
          if (!st::is_conditional_jump(j.op) || j.pc + j.len != v[cov].pc || labels_.count(v[cov].pc)) continue;
          auto& g = guards_[{p, cov - 1}];
          if (std::find(g.begin(), g.end(), name) == g.end()) g.push_back(name);
          for (uint32_t slot : condition_reads(p, cov - 1)) add_feeder(p, slot, &grew);
        }
      }
    }
  }

  // Every address a POU's frame has in the cold-start image.
  std::vector<uint32_t> instances_of(const st::PouInfo* target) const {
    std::vector<uint32_t> out;
    std::function<void(const st::PouInfo*, uint32_t, int)> walk = [&](const st::PouInfo* p, uint32_t addr, int depth) {
      if (p == target) out.push_back(addr);
      if (depth > 16) return;
      for (const auto& v : p->vars)
        if (v->where == st::Where::Frame && v->type && v->type->kind == st::TypeKind::Pou && v->type->pou)
          walk(v->type->pou, addr + v->offset, depth + 1);
    };
    for (const auto& pi : app_.programs) walk(pi.pou, pi.addr, 0);
    for (const auto& g : app_.globals)
      if (g.sym && g.sym->type && g.sym->type->kind == st::TypeKind::Pou && g.sym->type->pou)
        walk(g.sym->type->pou, g.sym->offset, 0);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // TIME constants feeding the PT of a TON/TOF/TP whose Q the program reads: followed
  // back from PT over 8-byte moves, through FB inputs to the callers' argument moves.
  void find_timer_constants() {
    std::set<std::pair<const st::PouInfo*, uint32_t>> work_seen;
    std::vector<std::pair<const st::PouInfo*, uint32_t>> work;
    for (const st::PouInfo* p : pous_)
      for (const auto& v : p->vars) {
        if (v->where != st::Where::Frame || !v->type || v->type->kind != st::TypeKind::Pou || !v->type->pou) continue;
        const st::PouInfo* t = v->type->pou;
        std::string n = st::canon(t->name);
        if (!t->is_stdlib || (n != "TON" && n != "TOF" && n != "TP")) continue;
        const st::Symbol* q = t->find_var("Q");
        const st::Symbol* pt = t->find_var("PT");
        if (!q || !pt) continue;
        bool q_read = false;
        for (const Insn& i : insns_[p])
          for (const auto& r : operand_refs(i.op))
            if (!r.dest && r.space == 'R' && word(i, r.word) == v->offset + q->offset) q_read = true;
        if (q_read) work.push_back({p, v->offset + pt->offset});
      }
    const st::Op mov8 = ops_by_name().at("MOV8");
    while (!work.empty()) {
      auto [p, slot] = work.back();
      work.pop_back();
      if (!work_seen.insert({p, slot}).second) continue;
      for (const Insn& i : insns_[p]) {
        if (i.op != mov8 || word(i, 1) != slot) continue;
        uint32_t src = word(i, 2);
        if (src >= p->const_from && src + 8 <= p->const_from + p->consts.size()) {
          timer_consts_.insert({p, src, i.pc, nullptr});
          continue;
        }
        const st::Symbol* sym = nullptr;
        for (const auto& v : p->vars)
          if (v->where == st::Where::Frame && v->offset == src) sym = v.get();
        if (!sym || !sym->type || !sym->type->is_time_like() || sym->type->size != 8) continue;
        if (sym->constant) {
          timer_consts_.insert({p, src, i.pc, sym});
        } else if (sym->section == st::VarSection::Input && p->kind == st::PouKind::FunctionBlock) {
          for (const st::PouInfo* q : pous_)
            for (const auto& w : q->vars)
              if (w->where == st::Where::Frame && w->type && w->type->kind == st::TypeKind::Pou && w->type->pou == p)
                work.push_back({q, w->offset + src});
        } else {
          work.push_back({p, src});
        }
      }
    }
  }

  std::string where_file(const st::SourceLoc& loc) const {
    return loc.file < app_.file_paths.size() ? app_.file_paths[loc.file] : "?";
  }
  std::string short_loc(const st::SourceLoc& loc) const {
    return fmt::format("{}:{}", std::filesystem::path(where_file(loc)).filename().string(), loc.line);
  }
  std::string statement(const st::SourceLoc& loc) const {
    if (loc.file >= cb_.build->sm.size()) return "?";
    return trim_statement(cb_.build->sm.file(loc.file).line_text(loc.line));
  }

  Mutant base(const st::PouInfo* p, size_t k, MutationOp op) const {
    const Insn& i = insns_.at(p)[k];
    Mutant m;
    m.op = op;
    m.pc = i.pc;
    st::SourceLoc loc = app_.loc_of(i.pc);
    m.file = where_file(loc);
    m.line = loc.line;
    m.col = loc.col;
    size_t cov = 0;
    m.branch = branch_of(p, k, &m.branch_known, &cov);
    m.pou = p;
    return m;
  }

  // Where else the variables are written (lines of the program's files), for the reasons.
  std::string writers_of(const std::vector<std::string>& names, uint32_t except_pc) const {
    std::map<std::string, std::set<uint32_t>> lines;
    for (const auto& s : stores_) {
      const Insn& i = insns_.at(s.pou)[s.idx];
      if (i.pc == except_pc || std::find(names.begin(), names.end(), s.name) == names.end()) continue;
      st::SourceLoc loc = app_.loc_of(i.pc);
      lines[std::filesystem::path(where_file(loc)).filename().string()].insert(loc.line);
    }
    std::string out;
    for (const auto& [f, ls] : lines) {
      out += (out.empty() ? "" : "; ") + f + ":";
      bool first = true;
      for (uint32_t l : ls) {
        out += (first ? "" : ", ") + std::to_string(l);
        first = false;
      }
    }
    return out;
  }

  void emit_guard(const st::PouInfo* p, size_t k, const std::vector<std::string>& names) {
    const Insn& j = insns_[p][k];
    std::string cond = statement(app_.loc_of(j.pc));
    std::string vars;
    for (const auto& n : names) vars += (vars.empty() ? "" : ", ") + n;
    uint32_t target = word(j, 1);
    {
      Mutant m = base(p, k, MutationOp::NegateCond);
      std::vector<uint32_t> w(app_.code.begin() + j.pc, app_.code.begin() + j.pc + j.len);
      w[0] = static_cast<uint32_t>(negated_jump(j.op));
      m.code.push_back({j.pc, w});
      m.variable = vars;
      m.writers = writers_of(names, UINT32_MAX);
      m.change = fmt::format("condition of `{}` negated", cond);
      push(std::move(m));
    }
    {
      Mutant m = base(p, k, MutationOp::DropCond);
      m.code.push_back({j.pc, std::vector<uint32_t>(j.len, static_cast<uint32_t>(st::Op::NOP))});
      m.variable = vars;
      m.writers = writers_of(names, UINT32_MAX);
      m.change = fmt::format("condition of `{}` dropped (branch always taken)", cond);
      push(std::move(m));
    }
    {
      Mutant m = base(p, k, MutationOp::ForceFalse);
      std::vector<uint32_t> w(j.len, static_cast<uint32_t>(st::Op::NOP));
      w[0] = static_cast<uint32_t>(st::Op::JMP);
      w[1] = target;
      m.code.push_back({j.pc, w});
      m.variable = vars;
      m.writers = writers_of(names, UINT32_MAX);
      m.change = fmt::format("condition of `{}` forced FALSE (branch never taken)", cond);
      push(std::move(m));
    }
  }

  // The constant-pool slot of p holding the byte value v (-1: none).
  int64_t pool_slot(const st::PouInfo* p, uint8_t v) const {
    for (size_t k = 0; k < p->consts.size(); ++k)
      if (p->consts[k] == v) return static_cast<int64_t>(p->const_from + k);
    return -1;
  }
  bool is_pool_value(const st::PouInfo* p, uint32_t slot, uint8_t v) const {
    return slot >= p->const_from && slot < p->const_from + p->consts.size() && p->consts[slot - p->const_from] == v;
  }

  void emit_store(const st::PouInfo* p, size_t k, const std::string& name) {
    const Insn& i = insns_[p][k];
    std::string stmt = statement(app_.loc_of(i.pc));
    {
      Mutant m = base(p, k, MutationOp::RemoveAssign);
      m.code.push_back({i.pc, std::vector<uint32_t>(i.len, static_cast<uint32_t>(st::Op::NOP))});
      m.variable = name;
      m.writers = writers_of({name}, i.pc);
      m.change = fmt::format("`{}` removed", stmt);
      push(std::move(m));
    }
    // A latch: this stores the constant TRUE and some other statement stores FALSE.
    std::string n = op_name(i.op);
    int src_word = n == "MOV1" || n == "STG1" ? 2 : n == "STBIT" ? 3 : 0;
    if (!src_word || !is_pool_value(p, word(i, src_word), 1)) return;
    bool has_reset = false;
    for (const auto& s : stores_) {
      if (s.name != name) continue;
      const Insn& r = insns_[s.pou][s.idx];
      std::string rn = op_name(r.op);
      int rw = rn == "MOV1" || rn == "STG1" ? 2 : rn == "STBIT" ? 3 : 0;
      if (rw && is_pool_value(s.pou, word(r, rw), 0)) has_reset = true;
    }
    int64_t zero = pool_slot(p, 0);
    if (!has_reset || zero < 0) return;
    Mutant m = base(p, k, MutationOp::ClearLatch);
    std::vector<uint32_t> w(app_.code.begin() + i.pc, app_.code.begin() + i.pc + i.len);
    w[static_cast<size_t>(src_word)] = static_cast<uint32_t>(zero);
    m.code.push_back({i.pc, w});
    m.variable = name;
    m.writers = writers_of({name}, i.pc);
    m.change = fmt::format("latch `{}` cleared: the set stores FALSE", stmt);
    push(std::move(m));
  }

  void emit_timer(const st::PouInfo* p, size_t k, uint32_t slot, const st::Symbol* sym) {
    auto insts = instances_of(p);
    if (insts.empty()) return;
    int64_t value = 0;
    std::memcpy(&value, app_.init_image.data() + insts.front() + slot, 8);
    if (value <= 0) return;
    for (auto [num, den, text] : {std::tuple{2, 1, "x2"}, std::tuple{1, 2, "x0.5"}}) {
      Mutant m = base(p, k, MutationOp::ScaleTimer);
      int64_t scaled = value / den * num;
      std::vector<uint8_t> bytes(8);
      std::memcpy(bytes.data(), &scaled, 8);
      for (uint32_t a : insts) m.image.push_back({a + slot, bytes});
      if (sym) {
        m.file = where_file(sym->loc);
        m.line = sym->loc.line;
        m.col = sym->loc.col;
        m.variable = p->name + "." + sym->name;
        m.change = fmt::format("timer preset constant {} = {} scaled {} to {}", sym->name, time_text(value), text, time_text(scaled));
      } else {
        m.variable = fmt::format("{} literal {}", p->name, time_text(value));
        m.change = fmt::format("TIME constant {} of `{}` (a timer preset; every use of the value in {}) scaled {} to {}",
                               time_text(value), statement(app_.loc_of(m.pc)), p->name, text, time_text(scaled));
      }
      push(std::move(m));
    }
  }

  void emit() {
    std::map<std::pair<const st::PouInfo*, uint32_t>, std::vector<std::pair<uint32_t, const st::Symbol*>>> timers_at;
    std::set<std::pair<const st::PouInfo*, uint32_t>> timer_done;
    for (const st::PouInfo* p : pous_) {
      const auto& v = insns_[p];
      for (size_t k = 0; k < v.size(); ++k) {
        auto g = guards_.find({p, k});
        if (g != guards_.end()) emit_guard(p, k, g->second);
        for (const auto& s : stores_)
          if (s.pou == p && s.idx == k) emit_store(p, k, s.name);
        for (const auto& t : timer_consts_)
          if (t.pou == p && t.pc == v[k].pc && timer_done.insert({p, t.slot}).second) emit_timer(p, k, t.slot, t.sym);
      }
    }
  }

  void push(Mutant m) {
    m.index = out_.size();
    out_.push_back(std::move(m));
  }

  // Equivalence proofs: the patch proofs (mark_patch_equivalents), then code no task reaches.
  void prove() {
    mark_patch_equivalents(app_, &out_);
    for (Mutant& m : out_)
      if (!m.equivalent && m.image.empty() && !reached_.count(m.pou)) {
        m.equivalent = true;
        m.proof = fmt::format("{} is never called from a task's program: its code is unreachable", m.pou->name);
      }
  }

  struct Store {
    const st::PouInfo* pou;
    size_t idx;
    std::string name;
  };
  struct TimerConst {
    const st::PouInfo* pou;
    uint32_t slot;
    uint32_t pc;
    const st::Symbol* sym;
    bool operator<(const TimerConst& o) const { return std::tie(pou, slot, pc) < std::tie(o.pou, o.slot, o.pc); }
  };

  const CampaignBuild& cb_;
  const st::Application& app_;
  std::vector<const st::PouInfo*> pous_;
  std::map<uint32_t, const st::PouInfo*> by_entry_;
  std::map<const st::PouInfo*, std::vector<Insn>> insns_;
  std::map<const st::PouInfo*, std::vector<std::vector<size_t>>> succ_;
  std::map<const st::PouInfo*, size_t> entry_;
  std::set<uint32_t> labels_;
  std::set<const st::PouInfo*> reached_;
  std::map<VarKey, std::string> targets_;
  std::map<std::pair<const st::PouInfo*, size_t>, std::vector<std::string>> guards_;
  std::vector<Store> stores_;
  std::set<TimerConst> timer_consts_;
  std::vector<Mutant> out_;
};

}  // namespace

std::vector<Mutant> generate_mutants(const CampaignBuild& cb) { return Generator(cb).run(); }

void mark_patch_equivalents(const st::Application& app, std::vector<Mutant>* mutants) {
  std::map<std::string, size_t> seen;
  for (Mutant& m : *mutants) {
    bool identical = true;
    std::string key;
    for (const auto& c : m.code) {
      key += fmt::format("c{}:", c.pc);
      for (size_t k = 0; k < c.words.size(); ++k) {
        key += fmt::format("{},", c.words[k]);
        identical = identical && app.code[c.pc + k] == c.words[k];
      }
    }
    for (const auto& im : m.image) {
      key += fmt::format("i{}:", im.addr);
      for (size_t k = 0; k < im.bytes.size(); ++k) {
        key += fmt::format("{},", im.bytes[k]);
        identical = identical && app.init_image[im.addr + k] == im.bytes[k];
      }
    }
    if (identical) {
      m.equivalent = true;
      m.proof = "the patched program is byte-identical to the original";
      continue;
    }
    auto [it, fresh] = seen.emplace(key, m.index);
    if (!fresh) {
      m.equivalent = true;
      m.proof = fmt::format("the same patch as mutant #{} (reported there)", it->second);
    }
  }
}

}  // namespace plcfi::campaign
