// A CPTest+ script's run rendered: its text report, its logs (text and CSV), its test in
// the test model (what --junit writes) and the history table of `plcfi history`.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "script/cpt.hpp"
#include "script/history.hpp"
#include "script/runner.hpp"
#include "testing/model.hpp"

namespace plcfi::report {

// The run's report: the verdict with its duration on the scan clock, the assertions that
// waited through a communication error, and why the run did not pass.
std::string script_run_text(const script::Script& s, const script::ScriptResult& r, const std::vector<std::string>& pous,
                            const script::RunOptions& ro, uint64_t failed_exchanges);

// The log of a run as text: every command, LOG line and snapshot, with the scan clock.
std::string script_text_log(const script::ScriptResult& r);

// The snapshots as CSV, one row each, to plot the variables around a failed assertion.
std::string script_csv_log(const script::ScriptResult& r);

// A script as a suite of one test in the test model, named as --filter and --list name it.
testing::TestSuite script_suite(const script::Script& s, const std::vector<std::pair<std::string, std::string>>& run_props);

// Its test after the run: the verdict (undecidable: neither a pass nor a failure of the
// program), why it did not pass, its duration on the scan clock, m_ci and p_lst.
testing::TestCase script_case(const script::Script& s, const script::ScriptResult& r, const script::HistoryRow& row,
                              int64_t p_lst);

// `plcfi history`: one row per recorded run, newest first as given.
std::string history_table(const std::vector<script::HistoryRow>& rows);

}  // namespace plcfi::report
