// The one scan loop of the test front ends that run on the program's scan (TcUnit,
// FB_ASSERT): the schedule's programs scan in virtual time; after each scan the front end
// (a ScanTest) looks at the program and says whether the run goes on. The loop owns the
// clock, the time-out, coverage and a trap in the programs; the front end writes one
// after_scan().
#pragma once

#include <cstdint>
#include <string>

#include "runtime/schedule.hpp"
#include "vm/vm.hpp"

namespace plcfi::testing {

class ScanTest {
 public:
  virtual ~ScanTest() = default;
  // After the programs of scan `cycle` (0-based) ran at `now_ns`. False: the run is over.
  virtual bool after_scan(st::Machine& m, uint64_t cycle, int64_t now_ns) = 0;
};

struct ScanRun {
  uint64_t cycles = 0;
  int64_t virtual_ns = 0;
  bool timed_out = false;    // the time-out ended the run
  std::string program_trap;  // a trap in a program (or in FB_init at the restart) ended it
};

// Cold-restarts m, then scans until t says so, a program traps or timeout_ns of virtual
// time passed. `budget`: loop iterations per call (the watchdog).
ScanRun run_scans(const st::Application& app, const rt::Schedule& schedule, st::Machine& m, ScanTest& t,
                  int64_t timeout_ns, uint64_t budget);

}  // namespace plcfi::testing
