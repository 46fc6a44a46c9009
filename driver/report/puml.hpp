// PlantUML diagrams of a fault-injection test case: a sequence diagram of the test
// procedure (test system, system under test, plant; start & init, injection and
// monitoring, completion) and a timing diagram of the expected transitions.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace plcfi::report {

struct PumlTransition {
  std::string lifeline, from, to;
  int64_t min_ns = -1, max_ns = 0;
  double tolerance = 0;
  bool faulted = false;  // the transition the test's fault suppresses
};

struct PumlCase {
  std::string id, title;         // "TC3", "init.ref_lower.StampLowered: reference stroke not completed"
  std::string precondition;      // ST text
  std::string start;             // the operation that starts the timing ("" = previous transition)
  std::string target, fault;     // "StampLowered (%IX0.4)", "stuck (pre-fault value)"
  std::string reaction;          // "gStampCylError AND gStampStop"
  int64_t deadline_ns = 0, max_duration_ns = 0;
  std::string fault_class, restart;
  int rpn = 0;
  std::vector<PumlTransition> transitions;
};

std::string sequence_diagram(const PumlCase& c);
std::string timing_diagram(const PumlCase& c);

}  // namespace plcfi::report
