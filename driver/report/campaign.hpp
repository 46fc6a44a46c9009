// A campaign's result rendered as text, JUnit and PlantUML: the listing of `generate`, the
// verdict table and totals of `campaign`, the FMEA suggestions, the changes since a
// baseline. The commands print what these return; the HTML model is in campaign_html.hpp.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "campaign/driver.hpp"
#include "campaign/explore.hpp"
#include "campaign/generate.hpp"
#include "report/junit.hpp"
#include "report/puml.hpp"
#include "report/safety.hpp"

namespace plcfi::report {

// "Name (address): fault", as in the tables and the JUnit detail.
std::string campaign_fault_text(const campaign::TestCase& tc);

// `plcfi generate`: the header, one row per case, then each case's precondition, start,
// expected reaction and forbidden changes.
std::string campaign_cases_text(const campaign::CampaignBuild& cb);

// The sequence and timing diagrams' facts for one case.
PumlCase campaign_puml_case(const campaign::CampaignBuild& cb, const campaign::TestCase& tc);

// The verdict table: the executions by case and path, then the cases NOT REACHED and NOT
// TESTED. *fail is the number of executions that did not pass.
std::string campaign_verdict_table(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res, size_t* fail);

// The totals, the run's figures (scans, time, real-time and I/O figures) and where the
// files are (out).
std::string campaign_totals_text(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res,
                                 const std::vector<std::string>& io_report, size_t fail, const std::string& out);

// The explored failures the FMEA misses, listed; csv_path is where they were written.
std::string fmea_suggestions_text(const std::vector<campaign::FmeaSuggestion>& sug, const std::string& csv_path);

// What changed since the baseline folder `old`; *regressions counts the regressions.
std::string baseline_changes_text(const std::vector<BaselineChange>& changes, const std::string& old, size_t* regressions);

// --junit: one suite, the executions, then the cases not tested and not reached; the run's
// figures (io_report: the devices' lines) and the safety evidence as properties.
JunitSuite campaign_junit(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res,
                          const std::vector<std::string>& io_report, const std::optional<SafetyReport>& safety);

}  // namespace plcfi::report
