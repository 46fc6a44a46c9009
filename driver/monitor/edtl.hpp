// EDTL requirement monitors: six formulas per requirement (trigger, invariant, final,
// delay, reaction, release) compiled once by the ST engine against a program (online) or
// a trace's variables (offline), then checked one state at a time with memory bounded
// by the open trigger instances. The definition is ../shared/reference/edtl.md.
#pragma once

#include <cstdint>
#include <memory>
#include <array>
#include <string>
#include <vector>

#include "engine.hpp"

namespace plcfi::monitor {

struct FormulaSource {
  std::string text;       // as written (may use /x \x ~x _x)
  uint32_t line = 0;      // in the requirements file, 1-based; 0 = default value
  uint32_t col = 0;
};

struct RequirementSpec {
  std::string id;
  std::string text;
  std::string severity;
  uint32_t line = 0;
  FormulaSource trigger, invariant, final, delay, reaction, release;
};

struct RequirementsFile {
  std::string path;
  std::vector<RequirementSpec> requirements;
};

// Loads and validates a requirements YAML file; errors read "FILE:LINE:COL: message".
bool load_requirements(const std::string& path, RequirementsFile* out, std::string* err);

// Rewrites the symbolic forms (/x \x ~x _x) as RISING(x) FALLING(x) HIGH(x) LOW(x).
// pos_map[i] is the column in `text` of output character i (for error locations).
std::string expand_symbols(const std::string& text, std::vector<uint32_t>* pos_map);

// The ST source of the monitor programs for a requirements file (one PROGRAM per
// requirement), and how to map a diagnostic in it back to the requirements file.
struct MonitorSource {
  std::string name;  // virtual file name
  std::string text;
  struct LineInfo {
    const FormulaSource* formula = nullptr;
    uint32_t prefix = 0;  // columns of generated text before the formula on this line
    std::vector<uint32_t> pos_map;
  };
  std::vector<LineInfo> lines;  // index = generated line - 1

  // The monitors as a late source of a build, each formula line pointing at the formula
  // in `reqs_path`, so diagnostics show the user's text. `exact_columns` false when the
  // formulas were instantiated with other text (a campaign's fault-class placeholders):
  // messages then point at the formula's start.
  st::GeneratedSource source(const std::string& reqs_path, bool exact_columns = true) const;
};
MonitorSource generate_monitors(const RequirementsFile& reqs);

enum class Cause { Invariant, Delay };

struct Violation {
  uint64_t trigger_state = 0;
  int64_t trigger_time_ns = 0;
  uint64_t state = 0;
  int64_t time_ns = 0;
  Cause cause = Cause::Invariant;
  uint64_t instances = 1;  // trigger instances that failed identically at this state
};

struct Verdict {
  std::string id;
  std::string text;
  std::string severity;
  uint64_t triggers = 0;
  uint64_t holds = 0;              // instances released or reacted in time
  uint64_t violated_instances = 0;
  uint64_t pending = 0;            // instances still open
  std::vector<Violation> violations;  // the first kMaxListed
  bool violated() const { return violated_instances > 0; }
  static constexpr size_t kMaxListed = 20;
};

// The checker of all requirements of one build (program + monitors, or trace + monitors).
class MonitorSet {
 public:
  // Binds to the compiled monitors; the build must contain generate_monitors() output as
  // late units. Fails when a monitor program is missing.
  static std::unique_ptr<MonitorSet> create(const st::Application& app, const RequirementsFile& reqs, std::string* err);
  // Binds only requirements [first, first + count) of `reqs` (a campaign monitors one
  // test case's requirements at a time, out of one build holding all of them).
  static std::unique_ptr<MonitorSet> create(const st::Application& app, const RequirementsFile& reqs, size_t first,
                                            size_t count, std::string* err);

  // Evaluates state `state` at time t (ns) on the machine's current memory: call once
  // per state, in order. Returns true when some requirement got its first violation
  // in this state (for live reporting).
  bool step(st::Machine& m, uint64_t state, int64_t t_ns);
  // Verdicts so far (pending = instances still open).
  std::vector<Verdict> verdicts() const;
  size_t size() const { return reqs_.size(); }
  // The requirement that first became violated in the last step() (for live output).
  const std::vector<size_t>& newly_violated() const { return newly_; }

  struct Group {
    bool phase_b = false;
    uint64_t first_trigger = 0;
    int64_t first_trigger_time = 0;
    uint64_t timer_state = 0;
    int64_t timer_time = 0;
    uint64_t count = 0;
  };

 private:
  struct Req {
    const RequirementSpec* spec = nullptr;
    uint32_t entry = 0, addr = 0;
    st::VarHandle out[6];  // trig inv fin del react rel
    st::VarHandle elapsed, state, full;
    const st::StateShift* shift = nullptr;
    bool uses_passed = false;
    // When every PASSED(...) of the requirement takes a duration literal, the formulas
    // depend on an instance's elapsed time only through which of these (sorted) it has
    // passed: instances between the same two thresholds get the same values at a state,
    // so one evaluation serves them all. Empty with passed_known false: no such cache.
    std::vector<int64_t> thresholds;
    bool passed_known = false;
    std::vector<std::array<bool, 6>> cached;  // per threshold interval, this state
    std::vector<uint8_t> cached_ok;
    std::vector<Group> groups;
    Verdict verdict;
  };
  bool eval(st::Machine& m, Req& r, int64_t elapsed, bool v[6], bool full);
  std::vector<Req> reqs_;
  std::vector<size_t> newly_;
  uint64_t state_ = 0;
};

// Offline: checks requirements on a CSV/VCD trace. cycle_ns: time between states when the
// trace has no time column (CSV default 1 s), or the VCD sampling period (0: one state per
// time stamp). On failure returns false with the rendered diagnostics or error in *error.
struct TraceCheck {
  std::vector<Verdict> verdicts;
  uint64_t states = 0;
};
bool check_trace(const RequirementsFile& reqs, const std::string& trace_path, int64_t cycle_ns, TraceCheck* out,
                 std::string* error);
std::string cause_text(Cause c);

}  // namespace plcfi::monitor
