// Runs a bound CPTest+ script against the live program: the program keeps scanning while
// the script waits, commands act on the program's variables between two scans, and
// ASSERT_COM re-checks through a communication error and weighs the wait with m_ci.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "runtime/realtime.hpp"
#include "runtime/runtime.hpp"
#include "script/bind.hpp"
#include "script/mci.hpp"

namespace plcfi::script {

struct RunOptions {
  MciParams mci;
  // How long ASSERT_COM re-checks a failed condition while communication is disturbed.
  int64_t max_wait_ns = 1'000'000'000;
  // Passes among the latest psi runs of this test since its POUs last changed (history).
  int64_t p_lst = 0;
  // SIGINT/SIGTERM: the run ends at the next scan, undecidable.
  const rt::StopSignals* signals = nullptr;
  // One scan; the default is Runtime::scan() (virtual time). A bench run paces it and
  // watches its devices; returning false ends the run with *why as the reason.
  std::function<bool(rt::Runtime&, std::string* why)> scan;
  // The scan-clock time the run may take (0: no limit): a run that needs a scan beyond it
  // ends Failed with time_limit_reason (plcfi script's --test-timeout and --timeout).
  int64_t time_limit_ns = 0;
  std::string time_limit_reason;
};

struct LogEntry {
  enum class Kind : uint8_t { Command, Log, Snapshot, Verdict };
  Kind kind = Kind::Command;
  int64_t t_ns = 0;     // scan clock
  uint64_t scan = 0;    // scans since the run started
  uint32_t line = 0;    // script line (0: none)
  std::string text;
  int snapshot = -1;    // Snapshot: index into ScriptResult::snapshots
};

struct AssertOutcome {
  uint32_t line = 0;
  std::string where;      // "line 8 (06)"

  std::string text;       // the command as written
  bool com = false;       // ASSERT_COM
  bool held = false;      // the condition held in the end (at once or after waiting)
  bool waited = false;    // ASSERT_COM re-checked through a communication error
  bool comm_error = false;
  int64_t cycles = 0;     // c: task cycles waited until it held (never held: waited + 1)
  bool has_mci = false;
  double mci = 0.0;
  Verdict verdict = Verdict::Passed;
  std::string actual;     // the variable's value when decided
};

struct ScriptResult {
  std::string test;
  Verdict verdict = Verdict::Passed;
  std::string reason;  // why a run that did not pass ended
  std::vector<AssertOutcome> asserts;
  std::vector<LogEntry> log;
  std::vector<std::string> snapshot_paths;
  std::vector<std::vector<std::string>> snapshots;  // per snapshot, values in snapshot_paths order
  int64_t end_ns = 0;
  uint64_t scans = 0;
};

// The variables a snapshot records: globals and the program instances' variables, down
// through structures and FB instances, as paths (at most `limit`).
std::vector<st::VarHandle> snapshot_variables(const st::Application& app, size_t limit = 2000);

// Runs s (bound to rt's application) from rt's current state; the caller restarts the
// runtime before (a cold restart: every test run starts from the initial state).
ScriptResult run_script(rt::Runtime& rt, const BoundScript& s, const RunOptions& opt);

}  // namespace plcfi::script
