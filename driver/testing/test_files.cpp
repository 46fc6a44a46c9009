// ST unit-test execution.
#include "test_files.hpp"

#include "common/duration.hpp"

namespace plcfi::testing {

std::vector<TestResult> run_tests(const st::Application& app, st::Machine& m, const TestRunOptions& opt) {
  std::vector<TestResult> out;
  m.set_budget(opt.budget);
  for (const auto& t : app.tests) {
    TestResult r;
    r.file = t.loc.file < app.file_paths.size() ? app.file_paths[t.loc.file] : "";
    r.name = t.name;
    r.loc = t.loc;
    if (opt.filter && !opt.filter->selects(r.file, r.name)) continue;
    const bool restarted = m.cold_restart();
    bool ok = restarted;
    m.set_now(0);
    auto trapped = [&](const char* what) {
      const st::Trap& tr = m.trap();
      r.where = app.where(tr.loc);
      // The result is shown after its location (r.where); SETUP and TEARDOWN say which
      // phase the trap came from.
      r.message = tr.kind == st::TrapKind::AssertFailed ? tr.message
                  : what                                 ? std::string(what) + ": " + st::describe_trap_kind(tr)
                                                         : st::describe_trap_kind(tr);
    };
    if (!ok) trapped("in FB_init/FB_exit at the restart");
    auto phase = [&](uint32_t entry, const char* what) {
      if (!m.call(entry, t.instance_addr)) {
        trapped(what);
        return false;
      }
      return true;
    };
    if (ok && t.has_init) ok = phase(t.init_entry, "in FB_init");
    if (ok && t.has_setup) ok = phase(t.setup_entry, "in SETUP");
    if (ok) ok = phase(t.body_entry, nullptr);
    if (ok && opt.test_timeout_ns > 0 && m.now() > opt.test_timeout_ns) {
      ok = false;
      r.where = app.where(t.loc);
      r.message = "advanced the clock by " + common::format_duration(m.now()) + ", beyond the per-test time-out (" +
                  common::format_duration(opt.test_timeout_ns) + ")";
    }
    r.seconds = static_cast<double>(m.now()) / 1e9;
    if (t.has_teardown && restarted) {
      bool td = phase(t.teardown_entry, "in TEARDOWN");
      if (ok && !td) ok = false;
    }
    if (t.has_exit && restarted) {
      if (ok) ok = phase(t.exit_entry, "in FB_exit");
      else (void)m.call(t.exit_entry, t.instance_addr);  // the first failure is the one reported
    }
    m.merge_coverage();
    m.clear_taken();
    r.passed = ok;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace plcfi::testing
