// Safety evidence from a campaign (issue 30): per safety function of the FMEA, its dangerous
// failure rate, the part the program's diagnostics detected in the campaign (diagnostic
// coverage), the worst detection-plus-reaction time against the classes' safety time, and
// the trace from every FMEA row to its executions and evidence files. A pure function of the
// specs, the generated cases and the verdicts (the journal's content); report/safety.hpp
// renders it.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "campaign/execution.hpp"
#include "campaign/generate.hpp"
#include "report/safety.hpp"

namespace plcfi::campaign {

// The FMEA gives failure rates: the campaign writes its safety evidence.
inline bool wants_safety_evidence(const Campaign& c) { return c.fmea.has_rates; }

// Definitions (the manual: docs/pages/reports/safety.md):
// - a row is detected when it has test cases, none NOT REACHED or left untested, each
//   executed at least once, and every execution PASSED; lambda_DD sums the detected
//   dangerous rows' rates;
// - an execution's reaction time is reaction_ns - inject_ns: from the scan the fault went in
//   to the scan in which every requirement of its class was met;
// - a function's safety time is the shortest safety_time among its dangerous rows' classes.
// `executions` in journal order (line k + 2 of results.jsonl holds executions[k]).
report::SafetyReport safety_evidence(const CampaignBuild& cb, const std::vector<Execution>& executions,
                                     const std::vector<size_t>& not_reached, const std::vector<size_t>& pending,
                                     bool vcd);

// Hashes (FNV-1a 64, common/hash.hpp) of what makes the campaign: every program file, the
// plant (file or built-in name) and its parameters, the campaign, TSD, FMEA, fault-class and
// requirements files, plcfi's version, the seed and the journal's fingerprint.
std::vector<std::pair<std::string, std::string>> campaign_hashes(const CampaignBuild& cb);

}  // namespace plcfi::campaign
