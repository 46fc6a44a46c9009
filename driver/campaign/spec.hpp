// The specifications a fault-injection campaign is generated from: the campaign file, the
// timing sequence diagram (TSD), the FMEA table and the fault classes. Loading checks
// everything that can be checked without the program (structure, S/O/D ranges, RPN,
// references between the files); bind_campaign() checks the rest against the compiled
// program. Every error names FILE:LINE:COL.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "monitor/edtl.hpp"

namespace plcfi::campaign {

struct Loc {
  std::string file;
  uint32_t line = 0;  // 1-based; 0 = unknown
  uint32_t col = 0;
  std::string str() const;  // "file:line:col"
};

enum class LifelineKind { Sensor, Actuator, Analog, Mode, Interface, Variable };

struct Lifeline {
  std::string name;
  std::string bind;  // variable path or I/O address, as written
  LifelineKind kind = LifelineKind::Variable;
  double tolerance = 0;  // analog comparisons: |value - expected| <= tolerance
  Loc loc, bind_loc;
};

// "lifeline = value" in a precondition.
struct LifelineState {
  std::string lifeline;
  std::string value;  // an ST literal (TRUE, 0, 6000, E_Step#InitRefLower)
  Loc loc;
};

struct Transition {
  std::string lifeline;
  std::string to;         // the value the lifeline goes to (ST literal)
  double tolerance = -1;  // < 0: the lifeline's
  int64_t max_ns = 0;
  int64_t min_ns = -1;    // < 0: none
  Loc loc;
};

struct Step {
  std::string id, text;
  std::vector<LifelineState> pre;
  std::string condition;  // optional ST expression, ANDed to the lifeline states
  Loc condition_loc;
  std::string start;      // ST expression; empty: `previous` (the timing starts with the precondition)
  Loc start_loc;
  std::vector<Transition> transitions;
  Loc loc;
};

struct Scenario {
  std::string id, text;
  std::vector<Step> steps;
  Loc loc;
};

struct Tsd {
  std::string path;
  std::vector<Lifeline> lifelines;
  std::vector<Scenario> scenarios;
  const Lifeline* find(const std::string& name) const;
};

struct FmeaRow {
  std::string id;
  std::string transition;  // "scenario.step.lifeline"
  std::string failure_mode, effect, cause, detection;
  int s = 0, o = 0, d = 0, rpn = 0;
  std::string fault_class;
  std::string alarm;        // alarm variable
  std::string fault_model;  // "" (default), "stuck_at(1)", or "Lifeline: model"
  // Safety evidence (optional columns failure_rate, safety_function, dangerous): the row's
  // failure rate in FIT (failures per 10^9 h), the safety function it threatens, and whether
  // the failure is dangerous (a safe one counts toward the safe failure fraction). A row
  // without a safety function (empty cell) is outside the evidence: failure_rate < 0.
  std::string safety_function;
  double failure_rate = -1;
  bool dangerous = true;
  uint32_t line = 0;
  Loc transition_loc, class_loc, alarm_loc, fault_loc, rate_loc;
};

struct Fmea {
  std::string path;
  std::vector<FmeaRow> rows;
  // The header has the failure_rate column (and so safety_function): the campaign writes
  // its safety evidence. Without it every output stays as it was before that column existed.
  bool has_rates = false;
};

// A requirement of a fault class: EDTL formulas with the placeholders {alarm}, {start},
// {deadline}, {signal} filled in per test case.
struct ClassRequirement {
  std::string id, text;
  monitor::FormulaSource trigger, invariant, final, delay, reaction, release;
};

struct Forbidden {
  monitor::FormulaSource formula;
  std::string text;
};

// After the reaction, a class may ask for the recovery too: the fault is withdrawn, the
// alarm must stay latched for `hold`, the test presses the acknowledgement input for
// `press`, and within `within` of the press the alarm and every `cleared` variable must be
// FALSE.
struct Recovery {
  bool enabled = false;
  std::string acknowledge;  // an input: a TSD lifeline, a variable located at %I, or a %IX address
  int64_t hold_ns = 1'000'000'000;
  int64_t press_ns = 200'000'000;
  int64_t within_ns = 1'000'000'000;
  std::vector<std::string> cleared;  // BOOL variables besides the alarm
  Loc loc;
};

struct FaultClass {
  std::string id, name, text;
  int64_t reaction_time_ns = 0;
  int64_t max_duration_ns = 30'000'000'000;
  // The process safety time (`safety_time:`): from the failure to the hazard, the budget for
  // detection and reaction that the safety evidence measures the worst reaction against.
  // -1: not given.
  int64_t safety_time_ns = -1;
  std::vector<ClassRequirement> requirements;
  std::vector<Forbidden> forbidden;
  Recovery recovery;
  Loc loc;
};

struct FaultClasses {
  std::string path;
  std::vector<FaultClass> classes;
  const FaultClass* find(const std::string& id) const;
};

enum class RestartKind { Cold, Warm };

// The campaign file's `explore:` section: settings of the fault-space exploration beyond
// the FMEA (explore.hpp). Exploring runs with `enabled: true` or `plcfi campaign --explore`.
struct ExploreSettings {
  bool enabled = false;
  std::string default_class;  // class of a signal no FMEA row names; "" = none
  Loc loc;                    // the `explore:` key, else the campaign file's first line
  Loc class_loc;              // the default_class value
};

struct Campaign {
  std::string path, name, text;
  std::vector<std::string> programs;  // resolved against the campaign file's folder
  std::string dialect = "iec";        // the programs' ST dialect (iec, codesys)
  std::string plant, plant_config;
  int64_t cycle_ns = 0;  // 0: from the program's CONFIGURATION (else 10 ms)
  uint64_t seed = 1;
  int64_t budget_ns = 3'600'000'000'000;
  int max_paths = 3;
  int64_t search_window_ns = 60'000'000'000;
  RestartKind restart = RestartKind::Cold;
  std::string io;  // a file with an io: section: the campaign runs on real I/O (needs --arm)
  ExploreSettings explore;
  // Compiled for mutation analysis, which patches one jump per condition and one store per
  // assignment: each IF, WHILE and REPEAT condition one value and one jump on it, no
  // statement copied into an IF's arms (CompileOptions::condition_jumps and loop_tails off).
  bool for_mutation = false;
  // EDTL requirements (a requirements file) that an explored case must not violate to count
  // as tolerated; "" = none. FMEA cases do not use them.
  std::string requirements;
  Tsd tsd;
  Fmea fmea;
  FaultClasses classes;
};

// Loads the campaign file and the TSD, FMEA and fault classes it names. Returns false with
// the first error ("FILE:LINE:COL: message") in *err.
bool load_campaign(const std::string& path, Campaign* out, std::string* err);

// Parts of the loader, usable on their own (tests, tools).
bool load_tsd(const std::string& path, Tsd* out, std::string* err);
bool load_fmea(const std::string& path, Fmea* out, std::string* err);
bool load_fault_classes(const std::string& path, FaultClasses* out, std::string* err);
// Cross-file checks: every FMEA row points at a TSD transition and a defined class.
bool check_references(const Campaign& c, std::string* err);

// Splits a "scenario.step.lifeline" reference; false when it has not three parts.
bool split_transition_ref(const std::string& ref, std::string* scenario, std::string* step, std::string* lifeline);

const char* kind_name(LifelineKind k);

}  // namespace plcfi::campaign
