// Runs the TESTs of a test build: each test on a cold-restarted machine with the scan
// clock at zero; SETUP before, TEARDOWN after (also after a failure).
#pragma once

#include <string>
#include <vector>

#include "engine.hpp"

namespace plcfi::st {

struct TestResult {
  std::string file;   // the test file's path
  std::string name;
  SourceLoc loc;      // the TEST
  bool passed = false;
  std::string where;  // file:line:col of the failure
  std::string message;
  double seconds = 0;
};

struct TestRunOptions {
  uint64_t budget = 100'000'000;  // loop iterations per test phase before a watchdog trap
};

std::vector<TestResult> run_tests(const Application& app, Machine& m, const TestRunOptions& opt);

}  // namespace plcfi::st
