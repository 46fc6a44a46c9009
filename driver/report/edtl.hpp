// EDTL verdicts (plcfi edtl check) as JUnit: one test case per requirement.
#pragma once

#include <string>
#include <vector>

#include "monitor/edtl.hpp"
#include "report/junit.hpp"

namespace plcfi::report {

// A violated requirement fails with its first violation as the message and the verdict's
// text as the detail; triggers, pending instances and severity are properties.
JunitSuite edtl_junit(const std::string& suite, const std::vector<monitor::Verdict>& verdicts);

}  // namespace plcfi::report
