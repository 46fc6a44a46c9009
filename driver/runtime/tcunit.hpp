// Runs TcUnit test suites (FUNCTION_BLOCKs that EXTEND FB_TestSuite, see
// st/stdlib/tcunit.cpp) the way TcUnit does on a PLC: the schedule's programs scan in
// virtual time; after each scan in which TcUnit.RUN() was called, the body of every suite
// instance not yet done is called once (RUN_IN_SEQUENCE: one suite after the other),
// until every test called TEST_FINISHED or the time-out.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "schedule.hpp"
#include "vm/vm.hpp"

namespace plcfi::rt {

struct TcUnitTest {
  std::string name;
  bool finished = false;
  bool failed = false;     // an assertion failed, the name is used twice, or a runtime error
  std::string message;     // TcUnit's words: "EXP: 5, ACT: 6, MSG: ..."
  st::SourceLoc where;     // the failed assertion (not valid: no location, e.g. a time-out)
};

struct TcUnitSuite {
  std::string path;        // instance path: PRG_TEST.fbSumTest
  const st::PouInfo* type = nullptr;
  std::vector<TcUnitTest> tests;
  bool overflow = false;   // more TESTs than a suite holds (100)
  bool started = false;    // its body was called (RUN_IN_SEQUENCE starts one after the other)
};

struct TcUnitReport {
  std::vector<TcUnitSuite> suites;
  bool run_called = false;   // RUN() or RUN_IN_SEQUENCE() was called at least once
  bool timed_out = false;
  uint64_t cycles = 0;
  int64_t virtual_ns = 0;
  std::string program_trap;  // a trap in the scanned programs ended the run
};

struct TcUnitOptions {
  int64_t timeout_ns = 10'000'000'000;  // TcUnit's default time-out: 10 s
  uint64_t budget = 10'000'000;         // loop iterations per call (watchdog)
};

// True when the application holds at least one TcUnit suite instance.
bool has_tcunit_suites(const st::Application& app);

// Runs the suites on machine m (cold-restarted first). Traps in a suite fail its current
// test and stop that suite; a trap in a scanned program stops the run.
TcUnitReport run_tcunit(const st::Application& app, const Schedule& schedule, st::Machine& m, const TcUnitOptions& opt);

}  // namespace plcfi::rt
