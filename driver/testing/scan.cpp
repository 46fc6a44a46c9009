#include "scan.hpp"

#include "engine.hpp"

namespace plcfi::testing {

ScanRun run_scans(const st::Application& app, const rt::Schedule& schedule, st::Machine& m, ScanTest& t,
                  int64_t timeout_ns, uint64_t budget) {
  ScanRun run;
  m.set_budget(budget);
  if (!m.cold_restart()) {
    run.program_trap = st::describe_trap(app, m.trap()) + " (in FB_init/FB_exit at the restart)";
    return run;
  }
  const int64_t tick = schedule.tick_ns();
  uint64_t n = 0;
  for (;; ++n) {
    const int64_t now = static_cast<int64_t>(n) * tick;
    if (now >= timeout_ns) {
      run.timed_out = true;
      break;
    }
    m.set_now(now);
    m.clear_taken();
    schedule.run_due(app, m, n, &run.program_trap);
    if (!run.program_trap.empty()) {
      m.merge_coverage();
      ++n;
      break;
    }
    const bool more = t.after_scan(m, n, now);
    m.merge_coverage();  // branch coverage of the programs and of what the front end called
    if (!more) {
      ++n;
      break;
    }
  }
  run.cycles = n;
  run.virtual_ns = static_cast<int64_t>(n) * tick;
  return run;
}

}  // namespace plcfi::testing
