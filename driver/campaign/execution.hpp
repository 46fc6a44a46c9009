// What one test execution and the campaign's progress are: the records the driver
// produces and the journal writes and reads back. A header of its own so that the driver
// and the journal both use it without depending on each other.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace plcfi::campaign {

enum class Outcome { Pass, Fail, NotReached };
const char* outcome_name(Outcome o);

// One execution of a test case on one control-flow path.
struct Execution {
  std::string case_id;
  size_t case_index = 0;
  int path = 1;                    // 1, 2, ... in the order the paths were met
  uint64_t path_hash = 0;          // of the program's branch ids taken in the injection scan
  std::vector<uint32_t> branches;  // those branch ids
  Outcome outcome = Outcome::Fail;
  std::string reason;              // why FAIL; what was seen for PASS
  uint64_t run = 0;                // run index (0-based); the run's seed is campaign seed + run
  int64_t inject_ns = 0;           // times on the run's scan clock
  int64_t start_ns = -1;           // the start condition first held (-1: never)
  int64_t reaction_ns = -1;        // every class requirement met (-1: never)
  int64_t end_ns = 0;
  int64_t latency_ns = -1;         // reaction - start
  std::string vcd;                 // trace of the test window (file name in the output folder)
};

// One run of a campaign as a worker process or a shard saw it (parallel.hpp). A process
// running a share of the runs searches in every run (which case a run injects does not
// depend on earlier tests' outcomes) but tests only its own runs; a run of another share
// ends at its injection, with the case claimed.
struct RunRecord {
  enum class Kind { Executed, Claimed, Ended };
  Kind kind = Kind::Ended;
  uint64_t run = 0;
  Execution exec;            // Executed: the execution; Claimed: case, path, hash, branches, inject_ns
  std::string line;          // Executed: its journal line, with campaign_ns and scans still 0
  uint64_t scans = 0;        // scans of the run as this process ran it
  int64_t ns = 0;            // their scan-clock time
  uint64_t inject_scan = 0;  // the scan (1-based) whose before_scan injected or claimed; 0: none
  std::string end;           // Ended: "window", "budget" or "stopped: <reason>"
};

struct Progress {
  uint64_t run = 0, scans = 0;
  int64_t campaign_ns = 0;  // scan-clock time used, all runs
  size_t executions = 0, pass = 0, fail = 0;
  size_t cases_tested = 0, cases = 0;
};

}  // namespace plcfi::campaign
