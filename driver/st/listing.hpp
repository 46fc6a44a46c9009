// What the engine shows of a compiled application: the bytecode listing, branch coverage
// per file, and the text of a runtime error (trap). Part of the engine's front door
// (engine.hpp).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "build.hpp"
#include "vm/program.hpp"
#include "vm/vm.hpp"

namespace plcfi::st {

// Bytecode listing with source lines, one POU after another.
std::string disassemble(const Application& app, const Build* build = nullptr);

// Branch coverage per file: taken / total and the arms never taken (file:line).
std::string coverage_report(const Application& app, const std::vector<uint64_t>& covered);

// `file:line:col: runtime error[ST5nn]: message` for a trap.
std::string describe_trap(const Application& app, const Trap& t);
// The same without the location: `runtime error[ST5nn]: message` (for output that shows
// the location already).
std::string describe_trap_kind(const Trap& t);
const char* trap_code(TrapKind k);

}  // namespace plcfi::st
