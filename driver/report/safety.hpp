// The safety evidence of a campaign as a model the reports render (safety.json, the text
// summary's section, JUnit properties, traceability.csv, the HTML section), and the
// comparison with an earlier run's safety.json (campaign --baseline). campaign/safety.hpp
// fills the model from the FMEA and the verdicts; nothing here knows a campaign.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace plcfi::report {

// One safety function: the FMEA rows that name it. Rates in FIT (failures per 10^9 h).
struct SafetyFunctionEvidence {
  std::string id;
  std::vector<std::string> rows;                               // every row, in FMEA order
  std::vector<std::pair<std::string, std::string>> undetected;  // dangerous row, why
  double lambda_d = 0;   // sum of the dangerous rows' rates
  double lambda_dd = 0;  // of those, the rows whose every execution PASSED
  double lambda_s = 0;   // sum of the safe rows' rates (dangerous = no)
  bool has_safe = false;  // a safe row exists: the safe failure fraction is given
  // Detection plus reaction: from the injection of the fault to the scan in which every
  // requirement of the class was met, over the dangerous rows' executions that reacted.
  int64_t worst_reaction_ns = -1;  // -1: no execution reacted
  std::string worst_execution;     // "TC5 path 1"
  size_t reacted = 0, unreacted = 0;
  int64_t safety_time_ns = -1;  // the shortest safety_time of the rows' classes; -1: none given

  bool has_dc() const { return lambda_d > 0; }
  double dc() const { return has_dc() ? lambda_dd / lambda_d : 0; }
  // (lambda_S + lambda_DD) / (lambda_S + lambda_D); only meaningful with has_safe.
  double sff() const { return lambda_s + lambda_d > 0 ? (lambda_s + lambda_dd) / (lambda_s + lambda_d) : 0; }
  // IEC 61508-2 bands: "none" below 60 %, "low" from 60 %, "medium" from 90 %, "high" from
  // 99 %; "n/a" without a dangerous rate.
  std::string band() const;
  bool has_margin() const { return safety_time_ns >= 0 && worst_reaction_ns >= 0; }
  int64_t margin_ns() const { return safety_time_ns - worst_reaction_ns; }
};

// A failure the exploration (--explore) found that no FMEA row describes.
struct UnassessedMode {
  std::string case_id, transition, fault, verdict, reason;
  int path = 0;
};

// One verdict, as a later run's --baseline compares it.
struct SafetyExecution {
  std::string case_id, fmea, verdict;
  int path = 0;
  int64_t reaction_ns = -1;  // from the injection; -1: no reaction
};

// One line of the traceability matrix: an FMEA row's case on one path (or the case's
// NOT REACHED / NOT TESTED), with its evidence files relative to the output folder.
struct TraceRow {
  std::string fmea, safety_function, dangerous, failure_mode;  // dangerous: yes, no or ""
  double failure_rate = -1;                                    // < 0: none
  std::string case_id, transition, fault, verdict;
  int path = 0;  // 0: not executed
  int64_t inject_ns = -1, reaction_ns = -1, latency_ns = -1, safety_time_ns = -1;
  size_t journal_line = 0;  // line of the verdict in results.jsonl (1 = the header); 0: none
  std::string vcd, sequence_diagram, timing_diagram;
};

struct SafetyReport {
  std::string campaign;
  // What an assessor needs to reproduce the run: name, hash (or value).
  std::vector<std::pair<std::string, std::string>> fingerprint;
  std::vector<SafetyFunctionEvidence> functions;
  std::vector<UnassessedMode> unassessed;
  std::vector<SafetyExecution> executions;
  std::vector<TraceRow> trace;
};

// OUT/safety.json (indented, keys in a fixed order; times in ms).
std::string safety_json(const SafetyReport& r);
// The "safety evidence" section of the text summary (starts with an empty line).
std::string safety_text(const SafetyReport& r, const std::string& out_dir);
// Suite properties for JUnit: safety.<function>.<key>.
std::vector<std::pair<std::string, std::string>> safety_junit_properties(const SafetyReport& r);
// OUT/traceability.csv: `# name,value` lines with the fingerprint, then a header and one
// record per TraceRow (RFC 4180 quoting).
std::string traceability_csv(const SafetyReport& r);

// Milliseconds as text: "600" when whole, else with the fraction ("0.5").
std::string ms_text(int64_t ns);

// What changed since an earlier run's safety.json (campaign --baseline).
struct BaselineChange {
  std::string what;  // one line, readable
  bool regression = false;
};
// Reads an earlier safety.json (text as read from `path`, for messages). False with
// "PATH: ..." in *err when it is not one.
bool parse_safety_json(const std::string& text, const std::string& path, SafetyReport* out, std::string* err);
// The changes from `before` to `now`: verdicts per case and path, cases that appeared or
// went, DC and band, worst reaction per safety function, unassessed failure modes. A
// regression: a PASS that is no longer one, a lower DC, a longer worst reaction, a new
// undetected row or unassessed failure mode, a safety function gone.
std::vector<BaselineChange> compare_safety(const SafetyReport& before, const SafetyReport& now);

}  // namespace plcfi::report
