// Runs the TESTs of ST test files (the STruC++ format): each test on a cold-restarted
// machine with the scan clock at zero; SETUP before, TEARDOWN after (also after a failure).
#pragma once

#include <string>
#include <vector>

#include "engine.hpp"
#include "filter.hpp"

namespace plcfi::testing {

struct TestResult {
  std::string file;   // the test file's path (its suite)
  std::string name;
  st::SourceLoc loc;  // the TEST
  bool passed = false;
  std::string where;  // file:line:col of the failure
  std::string message;
  double seconds = 0;  // the virtual time the test advanced (ADVANCE_TIME)
};

struct TestRunOptions {
  uint64_t budget = 100'000'000;  // loop iterations per test phase before a watchdog trap
  // A test that advanced the clock further than this fails (checked when it returns; the
  // watchdog stops one that never does). 0: no bound.
  int64_t test_timeout_ns = 0;
  const Filter* filter = nullptr;  // tests not selected are not run
};

std::vector<TestResult> run_tests(const st::Application& app, st::Machine& m, const TestRunOptions& opt);

}  // namespace plcfi::testing
