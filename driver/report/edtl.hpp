// EDTL verdicts (plcfi edtl check, plcfi sim --requirements) as text and as JUnit.
#pragma once

#include <string>
#include <vector>

#include "monitor/edtl.hpp"
#include "report/junit.hpp"

namespace plcfi::report {

// Per requirement: SATISFIED or VIOLATED, its counts and its violations (the first
// kMaxListed), then the totals line.
std::string edtl_verdicts_text(const std::vector<monitor::Verdict>& verdicts);

// JUnit, one test case per requirement. A violated requirement fails with its first violation as the message and the verdict's
// text as the detail; triggers, pending instances and severity are properties.
JunitSuite edtl_junit(const std::string& suite, const std::vector<monitor::Verdict>& verdicts);

}  // namespace plcfi::report
