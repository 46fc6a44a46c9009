// ST unit-test execution.
#include "test_runner.hpp"

#include <chrono>

namespace plcfi::st {

std::vector<TestResult> run_tests(const Application& app, Machine& m, const TestRunOptions& opt) {
  std::vector<TestResult> out;
  m.set_budget(opt.budget);
  for (const auto& t : app.tests) {
    TestResult r;
    r.file = t.loc.file < app.file_paths.size() ? app.file_paths[t.loc.file] : "";
    r.name = t.name;
    r.loc = t.loc;
    auto start = std::chrono::steady_clock::now();
    const bool restarted = m.cold_restart();
    bool ok = restarted;
    m.set_now(0);
    auto trapped = [&](const char* what) {
      const Trap& tr = m.trap();
      r.where = app.where(tr.loc);
      // The result is shown after its location (r.where); SETUP and TEARDOWN say which
      // phase the trap came from.
      r.message = tr.kind == TrapKind::AssertFailed ? tr.message
                  : what                             ? std::string(what) + ": " + describe_trap_kind(tr)
                                                     : describe_trap_kind(tr);
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
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace plcfi::st
