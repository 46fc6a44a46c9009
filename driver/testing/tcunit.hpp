// Runs TcUnit test suites (FUNCTION_BLOCKs that EXTEND FB_TestSuite, see
// st/stdlib/tcunit.cpp) the way TcUnit does on a PLC: the schedule's programs scan in
// virtual time; after each scan in which TcUnit.RUN() was called, the body of every suite
// instance not yet done is called once (RUN_IN_SEQUENCE: one suite after the other),
// until every test is finished or disabled, or the time-out.
//
// TcUnit's rules, which the runner applies to the library's calls (stdlib/tcunit_abi.hpp):
// - TEST('name') registers a test (trimmed) on its first call; a name starting with
//   DISABLED_ (any case) registers a disabled test without that prefix, whose assertions
//   are ignored. A second TEST of a registered name in the same cycle is a duplicate: its
//   assertions are ignored and TcUnit's error names it once.
// - Every failed assertion of a test is reported, with TcUnit's words. An assertion is
//   identified by its EXP and ACT (for arrays: their sizes), message and test; when the same
//   one runs again in a later cycle it is not reported again, unless it runs more often in
//   that cycle than in the cycle before.
// - Assertions after TEST_FINISHED() (or before any TEST, or of a test that is not this
//   ordered test's turn) are ignored. A test's number of assertions is the count of
//   distinct ones, taken when it finishes.
// - A suite is done when every test is finished or disabled; a suite without tests after
//   its first call.
// - GVL_Param_TcUnit's MaxNumberOfTestsForEachTestSuite and MaxNumberOfAssertsForEachTestSuite
//   bound what a suite keeps, with TcUnit's errors when exceeded.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "filter.hpp"
#include "runtime/schedule.hpp"
#include "vm/vm.hpp"

namespace plcfi::testing {

// A failed assertion as TcUnit reports it.
struct TcUnitFailure {
  std::string line;        // FAILED TEST 'PRG_TEST.inst@Test', EXP: 5, ACT: 6, MSG: ...
  st::SourceLoc where;     // the assertion (not valid: no location)
};

struct TcUnitTest {
  std::string name;
  bool finished = false;
  bool disabled = false;   // DISABLED_...: not run, counted apart
  bool failed = false;     // an assertion failed, or plcfi's reason below
  std::vector<TcUnitFailure> failures;  // every reported failed assertion, in order
  std::string message;     // TcUnit's failure message: the first non-empty assertion message
  std::string type;        // TcUnit's assertion type of the first failure (INT, Array_REAL, ...)
  std::string problem;     // plcfi's reason: a runtime error, not finished by the time-out
  st::SourceLoc problem_at;
  uint32_t asserts = 0;    // distinct assertions, taken when it finished
  double seconds = 0;      // from its first TEST call to TEST_FINISHED, in virtual time
};

struct TcUnitSuite {
  std::string path;        // instance path: PRG_TEST.fbSumTest
  const st::PouInfo* type = nullptr;
  std::vector<TcUnitTest> tests;
  uint32_t registered = 0;  // tests its TESTs named, beyond the ones kept when over the maximum
  bool started = false;    // its body was called (RUN_IN_SEQUENCE starts one after the other)
  uint32_t filtered = 0;   // tests --filter did not select (run, not reported)
  double seconds = 0;      // from its first call to its last test's end
};

struct TcUnitLogLine {
  std::string level;       // "error", "warn", "hint"
  std::string text;
};

struct TcUnitReport {
  std::vector<TcUnitSuite> suites;
  std::vector<TcUnitLogLine> log;  // TcUnit's messages in order: failures, errors, TCUNIT_ADSLOGSTR
  bool run_called = false;   // RUN() or RUN_IN_SEQUENCE() was called at least once
  bool timed_out = false;
  bool aborted = false;      // TEST_FINISHED_NAMED of a test that does not exist stopped TcUnit
  uint32_t own_errors = 0;   // TcUnit's own errors in the log (a name twice, too many assertions, ...)
  uint64_t cycles = 0;
  int64_t virtual_ns = 0;
  double seconds = 0;        // from the first RUN to the end, in virtual time
  std::string program_trap;  // a trap in the scanned programs ended the run
  uint32_t max_tests = 100;  // GVL_Param_TcUnit's values used
  uint32_t max_asserts = 1000;
};

struct TcUnitOptions {
  int64_t timeout_ns = 10'000'000'000;  // plcfi's bound on the run (TcUnit has none)
  int64_t test_timeout_ns = 0;          // a test not finished this long after its start fails (0: none)
  uint64_t budget = 10'000'000;         // loop iterations per call (watchdog)
  const Filter* filter = nullptr;       // tests not selected run (TcUnit calls them) but are not reported
};

// True when the application holds at least one TcUnit suite instance.
bool has_tcunit_suites(const st::Application& app);
// Every suite instance: its path and type, in the order TcUnit runs them.
std::vector<std::pair<std::string, const st::PouInfo*>> tcunit_suite_instances(const st::Application& app);

// Runs the suites on machine m (cold-restarted first). Traps in a suite fail its current
// test and stop that suite; a trap in a scanned program stops the run.
TcUnitReport run_tcunit(const st::Application& app, const rt::Schedule& schedule, st::Machine& m, const TcUnitOptions& opt);

}  // namespace plcfi::testing
