// The one model of a unit-test run, which every test front end fills (ST test files,
// TcUnit suites, FB_ASSERT units, CPTest+ scripts) and report/tests renders (text, JUnit,
// TcUnit's xUnit). Plain data: no dependency on how the tests ran.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace plcfi::testing {

enum class Verdict {
  Pass,
  Fail,
  Disabled,     // not run on purpose (TcUnit's DISABLED_): counted apart
  Undecidable,  // the communication, not the program, failed (CPTest+): counted apart
};

// A reported assertion or problem of a test: "file:line:col" (may be empty) and the text.
struct Finding {
  std::string where;
  std::string text;
};

struct TestCase {
  std::string name;
  Verdict verdict = Verdict::Pass;
  std::vector<Finding> findings;  // shown under a failed test, in order
  std::string note;               // shown after the name of a passed test (FB_ASSERT's passed entries)
  double seconds = 0;             // the test's duration (virtual time where the run is virtual)
  // Extra facts for the reports (JUnit properties; TcUnit's xUnit reads "message", "type").
  std::vector<std::pair<std::string, std::string>> properties;

  // The first finding, as one line: a failure's summary.
  std::string summary() const {
    if (findings.empty()) return "";
    const Finding& f = findings.front();
    return f.where.empty() ? f.text : f.where + ": " + f.text;
  }
};

struct TestSuite {
  std::string name;     // a test file, a TcUnit suite instance (PRG_TEST.fbTest), an FB_ASSERT unit, a script
  std::string heading;  // what the text report shows in brackets (the name by default)
  std::vector<TestCase> cases;
  std::vector<std::string> notes;  // lines shown under the suite's tests (e.g. "(no tests)")
  double seconds = 0;
  std::vector<std::pair<std::string, std::string>> properties;
};

struct Totals {
  size_t passed = 0, failed = 0, disabled = 0, undecidable = 0;
  size_t all() const { return passed + failed + disabled + undecidable; }
};

inline Totals totals(const std::vector<TestSuite>& suites) {
  Totals t;
  for (const auto& s : suites)
    for (const auto& c : s.cases) switch (c.verdict) {
        case Verdict::Pass: ++t.passed; break;
        case Verdict::Fail: ++t.failed; break;
        case Verdict::Disabled: ++t.disabled; break;
        case Verdict::Undecidable: ++t.undecidable; break;
      }
  return t;
}

}  // namespace plcfi::testing
