// A self-contained HTML report of a fault-injection campaign: one index.html with inline
// CSS and inline SVG (verdict table, the waveform of each test window read from its VCD,
// the timing sequence diagrams, FMEA suggestions, mutants, safety evidence). The model below is plain
// data so that any producer (the campaign, exploration, mutation analysis) can fill it;
// the report layer knows nothing of driver/campaign.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "report/safety.hpp"

namespace plcfi::report {

enum class HtmlVerdict { Pass, Fail, NotReached, NotTested };
const char* html_verdict_name(HtmlVerdict v);  // "PASS", "FAIL", "NOT REACHED", "NOT TESTED"

// What the page starts with. No dates or wall-clock times: the same campaign gives the
// same bytes.
struct HtmlHeader {
  std::string name, text;
  std::string title;  // the page's heading; empty: "Campaign <name>"
  std::vector<std::string> programs;
  std::string plant;
  uint64_t seed = 0;
  std::string end_reason;
  size_t cases = 0, executions = 0, pass = 0, fail = 0, not_reached = 0, not_tested = 0;
  // Further facts shown as "key: value" lines in this order (runs, scan-clock time, ...).
  std::vector<std::pair<std::string, std::string>> facts;
};

// One line of the verdict table: an execution of a case on a path, or a case that never
// ran (path 0: NOT REACHED, NOT TESTED).
struct HtmlRow {
  std::string case_id;
  int path = 0;
  HtmlVerdict verdict = HtmlVerdict::Fail;
  int rpn = 0;
  std::string class_id, class_name;
  std::string transition;    // scenario.step.lifeline
  std::string fmea_id;       // empty for generated cases
  std::string failure_mode;
  std::string fault;         // "StampLowered (%IX0.4): stuck (pre-fault value)"
  std::string expected;      // the expected reaction, readable
  int64_t latency_ns = -1;   // -1: none
  std::string reason;
  std::vector<std::string> branches;  // distinguishing branch points (file:line)
  int execution = -1;        // index into HtmlReport::executions; -1: no waveform section
};

// The test window of one execution. Times are on the run's scan clock (the VCD's time).
struct HtmlExecution {
  std::string title;       // "TC3 path 1"
  HtmlVerdict verdict = HtmlVerdict::Fail;
  std::string summary;     // one line under the title (transition, fault)
  std::string vcd;         // path of the trace to read; empty: no trace
  int64_t inject_ns = 0;
  int64_t start_ns = -1;     // -1: the start condition never held
  int64_t deadline_ns = -1;  // start + deadline; -1: unknown
  int64_t reaction_ns = -1;  // -1: no reaction seen
  int64_t end_ns = 0;
  std::string faulted;                // name of the faulted signal in the trace
  std::vector<std::string> alarms;    // names of the alarm signals in the trace
};

// The timing sequence diagram, per scenario.
struct HtmlLifeline {
  std::string name, kind;  // kind: sensor, actuator, analog, mode, interface, variable
};

struct HtmlTransition {
  std::string lifeline, from, to;  // from: the value before ("" unknown)
  int64_t min_ns = -1, max_ns = 0;
  double tolerance = 0;
  std::vector<std::string> cases;  // ids of the test cases that fault this transition
};

struct HtmlStep {
  std::string id, text;
  std::vector<std::pair<std::string, std::string>> pre;  // lifeline = value
  std::string condition;  // extra ST condition of the precondition
  std::string start;      // ST expression; empty: the previous transition
  std::vector<HtmlTransition> transitions;
};

struct HtmlScenario {
  std::string id, text;
  std::vector<HtmlStep> steps;
};

// Optional sections, rendered only when not empty.
struct FmeaSuggestion {
  std::string component, failure_mode, effect;
  std::string alarm;  // the alarm that detected it; empty: none
  std::string case_id, transition;
};

enum class MutantStatus { Killed, Survived, Equivalent };
const char* mutant_status_name(MutantStatus s);  // "killed", "survived", "equivalent"

struct MutantRow {
  std::string id;
  std::string location;  // file:line:col
  std::string change;    // "StampLowered AND x -> StampLowered OR x"
  MutantStatus status = MutantStatus::Survived;
  std::string killed_by;  // case id
  std::string reason;
};

struct HtmlReport {
  HtmlHeader header;
  std::vector<HtmlRow> rows;  // shown in this order
  std::vector<HtmlExecution> executions;
  std::string waveform_note;  // shown instead of the waveforms when not empty (e.g. traces off)
  std::string tsd_path;
  std::vector<HtmlLifeline> lifelines;
  std::vector<HtmlScenario> scenarios;
  std::vector<FmeaSuggestion> suggestions;
  std::vector<MutantRow> mutants;
  // The safety evidence (an FMEA with failure rates): per safety function, the
  // traceability matrix and the fingerprint; none: no section.
  std::optional<SafetyReport> safety;
};

// The page as text. Every string of the model is HTML-escaped; traces that cannot be read
// are named with their error in the page instead of a waveform.
std::string html_report(const HtmlReport& r);

// Writes DIR/index.html (creating DIR). False with "PATH: reason" in *err when it cannot.
bool write_html_report(const HtmlReport& r, const std::string& dir, std::string* err);

// Creates DIR and checks that a report can be written there (false, "DIR: reason"); run
// before a long campaign, so that a bad --html folder is refused at once.
bool html_dir_writable(const std::string& dir, std::string* err);

// One waveform as an SVG element (exposed for tests). Reads exec.vcd; on a read error
// returns false with the message in *err.
bool waveform_svg(const HtmlExecution& exec, std::string* svg, std::string* err);

// HTML escaping of text and attribute values (& < > " ').
std::string html_escape(const std::string& s);

}  // namespace plcfi::report
