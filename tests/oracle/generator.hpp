// The oracle's program generator: from a seed, a random ST program that is well typed by
// construction, always terminates and stays clear of what IEC 61131-3 leaves to the
// implementation (division by zero, out-of-range indices, REAL overflow to infinity).
#pragma once

#include <cstdint>
#include <string>

namespace plcfi::oracle {

struct GenOptions {
  // METHOD and interface calls get only variables and literals as arguments (no call, no
  // property read inside them): excludes the construct of a known engine bug, for local runs.
  bool avoid_method_args_with_calls = false;
};

// Every statement of the program is on a line of its own (compound statements included),
// so that a line is a unit the shrinker can delete.
std::string generate_program(uint64_t seed, const GenOptions& opt);

}  // namespace plcfi::oracle
