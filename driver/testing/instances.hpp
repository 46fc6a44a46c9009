// The FB instances of a kind in an application's memory (TcUnit suites, FB_ASSERTs): in
// the program instances and the global variables, inside FB instances, structures and
// arrays of them.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vm/program.hpp"

namespace plcfi::testing {

struct Found {
  std::string path;            // PRG_TEST.fbSumTest, GVL.aTests[2]
  const st::PouInfo* type;
  uint32_t addr;
};

// Every instance of a function block `wanted` accepts, outermost first; an instance found
// is not searched further. At most 10,000.
std::vector<Found> find_instances(const st::Application& app, const std::function<bool(const st::PouInfo*)>& wanted);

// p is base or derives from it.
bool derives(const st::PouInfo* p, const st::PouInfo* base);

}  // namespace plcfi::testing
