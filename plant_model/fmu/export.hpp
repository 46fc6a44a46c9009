// Packs a built-in plant as an FMI 2.0 co-simulation FMU: modelDescription.xml written from
// the plant's signal list, the binary that wraps the plant, and a plant file that maps the
// FMU back onto the image addresses the built-in plant uses.
#pragma once

#include <string>
#include <vector>

#include "plant_model/plant.hpp"

namespace plcfi::plant::fmu {

struct ExportOptions {
  std::string library;     // the FMU binary to pack (plcfi_stamping_fmu.so)
  std::string out;         // the .fmu to write
  std::string plant_file;  // optional: the plant file to write beside it
  int64_t step_ns = 10'000'000;  // DefaultExperiment stepSize and the plant file's step
};

// One file of an FMU archive: its text, or the file on disk to copy (`from`).
struct ArchiveEntry {
  std::string name;  // path in the archive: modelDescription.xml, binaries/linux64/X.so, ...
  std::string data;
  std::string from;  // when set, the archive gets this file's bytes instead of data
};
// Writes the archive atomically (to OUT.tmp, then renamed). Throws common::InputError
// naming `out` on failure.
void write_fmu_archive(const std::string& out, const std::vector<ArchiveEntry>& entries);

// modelDescription.xml of the stamping FMU (signal i = value reference i; actuators are
// inputs, sensors outputs; BOOL signals Boolean, analog ones Integer; parameter seed).
std::string stamping_model_description(const Plant& plant, int64_t step_ns);

// Writes the archive (and the plant file). Throws common::InputError naming the file on
// failure.
void export_stamping_fmu(const Plant& plant, const ExportOptions& opt);

}  // namespace plcfi::plant::fmu
