// `plcfi export-fmu`: packs a compiled PLC program as an FMI 2.0 co-simulation FMU, the
// engine's shared object as its binary and the sources as its resources.
#pragma once

#include <string>
#include <vector>

#include "fmu/program_fmu.hpp"

namespace plcfi::fmu {

struct ExportOptions {
  std::vector<std::string> sources;    // the program's files, as given
  std::vector<std::string> libraries;  // --library files (compiled as library code)
  st::Dialect dialect = st::Dialect::Iec;
  bool strict = false;
  std::string program;              // --program
  int64_t cycle_ns = 10'000'000;    // --cycle-time
  std::string binary;               // the engine FMU binary (plcfi_program_fmu.so)
  std::string out;                  // the .fmu to write
  std::string model_identifier;     // default: the output file's stem, as a C identifier
};

// The manifest of `app` (compiled from opt's files) as the archive will hold it: ports,
// schedule, files (renamed into src/ and lib/), and a GUID that fingerprints all of it.
// Throws common::InputError with a message for the user (no ports, a port FMI cannot
// carry, a TwinCAT project file, no schedule).
Manifest make_manifest(const st::Application& app, const ExportOptions& opt);

// Writes the archive: modelDescription.xml, binaries/linux64/ID.so, resources/plcfi/.
// Throws common::InputError naming the file on failure.
void write_program_fmu(const Manifest& m, const ExportOptions& opt);

}  // namespace plcfi::fmu
