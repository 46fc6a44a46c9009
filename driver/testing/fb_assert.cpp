// Unit tests in the assertion-FB style: the scan loop until a condition, and FB_ASSERT's log.
#include "fb_assert.hpp"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include <map>

#include "codegen/compiler.hpp"
#include "common/duration.hpp"
#include "engine.hpp"
#include "instances.hpp"
#include "scan.hpp"
#include "vm/memory.hpp"

namespace plcfi::testing {

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


std::vector<Found> fb_assert_instances(const st::Application& app) {
  return find_instances(app, [](const st::PouInfo* p) { return p->is_stdlib && st::iequals(p->name, "FB_ASSERT"); });
}

// A unit's state machine as the scans see it: the state it is in and since when, and how
// long each state lasted (its last stay).
struct Unit {
  std::string name;                  // read after the restart (FB_init sets it)
  uint32_t step_addr = 0, name_addr = 0, name_size = 0;
  int64_t state = 0, since_ns = 0;
  bool timed_out = false;            // this stay outlasted --test-timeout (reported once)
  std::map<int64_t, double> lasted;  // state -> seconds
};

class UntilScan : public ScanTest {
 public:
  UntilScan(const st::Application& app, const st::ProgramInstance& until, uint32_t reached, const UntilOptions& opt,
            UntilReport* rep)
      : app_(app), until_(until), reached_(reached), opt_(opt), rep_(rep) {}

  std::vector<Unit> units;
  std::vector<AssertLogEntry> timeouts;

  bool after_scan(st::Machine& m, uint64_t n, int64_t now) override {
    follow_units(m, now);
    if (!m.call(until_.pou->entry, until_.addr)) {
      rep_->program_trap = st::describe_trap(app_, m.trap()) + fmt::format(" (in --until, cycle {})", n);
      return false;
    }
    if (m.mem()[until_.addr + reached_] != 0) {
      rep_->reached = true;
      return false;
    }
    return true;
  }

  // Closes every unit's current stay at the end of the run.
  void finish(int64_t end_ns) {
    for (auto& u : units) u.lasted[u.state] = static_cast<double>(end_ns - u.since_ns) / 1e9;
  }

 private:
  void follow_units(const st::Machine& m, int64_t now) {
    for (auto& u : units) {
      if (u.name.empty()) u.name = text_at(m.mem(), u.name_addr, u.name_size);
      const int64_t state = st::load_as<int32_t>(m.mem() + u.step_addr);
      if (state != u.state) {
        u.lasted[u.state] = static_cast<double>(now - u.since_ns) / 1e9;
        u.state = state;
        u.since_ns = now;
        u.timed_out = false;
      } else if (opt_.test_timeout_ns > 0 && !u.timed_out && now - u.since_ns >= opt_.test_timeout_ns) {
        u.timed_out = true;
        AssertLogEntry e;
        e.unit = u.name;
        e.state = state;
        e.message = fmt::format("state {} lasted longer than the per-test time-out ({})", state,
                                common::format_duration(opt_.test_timeout_ns));
        timeouts.push_back(std::move(e));
      }
    }
  }

  const st::Application& app_;
  const st::ProgramInstance& until_;
  uint32_t reached_;
  const UntilOptions& opt_;
  UntilReport* rep_;
};

}  // namespace

bool has_fb_assert(const st::Application& app) { return log_of(app).ok; }

std::vector<std::string> fb_assert_units(const st::Application& app, st::Machine& m, std::string* trap) {
  std::vector<std::string> out;
  if (!m.cold_restart()) {
    *trap = st::describe_trap(app, m.trap()) + " (in FB_init/FB_exit at the restart)";
    return out;
  }
  for (const auto& f : fb_assert_instances(app))
    if (const st::Field* name = f.type->type->field("_faName")) {
      std::string unit = text_at(m.mem(), f.addr + name->offset, name->type->size);
      if (std::find(out.begin(), out.end(), unit) == out.end()) out.push_back(std::move(unit));
    }
  return out;
}

UntilReport run_until(const st::Application& app, const rt::Schedule& schedule, st::Machine& m,
                      const st::ProgramInstance& until, uint32_t reached, const UntilOptions& opt) {
  UntilReport rep;
  UntilScan scan(app, until, reached, opt, &rep);
  for (const auto& f : fb_assert_instances(app)) {
    const st::Field* step = f.type->type->field("_faStep");
    const st::Field* name = f.type->type->field("_faName");
    if (!step || !name) continue;
    Unit u;
    u.step_addr = f.addr + step->offset;
    u.name_addr = f.addr + name->offset;
    u.name_size = name->type->size;
    scan.units.push_back(std::move(u));
  }
  const ScanRun run = run_scans(app, schedule, m, scan, opt.timeout_ns, opt.budget);
  if (rep.program_trap.empty()) rep.program_trap = run.program_trap;
  rep.cycles = run.cycles;
  rep.virtual_ns = run.virtual_ns;
  scan.finish(rep.virtual_ns);
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
  rep.timeouts = static_cast<int64_t>(scan.timeouts.size());
  for (auto& e : scan.timeouts) rep.log.push_back(std::move(e));
  for (auto& e : rep.log)
    for (const auto& u : scan.units)
      if (u.name == e.unit)
        if (auto it = u.lasted.find(e.state); it != u.lasted.end()) e.seconds = it->second;
  if (opt.filter)
    std::erase_if(rep.log, [&](const AssertLogEntry& e) { return !opt.filter->selects(e.unit, fmt::format("state {}", e.state)); });
  return rep;
}

}  // namespace plcfi::testing
