// Each front end's results as the one test model (model.hpp), with locations in the files
// the user wrote (a .TcPOU, a PLCopen .xml: Build::sm maps them back).
#pragma once

#include <vector>

#include "engine.hpp"
#include "fb_assert.hpp"
#include "model.hpp"
#include "tcunit.hpp"
#include "test_files.hpp"

namespace plcfi::testing {

// One suite per test file, in the order the tests ran.
std::vector<TestSuite> test_file_suites(const std::vector<TestResult>& results);
// One suite per TcUnit suite instance; its notes say why it has no tests.
std::vector<TestSuite> tcunit_suites(const TcUnitReport& rep, const st::Build& b);
// One suite per FB_ASSERT unit, in the order the units first logged; a case per entry.
std::vector<TestSuite> fb_assert_suites(const UntilReport& rep, const st::Build& b);

// The tests a run would run, without running them (--list): SUITE/TEST per line.
std::vector<std::string> list_test_files(const st::Application& app, const Filter& f);
// TcUnit's tests are registered by the TEST calls as the suites run: those naming a
// literal in a suite's body and methods (TEST, TEST_ORDERED), per suite instance.
std::vector<std::string> list_tcunit(const st::Build& b, const Filter& f);

}  // namespace plcfi::testing
