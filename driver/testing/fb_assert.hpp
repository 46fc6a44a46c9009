// Runs unit tests written in the assertion-FB style (FB_ASSERT, st/stdlib/tcunit.cpp):
// the schedule's programs scan in virtual time (testing/scan.hpp) until a condition holds
// (typically the test FBs' `bDone OR bError`) or the time-out, then the assertions' log is
// read. Each unit's state machine (Assert.State) is followed: a state is a step of the test,
// its duration is reported with its entries, and --test-timeout bounds it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "filter.hpp"
#include "runtime/schedule.hpp"
#include "vm/vm.hpp"

namespace plcfi::testing {

// One entry of FB_ASSERT's log: a failed assertion, or a passed one (LogPassed,
// PrintPassed), or a state that outlasted --test-timeout.
struct AssertLogEntry {
  std::string unit;      // the name its FB_ASSERT got through FB_init ('FB_Foo')
  int64_t state = 0;     // Assert.State when it was evaluated
  bool passed = false;
  std::string message;   // "EXP: 5, ACT: 4, MSG: ..."
  st::SourceLoc where;   // the assertion (not valid for none)
  double seconds = 0;    // how long the unit was in that state (its last stay), virtual time
};

struct UntilReport {
  bool reached = false;      // the condition held
  uint64_t cycles = 0;
  int64_t virtual_ns = 0;
  std::string program_trap;  // a trap (in a program or in FB_init) ended the run
  std::vector<AssertLogEntry> log;
  bool overflow = false;     // more entries were due than the log holds (500)
  int64_t checks = 0;        // assertions evaluated
  int64_t failures = 0;      // of them failed (repeats included)
  int64_t timeouts = 0;      // states that outlasted --test-timeout
};

struct UntilOptions {
  int64_t timeout_ns = 10'000'000'000;
  int64_t test_timeout_ns = 0;   // a unit staying longer in one state fails there (0: no bound)
  uint64_t budget = 10'000'000;  // loop iterations per call (watchdog)
  const Filter* filter = nullptr;  // entries of units (suites) / states (tests) not selected are dropped
};

// True when the application holds the FB_ASSERT library.
bool has_fb_assert(const st::Application& app);

// The units under test (the names FB_init gives the FB_ASSERT instances), as a cold
// restart of m leaves them, without a scan: what --list shows. Empty with *trap set when
// FB_init trapped.
std::vector<std::string> fb_assert_units(const st::Application& app, st::Machine& m, std::string* trap);

// Runs machine m (cold-restarted first) until the BOOL at `reached` (an output of the
// observer program `until`, called after every cycle's programs) is TRUE.
UntilReport run_until(const st::Application& app, const rt::Schedule& schedule, st::Machine& m,
                      const st::ProgramInstance& until, uint32_t reached, const UntilOptions& opt);

}  // namespace plcfi::testing
