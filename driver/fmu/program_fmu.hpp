// The PLC program as an FMI 2.0 co-simulation FMU (`plcfi export-fmu`): what the archive
// says about the program, shared by the command that packs it and by the FMU binary that
// runs it (the engine itself, compiled into a shared object).
//
// The archive holds the program's sources under resources/plcfi/ and a manifest,
// resources/plcfi/program.txt: dialect, the program to run, cycle time, the files and the
// FMU's ports. At fmi2Instantiate the binary compiles the sources with the same front end
// and checks that they still give these ports. Value references:
//   port i (located variable)       i            input or output, Boolean/Integer/Real
//   fault model of port i           1000000 + i  String parameter ("" = none)
//   injection time of port i (s)    2000000 + i  Real parameter
//   seed of random fault models     3000000      Integer parameter
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "codegen/compiler.hpp"
#include "engine.hpp"
#include "runtime/schedule.hpp"

namespace plcfi::fmu {

enum class FmiType { Boolean, Integer, Real };
const char* fmi_type_name(FmiType t);

inline constexpr uint32_t kFaultRef = 1'000'000;
inline constexpr uint32_t kFaultAtRef = 2'000'000;
inline constexpr uint32_t kSeedRef = 3'000'000;

// A located variable of the program in %I (an FMU input) or %Q (an FMU output).
struct Port {
  bool input = true;
  FmiType fmi = FmiType::Boolean;
  std::string path;     // the variable's path: StampLowered, Main.start
  std::string address;  // %IX0.4
  std::string type;     // BOOL, INT, REAL, ...
};

// The ports of an application: every variable declared at a %I or %Q address (globals,
// and the variables of the program instances), inputs first, each area in address order.
// Refused, with a message naming the variable: types FMI 2.0 cannot carry exactly (64-bit
// integers, TIME, STRING, structures) and inputs sharing bytes (one FMU input would
// change another).
bool list_ports(const st::Application& app, std::vector<Port>* out, std::string* err);

struct Manifest {
  std::string guid;
  std::string model_identifier;  // the binary's name (binaries/linux64/ID.so)
  std::string model_name;
  st::Dialect dialect = st::Dialect::Iec;
  bool strict = false;
  std::string program;      // --program: this program alone, every cycle_ns
  int64_t cycle_ns = 10'000'000;  // without a CONFIGURATION (or with --program)
  int64_t tick_ns = 0;      // the base tick of the schedule (the DefaultExperiment's step)
  std::vector<std::string> libraries, sources;  // relative to resources/plcfi/
  std::vector<Port> ports;
};

std::string write_manifest(const Manifest& m);
// Parses program.txt; false with "line N: ..." in *err.
bool read_manifest(const std::string& text, Manifest* m, std::string* err);

// modelDescription.xml of the program FMU.
std::string model_description(const Manifest& m);

// The tasks to run: the CONFIGURATION's, or one program (m.program, or the only one)
// every m.cycle_ns.
bool make_schedule(const st::Application& app, const Manifest& m, rt::Schedule* sched, std::string* err);

}  // namespace plcfi::fmu
