// Test-case generation: one test case per expected TSD transition that has an FMEA row
// (precondition, fault, expected reaction, deadline, priority = RPN), compiled once with
// the program under test: the preconditions of all cases into one generated PROGRAM, the
// fault-class reactions into EDTL monitors.
#pragma once

#include <cstdint>
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
  std::string id;  // TC1, TC2, ... in priority order
  const FmeaRow* row = nullptr;
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
  std::string expected;  // readable: "gStampCylError AND gStampStop within 600 ms of StampDown"
  std::string transition_ref() const;  // scenario.step.lifeline
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
};

// Generates and compiles the test cases. Errors (rendered diagnostics or FILE:LINE:COL
// messages) go to *err; false means the campaign cannot run.
bool prepare_campaign(Campaign spec, CampaignBuild* out, std::string* err);

// The generated ST source of the preconditions (exposed for tests and `generate --json`).
std::string precondition_program(const std::vector<TestCase>& cases);

// "T#600ms"-style text of a duration; "600 ms" for people.
std::string st_duration(int64_t ns);
std::string human_duration(int64_t ns);
// "%IX0.4", "%IW2", "%QX0.1" of an image location.
std::string address_text(const rt::ImageRef& r);

}  // namespace plcfi::campaign
