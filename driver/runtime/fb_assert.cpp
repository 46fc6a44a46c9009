// Unit tests in the assertion-FB style: the scan loop until a condition, and FB_ASSERT's log.
#include "fb_assert.hpp"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "codegen/compiler.hpp"
#include "engine.hpp"
#include "vm/memory.hpp"

namespace plcfi::rt {

namespace {

const st::Symbol* global(const st::Application& app, const char* name) {
  for (const auto& g : app.globals)
    if (g.sym && g.sym->where == st::Where::Abs && st::iequals(g.sym->name, name)) return g.sym;
  return nullptr;
}

// FB_ASSERT's log in the library's globals.
struct Log {
  const st::Symbol *count, *overflow, *checks, *failures, *unit, *state, *passed, *text, *where;
  bool ok = false;
};

Log log_of(const st::Application& app) {
  Log l{global(app, "_faCount"), global(app, "_faOverflow"), global(app, "_faChecks"),
        global(app, "_faFailures"), global(app, "_faUnit"), global(app, "_faState"),
        global(app, "_faPassed"), global(app, "_faText"), global(app, "_faWhere")};
  l.ok = l.count && l.overflow && l.checks && l.failures && l.unit && l.state && l.passed && l.text && l.where &&
         l.unit->type->elem && l.text->type->elem;
  return l;
}

std::string text_at(const uint8_t* mem, uint32_t addr, uint32_t size) {
  const char* p = reinterpret_cast<const char*>(mem + addr);
  return std::string(p, strnlen(p, size));
}

}  // namespace

bool has_fb_assert(const st::Application& app) { return log_of(app).ok; }

UntilReport run_until(const st::Application& app, const Schedule& schedule, st::Machine& m,
                      const st::ProgramInstance& until, uint32_t reached, const UntilOptions& opt) {
  UntilReport rep;
  m.set_budget(opt.budget);
  const int64_t tick = schedule.tick_ns();
  uint64_t n = 0;
  if (!m.cold_restart()) rep.program_trap = st::describe_trap(app, m.trap()) + " (in FB_init/FB_exit at the restart)";
  while (rep.program_trap.empty()) {
    const int64_t now = static_cast<int64_t>(n) * tick;
    if (now >= opt.timeout_ns) break;
    m.set_now(now);
    m.clear_taken();
    schedule.run_due(app, m, n, &rep.program_trap);
    m.merge_coverage();
    ++n;
    if (!rep.program_trap.empty()) break;
    if (!m.call(until.pou->entry, until.addr)) {
      rep.program_trap = st::describe_trap(app, m.trap()) + fmt::format(" (in --until, cycle {})", n - 1);
      break;
    }
    if (m.mem()[until.addr + reached] != 0) {
      rep.reached = true;
      break;
    }
  }
  rep.cycles = n;
  rep.virtual_ns = static_cast<int64_t>(n) * tick;

  const Log l = log_of(app);
  if (!l.ok) return rep;
  const uint8_t* mem = m.mem();
  rep.overflow = mem[l.overflow->offset] != 0;
  rep.checks = st::load_as<int32_t>(mem + l.checks->offset);
  rep.failures = st::load_as<int32_t>(mem + l.failures->offset);
  const int count = std::clamp<int>(st::load_as<int16_t>(mem + l.count->offset), 0, 500);
  const uint32_t unit_size = l.unit->type->elem->size, text_size = l.text->type->elem->size;
  for (int i = 0; i < count; ++i) {
    const auto k = static_cast<uint32_t>(i);
    AssertLogEntry e;
    e.unit = text_at(mem, l.unit->offset + k * unit_size, unit_size);
    e.state = st::load_as<int32_t>(mem + l.state->offset + k * 4);
    e.passed = mem[l.passed->offset + k] != 0;
    e.message = text_at(mem, l.text->offset + k * text_size, text_size);
    const int64_t at = st::load_as<int64_t>(mem + l.where->offset + k * 8);
    if (at != 0) e.where = st::unpack_location(at);
    rep.log.push_back(std::move(e));
  }
  return rep;
}

}  // namespace plcfi::rt
