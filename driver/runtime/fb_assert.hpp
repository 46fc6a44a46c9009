// Runs unit tests written in the assertion-FB style (FB_ASSERT, st/stdlib/tcunit.cpp):
// the schedule's programs scan in virtual time until a condition holds (typically the test
// FBs' `bDone OR bError`) or the time-out, then the assertions' log is read.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "schedule.hpp"
#include "vm/vm.hpp"

namespace plcfi::rt {

// One entry of FB_ASSERT's log: a failed assertion, or a passed one (PrintPassed).
struct AssertLogEntry {
  std::string unit;      // the name its FB_ASSERT got through FB_init ('FB_Foo')
  int64_t state = 0;     // Assert.State when it was evaluated
  bool passed = false;
  std::string message;   // "EXP: 5, ACT: 4, MSG: ..."
  st::SourceLoc where;   // the assertion (not valid for none)
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
};

struct UntilOptions {
  int64_t timeout_ns = 10'000'000'000;
  uint64_t budget = 10'000'000;  // loop iterations per call (watchdog)
};

// True when the application holds the FB_ASSERT library.
bool has_fb_assert(const st::Application& app);

// Runs machine m (cold-restarted first) until the BOOL at `reached` (an output of the
// observer program `until`, called after every cycle's programs) is TRUE.
UntilReport run_until(const st::Application& app, const Schedule& schedule, st::Machine& m,
                      const st::ProgramInstance& until, uint32_t reached, const UntilOptions& opt);

}  // namespace plcfi::rt
