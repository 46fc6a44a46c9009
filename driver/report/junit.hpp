// JUnit XML writer (the format CI servers and test dashboards read).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace plcfi::report {

struct JunitCase {
  std::string classname;
  std::string name;
  double seconds = 0;
  enum class Outcome { Pass, Fail, Skipped, Error } outcome = Outcome::Pass;
  std::string message;  // failure/skip message (attribute)
  std::string detail;   // element text
  std::vector<std::pair<std::string, std::string>> properties;
};

struct JunitSuite {
  std::string name;
  std::vector<JunitCase> cases;
  std::vector<std::pair<std::string, std::string>> properties;  // of the whole run (e.g. real-time statistics)
};

// A scan cycle run by `plcfi run --io/--realtime`: one test case, failed when the run did.
struct ScanRunFacts {
  std::string name;  // "scan cycle" or "scan cycle on IO.yaml"
  double seconds = 0;
  bool failed = false;
  std::string ended;  // why the run ended
  uint64_t scans = 0;
  std::vector<std::pair<std::string, std::string>> realtime;  // the pacer's figures
  std::vector<std::string> io_report;                          // the devices' lines
};
JunitSuite scan_run_junit(const ScanRunFacts& run);

std::string junit_xml(const std::vector<JunitSuite>& suites);
// Writes atomically (temporary file + rename). Returns false and fills err on failure.
bool write_junit(const std::string& path, const std::vector<JunitSuite>& suites, std::string* err);
std::string xml_escape(const std::string& s);

// Writes text to path atomically (a temporary file, then a rename).
bool write_file_atomically(const std::string& path, const std::string& text, std::string* err);

}  // namespace plcfi::report
