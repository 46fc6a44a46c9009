// Test-case generation: one test case per expected TSD transition that has an FMEA row
// (precondition, fault, expected reaction, deadline, priority = RPN), compiled once with
// the program under test: the preconditions of all cases into one generated PROGRAM, the
// fault-class reactions into EDTL monitors. With exploring on (explore.hpp), explored cases
// X1... follow the FMEA's: one per TSD step, signal and fault model the FMEA lacks.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engine.hpp"
#include "faults/fault_model.hpp"
#include "monitor/edtl.hpp"
#include "runtime/image.hpp"
#include "runtime/schedule.hpp"
#include "spec.hpp"

namespace plcfi::campaign {

struct TestCase {
  std::string id;  // TC1, TC2, ... in priority order; X1, X2, ... explored cases after them
  // The FMEA row; for an explored case a row made up by the exploration (empty id) that
  // carries its failure mode, class and alarm (CampaignBuild::explored_rows).
  const FmeaRow* row = nullptr;
  bool explored = false;
  const Scenario* scenario = nullptr;
  const Step* step = nullptr;
  const Transition* transition = nullptr;
  const FaultClass* cls = nullptr;
  int rpn = 0;
  std::string precondition;  // ST expression (lifeline states AND condition)
  std::string start;         // ST expression ("TRUE" when the timing starts with the precondition)
  const Lifeline* target = nullptr;  // the faulted lifeline
  rt::ImageRef target_ref;
  faults::FaultSpec fault;
  int64_t deadline_ns = 0;  // transition max + class reaction time, from the start condition
  int64_t max_duration_ns = 0;
  // This case's requirements in CampaignBuild::monitors: [first_req, first_req + reqs),
  // the class requirements first, then one per forbidden reaction.
  size_t first_req = 0, reqs = 0, forbidden = 0;
  // The class's recovery (FaultClass::recovery), resolved on the built program; FMEA
  // cases only (an explored case ends at its verdict).
  bool recovery = false;
  rt::ImageRef ack_ref;                 // the acknowledgement input the test presses
  std::vector<st::VarHandle> cleared;   // the alarm first, then the class's cleared variables
  std::string expected;  // readable: "gStampCylError AND gStampStop within 600 ms of StampDown"
  // Explored cases: the step's index in ExplorePlan::steps.
  size_t explore_step = 0;
  std::string transition_ref() const;  // scenario.step.lifeline (explored: scenario.step.faulted signal)
};

// The generated program and step table that the oracle of explored cases reads (explore.hpp).
struct ExploreStep {
  const Scenario* scenario = nullptr;
  const Step* step = nullptr;
  size_t first_transition = 0;  // index of its first transition in the program's tr[] array
  int64_t window_ns = 0;        // the longest max time of its transitions
  size_t last_of_scenario = 0;  // index of its scenario's last step
};
struct ExplorePlan {
  std::vector<ExploreStep> steps;  // every TSD step, scenario by scenario, in file order
  std::string source;              // PROGRAM __FI_EXPLORE
  std::vector<st::LineOrigin> origins;  // its lines' places in the TSD and campaign file
  uint32_t entry = 0, addr = 0;    // to call it
  uint32_t pre = 0, start = 0, tr = 0, det = 0;  // absolute addresses of its BOOL arrays
  std::vector<st::VarHandle> alarms;             // the FMEA's alarm variables
};

struct CampaignBuild {
  Campaign spec;
  std::unique_ptr<st::Build> build;
  rt::Schedule schedule;
  std::vector<TestCase> cases;  // priority order: RPN descending, then FMEA order
  monitor::RequirementsFile monitors;
  monitor::MonitorSource monitor_source;
  std::string preconditions_source;
  st::VarHandle preconditions;  // ARRAY[0..n-1] OF BOOL, index = case index
  uint32_t preconditions_entry = 0, preconditions_addr = 0;
  std::vector<uint32_t> program_files;  // source-manager ids of the program's own files
  std::vector<st::VarHandle> watch;     // lifelines and alarms, for traces
  std::deque<FmeaRow> explored_rows;    // the made-up rows of explored cases (stable addresses)
  ExplorePlan explore;                  // empty unless the campaign explores
};

// Generates and compiles the test cases. Errors (rendered diagnostics or FILE:LINE:COL
// messages) go to *err; false means the campaign cannot run.
bool prepare_campaign(Campaign spec, CampaignBuild* out, std::string* err);

// The generated ST source of the preconditions (exposed for tests and `generate --json`).
std::string precondition_program(const std::vector<TestCase>& cases);

// ST text of "lifeline has value v" (analog: within tolerance `tol`); *human gets the
// readable form.
std::string lifeline_state(const Lifeline& l, const st::VarHandle& h, const std::string& value, double tol,
                           std::string* human);

// "T#600ms"-style text of a duration; "600 ms" for people.
std::string st_duration(int64_t ns);
std::string human_duration(int64_t ns);
// "%IX0.4", "%IW2", "%QX0.1" of an image location.
std::string address_text(const rt::ImageRef& r);

}  // namespace plcfi::campaign
