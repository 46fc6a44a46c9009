// TcUnit runner: find the suite instances, scan, call the suites, read their results.
#include "tcunit.hpp"

#include <cstring>

#include <fmt/format.h>

#include "codegen/compiler.hpp"
#include "engine.hpp"
#include "common/duration.hpp"
#include "vm/memory.hpp"

namespace plcfi::rt {

namespace {

const st::PouInfo* suite_base(const st::Application& app) {
  for (const auto& p : app.pous)
    if (p->is_stdlib && p->kind == st::PouKind::FunctionBlock && st::iequals(p->name, "FB_TestSuite")) return p.get();
  return nullptr;
}

bool derives(const st::PouInfo* p, const st::PouInfo* base) {
  for (int depth = 0; p && depth < 64; p = p->base, ++depth)
    if (p == base) return true;
  return false;
}

struct Found {
  std::string path;
  const st::PouInfo* type;
  uint32_t addr;
};

// Every instance of a type derived from FB_TestSuite inside a value of type t at addr:
// members of FB instances and STRUCTs, elements of arrays.
void collect(const st::Type* t, uint32_t addr, const std::string& path, const st::PouInfo* base, int depth,
             std::vector<Found>* out) {
  if (!t || depth > 32 || out->size() > 10'000) return;
  if (t->kind == st::TypeKind::Pou && t->pou) {
    if (t->pou != base && derives(t->pou, base)) {
      out->push_back(Found{path, t->pou, addr});
      return;  // a suite's own members are its business
    }
  }
  if ((t->kind == st::TypeKind::Pou && t->pou) || (t->kind == st::TypeKind::Struct && !t->is_union)) {
    for (const auto& f : t->fields) collect(f.type, addr + f.offset, path + "." + f.name, base, depth + 1, out);
    return;
  }
  if (t->kind == st::TypeKind::Array && t->elem && t->dims.size() == 1 &&
      (t->elem->kind == st::TypeKind::Pou || t->elem->kind == st::TypeKind::Struct)) {
    const auto& d = t->dims[0];
    for (int64_t i = d.lo; i <= d.hi && out->size() <= 10'000; ++i)
      collect(t->elem, addr + static_cast<uint32_t>(i - d.lo) * t->elem->size, fmt::format("{}[{}]", path, i), base,
              depth + 1, out);
  }
}

std::vector<Found> find_suites(const st::Application& app) {
  std::vector<Found> out;
  const st::PouInfo* base = suite_base(app);
  if (!base) return out;
  for (const auto& inst : app.programs)
    if (inst.pou) collect(inst.pou->type, inst.addr, inst.name, base, 0, &out);
  for (const auto& g : app.globals)
    if (g.sym && g.sym->where == st::Where::Abs) collect(g.sym->type, g.sym->offset, g.scope + "." + g.sym->name, base, 0, &out);
  return out;
}

const st::Symbol* global(const st::Application& app, const char* name) {
  for (const auto& g : app.globals)
    if (g.sym && g.sym->where == st::Where::Abs && st::iequals(g.sym->name, name)) return g.sym;
  return nullptr;
}

// Offsets of FB_TestSuite's bookkeeping inside a suite instance.
struct Layout {
  uint32_t cycle = 0, count = 0, current = 0, overflow = 0;
  const st::Field *name = nullptr, *finished = nullptr, *failed = nullptr, *message = nullptr, *where = nullptr;
  bool ok = false;
};

Layout layout_of(const st::PouInfo* base) {
  Layout l;
  const st::Type* t = base->type;
  auto f = [&](const char* n) { return t->field(n); };
  const st::Field *cy = f("_tcuCycle"), *co = f("_tcuCount"), *cu = f("_tcuCurrent"), *ov = f("_tcuOverflow");
  l.name = f("_tcuName");
  l.finished = f("_tcuFinished");
  l.failed = f("_tcuFailed");
  l.message = f("_tcuMessage");
  l.where = f("_tcuWhere");
  if (!cy || !co || !cu || !ov || !l.name || !l.finished || !l.failed || !l.message || !l.where) return l;
  l.cycle = cy->offset;
  l.count = co->offset;
  l.current = cu->offset;
  l.overflow = ov->offset;
  l.ok = true;
  return l;
}

struct Live {
  Found at;
  bool started = false;
  bool done = false;
  bool stopped = false;     // a runtime error ended it
  std::string trap;         // that error
  int current_at_trap = 0;  // the test it happened in (1-based; 0 none)
  st::SourceLoc trap_loc;
};

int16_t count_of(const st::Machine& m, const Layout& l, uint32_t addr) { return st::load_as<int16_t>(m.mem() + addr + l.count); }

bool all_finished(const st::Machine& m, const Layout& l, uint32_t addr) {
  const int n = count_of(m, l, addr);
  for (int i = 0; i < n; ++i)
    if (!m.mem()[addr + l.finished->offset + i]) return false;
  return true;  // a suite without tests is done after its first call
}

}  // namespace

bool has_tcunit_suites(const st::Application& app) { return !find_suites(app).empty(); }

TcUnitReport run_tcunit(const st::Application& app, const Schedule& schedule, st::Machine& m, const TcUnitOptions& opt) {
  TcUnitReport rep;
  const st::PouInfo* base = suite_base(app);
  const st::Symbol* run = global(app, "_TcUnitRun");
  const st::Symbol* mode = global(app, "_TcUnitMode");
  if (!base || !run || !mode) return rep;
  const Layout l = layout_of(base);
  if (!l.ok) return rep;
  std::vector<Live> live;
  for (auto& f : find_suites(app)) {
    Live s;
    s.at = f;
    live.push_back(std::move(s));
  }

  m.set_budget(opt.budget);
  if (!m.cold_restart()) {
    rep.program_trap = st::describe_trap(app, m.trap()) + " (in FB_init/FB_exit at the restart)";
    return rep;
  }
  const int64_t tick = schedule.tick_ns();
  uint64_t n = 0;
  auto pending = [&] {
    for (const auto& s : live)
      if (!s.done) return true;
    return false;
  };
  while (pending()) {
    const int64_t now = static_cast<int64_t>(n) * tick;
    if (now >= opt.timeout_ns) {
      rep.timed_out = true;
      break;
    }
    m.set_now(now);
    m.clear_taken();
    schedule.run_due(app, m, n, &rep.program_trap);
    ++n;
    if (!rep.program_trap.empty()) {
      m.merge_coverage();
      break;
    }
    uint8_t* mem = m.mem();
    if (st::load_as<int32_t>(mem + run->offset) == 0) {  // RUN() not called in this scan
      m.merge_coverage();
      continue;
    }
    rep.run_called = true;
    st::store_as<int32_t>(mem + run->offset, 0);
    const bool in_sequence = st::load_as<int16_t>(mem + mode->offset) == 2;
    for (auto& s : live) {
      if (s.done) continue;
      s.started = true;
      uint8_t* inst = m.mem() + s.at.addr;
      st::store_as<int32_t>(inst + l.cycle, st::load_as<int32_t>(inst + l.cycle) + 1);
      if (!m.call(s.at.type->entry, s.at.addr)) {
        s.stopped = true;
        s.done = true;
        s.trap = st::describe_trap_kind(m.trap());
        s.trap_loc = m.trap().loc;
        s.current_at_trap = st::load_as<int16_t>(m.mem() + s.at.addr + l.current);
      } else {
        s.done = all_finished(m, l, s.at.addr);
      }
      if (in_sequence && !s.done) break;  // the next suite starts when this one is done
    }
    m.merge_coverage();  // branch coverage of the program and the suites (--coverage)
  }
  rep.cycles = n;
  rep.virtual_ns = static_cast<int64_t>(n) * tick;

  // Results, from each suite's bookkeeping.
  const uint8_t* mem = m.mem();
  for (const auto& s : live) {
    TcUnitSuite out;
    out.path = s.at.path;
    out.type = s.at.type;
    out.started = s.started;
    const uint32_t a = s.at.addr;
    out.overflow = mem[a + l.overflow] != 0;
    const int count = std::min<int>(count_of(m, l, a), 100);
    const uint32_t name_size = l.name->type->elem->size, msg_size = l.message->type->elem->size;
    for (int i = 0; i < count; ++i) {
      TcUnitTest t;
      auto text = [&](const st::Field* f, uint32_t size) {
        const char* p = reinterpret_cast<const char*>(mem + a + f->offset + static_cast<uint32_t>(i) * size);
        return std::string(p, strnlen(p, size));
      };
      t.name = text(l.name, name_size);
      t.finished = mem[a + l.finished->offset + i] != 0;
      t.failed = mem[a + l.failed->offset + i] != 0;
      if (t.failed) {
        t.message = text(l.message, msg_size);
        const int64_t at = st::load_as<int64_t>(mem + a + l.where->offset + static_cast<uint32_t>(i) * 8);
        if (at != 0) t.where = st::unpack_location(at);
      }
      if (!t.failed && s.stopped && s.current_at_trap == i + 1) {
        t.failed = true;
        t.message = s.trap;
        t.where = s.trap_loc;
      } else if (!t.failed && !t.finished) {
        t.failed = true;
        t.message = s.stopped ? "not finished: the suite stopped at a runtime error in another test"
                    : !rep.program_trap.empty()
                        ? "not finished: a runtime error in the program stopped the run"
                        : fmt::format("not finished within the time-out ({}): TEST_FINISHED() was not called",
                                      common::format_duration(opt.timeout_ns));
      }
      out.tests.push_back(std::move(t));
    }
    if (count == 0 && s.stopped) {
      TcUnitTest t;
      t.name = "(before any TEST)";
      t.failed = true;
      t.message = s.trap;
      t.where = s.trap_loc;
      out.tests.push_back(std::move(t));
    }
    rep.suites.push_back(std::move(out));
  }
  return rep;
}

}  // namespace plcfi::rt
