// Fault-space exploration beyond the FMEA (`plcfi campaign --explore`, or `explore:` in the
// campaign file): test cases for the failures the FMEA forgot, their oracle, and the FMEA
// rows a failed one suggests.
//
// Generation. For every TSD step (scenario by scenario, in file order) and every signal of
// that step, one case per applicable fault model:
//  - the signals of a step: the lifelines of kind sensor, actuator or analog that are bound
//    to an I/O address and that the program accesses (its bytecode loads the %I location
//    or stores the %Q location; access through a reference is not seen), restricted for
//    inputs to those the step names (its precondition, its start expression or condition,
//    its transitions: what the TSD says the step looks at). Outputs are taken in every
//    step: the TSD rarely names the valve a step drives (the slider's step names only
//    PosStamp), and a valve that fails while nothing is expected of it must be tolerated.
//  - fault models: BOOL input stuck_at(0) and stuck_at(1) (one of them is the classic
//    "never switches"); analog input frozen, offset(10 x the lifeline's tolerance, else
//    100) and stuck_at(0); BOOL output no_effect, stuck_on and stuck_off; analog output
//    no_effect and stuck_off.
//  - a case equal to an FMEA case (same step, same faulted lifeline, equivalent fault:
//    "stuck" of a BOOL is stuck_at(v) with v the value the step's precondition gives it, or
//    the opposite of the value its transition goes to; "stuck" of an analog value is
//    "frozen") is left out. A step's cases do not depend on which of its transitions the
//    fault belongs to (the oracle watches them all), so the unit is the step, and the
//    reference of a case is scenario.step.SIGNAL.
//  - explored cases come after all FMEA cases, with ids X1, X2, ..., ordered by step,
//    then signal (TSD lifeline order), then fault model (the order above).
//  - the class of a case: the class of the first FMEA row (file order) that faults the same
//    lifeline, with that row's alarm; else the campaign's explore: default_class, whose
//    alarm is "any alarm of the FMEA" (the OR of the FMEA rows' alarm variables). Neither:
//    an error at the campaign file's explore: section.
//
// Oracle. The fault is injected when the step's precondition rises (as for FMEA cases);
// from then on the steps of the scenario, the faulted one first, are followed on what the
// program sees (program memory after each scan: faulted inputs, the program's outputs):
//  - a step begins when its precondition (a later step's) and then its start condition
//    hold; it must begin within its window (its longest transition max) of the moment it
//    became due: the injection for the faulted step, the end of the previous step else;
//  - each transition of a begun step must reach its value within [min, max] of the step's
//    start; when all have, the next step is due; after the scenario's last step the case is
//    TOLERATED (PASS);
//  - the first deviation (a step not begun in its window, a transition late or too early)
//    sets the detection deadline: the deviation's bound (the window's end, or the step
//    start plus the transition's max) plus the class's reaction time;
//  - DETECTED (PASS): the class's reaction (the reaction formulas of its requirements with
//    {alarm} etc. filled in, ANDed; plain ST) holds at a scan before the first deviation or
//    by its detection deadline;
//  - FAIL: the detection deadline passes without it ("effect seen": the deviation and "no
//    alarm", or the alarms that were up), a forbidden reaction of the class, the program
//    stopping, or the class's maximum test duration.
// What the program sees is what the FMEA cases' monitors see too, and it is what makes a
// weakened plausibility check visible: a sensor stuck at the value its own transition goes
// to completes that transition at once, which the transition's min time or a later step
// then shows (the plant's true values would call such a run tolerated).
// Monitors, as for FMEA cases: the class's forbidden reactions (one that becomes true is a
// FAIL at once) and the campaign's `requirements:` file (EDTL): a run the TSD calls
// tolerated FAILS when one of them was violated; a detected run stays detected (the alarm
// legitimately stops what the requirements describe).
// A FAILed explored case is an FMEA suggestion: a row for the FMEA (fmea_suggestions.csv).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "execution.hpp"
#include "generate.hpp"

namespace plcfi::campaign {

// The lifelines a step's explored cases fault, in TSD lifeline order (the rule above).
// `program` is the program alone (no generated units).
std::vector<const Lifeline*> explore_signals(const Campaign& c, const st::Application& program, const Step& step);

// The fault models tried on a lifeline at `ref`, in the order above.
std::vector<std::string> explore_fault_models(const Lifeline& l, const rt::ImageRef& ref);

// The canonical text of a fault for deduplication ("stuck" made explicit, see above).
std::string equivalent_fault(const Step& step, const Lifeline& l, const rt::ImageRef& ref, const faults::FaultSpec& f);

// Appends the explored cases of cb->spec to *cases (the FMEA's, in priority order): ids,
// made-up rows (cb->explored_rows), targets, faults, classes, deadlines; and fills the
// step table and program source of cb->explore. binds: lifeline name -> its handle in
// `program`. Errors: "FILE:LINE:COL: message".
bool add_explored_cases(CampaignBuild* cb, const st::Application& program, const std::map<std::string, st::VarHandle>& binds,
                        std::vector<TestCase>* cases, std::string* err);

// Sets the explore program's entry and array addresses once it is linked into cb->build.
bool bind_explore(CampaignBuild* cb, std::string* err);

// The oracle of one execution of an explored case (the rule above), stepped after each scan.
class ExploreOracle {
 public:
  enum class State { Open, Detected, Tolerated, Failed };
  ExploreOracle(const CampaignBuild& cb, size_t case_index, int64_t inject_ns);
  // Runs the explore program on the machine's memory and advances; returns the state.
  State step(st::Machine& m, int64_t now_ns);
  // PASS: "detected: ..." / "tolerated: ..."; FAIL: the effect seen.
  const std::string& reason() const { return reason_; }
  int64_t verdict_ns() const { return verdict_ns_; }

 private:
  enum class Phase { AwaitPre, AwaitStart, Running };
  void deviate(int64_t bound_ns, std::string what);
  State tolerated(int64_t now_ns);
  std::string rel(int64_t t) const;

  const CampaignBuild& cb_;
  const TestCase& tc_;
  size_t det_;  // index in det[]
  int64_t inject_ns_;
  size_t step_;  // current index in cb_.explore.steps
  Phase phase_ = Phase::AwaitStart;
  int64_t due_ns_ = 0, start_ns_ = 0;
  std::vector<int64_t> reached_;
  int64_t deviation_ns_ = -1, detect_by_ns_ = 0;
  std::string deviation_;
  std::string reason_;
  int64_t verdict_ns_ = -1;
  State state_ = State::Open;
};

// One suggested FMEA row: a failed explored case.
struct FmeaSuggestion {
  std::string case_id;
  std::string component;     // the faulted lifeline, e.g. StampUp
  std::string transition;    // an FMEA-valid reference: scenario.step.<a transition of the step>
  std::string failure_mode;  // e.g. "StampUp stuck_at(0)"
  std::string effect;        // what the oracle saw
  std::string detection;     // the alarm that rose, or "none"
  std::string fault_class, alarm;
  std::string fault_model;   // "StampUp: stuck_at(0)"
};

// The suggestions of a campaign's executions: one per explored case with a FAIL, in case order.
std::vector<FmeaSuggestion> fmea_suggestions(const CampaignBuild& cb, const std::vector<Execution>& executions);

// The suggestions as CSV with the FMEA's columns (S, O, D and RPN left empty to be rated).
std::string fmea_suggestions_csv(const std::vector<FmeaSuggestion>& s);

}  // namespace plcfi::campaign
