// The reports of a unit-test run (testing/model.hpp), whatever front end filled it: the
// text listing, JUnit XML and the xUnit file TcUnit publishes.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "junit.hpp"
#include "testing/model.hpp"
#include "testing/tcunit.hpp"

namespace plcfi::report {

// [heading] per suite, a line per test (PASS/FAIL/DISABLED/UNDECIDABLE: name (duration)),
// each finding of a failed test under it, the suite's notes.
void print_tests(std::ostream& out, const std::vector<testing::TestSuite>& suites);
// "3 passed, 1 failed" (+ ", 2 disabled", ", 1 undecidable" when there are).
std::string totals_line(const testing::Totals& t);
// A duration as the listing shows it: 0s, 20ms, 1s500ms.
std::string test_duration(double seconds);

// What TcUnit prints besides the tests (print_tests shows those): its own messages and
// the program's (TCUNIT_ADSLOGSTR, ADSLOGSTR) in order, its errors, its extended results
// when asked, its summary. False when TcUnit reported an error of its own (a test name
// used twice, more tests or assertions than GVL_Param_TcUnit allows, TcUnit stopped).
bool print_tcunit_summary(std::ostream& out, const testing::TcUnitReport& rep, bool extended);
// TcUnit's text of a number of seconds (LREAL_TO_STRING with a decimal point: 0.0, 0.01).
std::string tcunit_seconds(double s);

std::vector<JunitSuite> junit_suites(const std::vector<testing::TestSuite>& suites);
bool write_test_junit(const std::string& path, const std::vector<testing::TestSuite>& suites, std::string* err);

// TcUnit's xUnit file: <testsuites> with failures, tests (TcUnit counts its successful
// ones) and time; a <testsuite> per suite (id, name, tests, failures, time); a <testcase>
// per test (name, classname, time, status PASS/FAIL/SKIP) with <failure message type> when
// it failed (the case's properties "message" and "type": TcUnit's failure message and
// assertion type). `seconds`: the whole run.
std::string tcunit_xunit_xml(const std::vector<testing::TestSuite>& suites, double seconds);
bool write_tcunit_xunit(const std::string& path, const std::vector<testing::TestSuite>& suites, double seconds,
                        std::string* err);

}  // namespace plcfi::report
