// The plant file (YAML): which plant stands in for the machine (a built-in model, an FMU or
// an ST program), its own step, its parameters and the map between its variables and the
// PLC's I/O image.
//
//   fmu: conveyor.fmu          # or  builtin: stamping  |  st: tank_plant.st (or a list)
//   step: 1ms                  # the plant's step, independent of the PLC cycle
//   stop_time: 1h              # FMU only, optional: the stop time of fmi2SetupExperiment
//   seed_parameter: seed       # FMU only, optional: an Integer parameter set to the run's seed
//   call_timeout: 10s          # FMU only, optional: an FMU call taking longer is a hang (an error)
//   parameters: {Speed: 0.5}   # FMU start values / ST initial values, by name
//   program: TankPlant         # ST only, optional: the PROGRAM instance to scan
//   stats: [stamped, defective]  # FMU or ST, optional: variables shown as the plant's statistics
//   config: my-stamping.yaml   # built-in only, optional: its parameter file
//   map:                       # %I: the plant writes it (sensor); %Q: the plant reads it
//     - {image: "%QX0.0", plant: Motor}
//     - {image: "%IX0.0", plant: LightBarrier}
//     - {image: "%IW2", plant: Level, scale: {from: [0, 10], to: [0, 27648]}}
//
// Paths are relative to the plant file. Every error is "FILE:LINE:COL: message".
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace plcfi::plant {

// A linear map between the plant's engineering units (from) and the image's (to).
struct Scale {
  double from_lo = 0, from_hi = 1, to_lo = 0, to_hi = 1;
  double to_image(double v) const { return to_lo + (v - from_lo) * (to_hi - to_lo) / (from_hi - from_lo); }
  double to_plant(double v) const { return from_lo + (v - to_lo) * (from_hi - from_lo) / (to_hi - to_lo); }
};

struct MapEntry {
  std::string image;   // "%IX0.0", "%QW2"
  bool input = false;  // %I: a sensor, written by the plant
  bool bit = false;    // X: a BOOL; W: a 16-bit word
  std::string plant;   // the plant's variable
  std::optional<Scale> scale;
  std::string where;        // FILE:LINE:COL of the entry
  std::string plant_where;  // ... of its plant: value
  std::string scale_where;  // ... of its scale: value (when given)
};

struct Parameter {
  std::string name;
  std::string value;  // the scalar as written; its type comes from the plant's variable
  std::string where;  // FILE:LINE:COL of the value
};

struct PlantFile {
  enum class Kind { Builtin, Fmu, St };
  Kind kind = Kind::Builtin;
  std::string path;                 // of the plant file
  std::string builtin;              // Builtin: the model's name
  std::string config;               // Builtin: its parameter file (resolved), may be empty
  std::string fmu;                  // Fmu: the archive (resolved)
  std::string fmu_where;            // Fmu: FILE:LINE:COL of the fmu: value
  std::vector<std::string> st;      // St: the source files (resolved)
  std::string program;              // St: the PROGRAM instance (empty: the only one)
  std::vector<Parameter> stats;     // Fmu, St: variables reported as the plant's statistics (value unused)
  int64_t step_ns = 0;              // 0: not given
  std::string step_where;
  int64_t stop_time_ns = 0;         // 0: not given
  int64_t call_timeout_ns = 10'000'000'000;  // Fmu: a call that takes longer is a hang
  std::string seed_parameter;       // Fmu: an Integer parameter that takes the run's seed
  std::string seed_where;
  std::vector<Parameter> parameters;
  std::vector<MapEntry> map;
  std::string where;                // FILE:1:1, for messages about the file as a whole
};

// What a plant variable holds, for the check of its map entry.
enum class ValueKind { Bool, Integer, Real };
// Checks that map entry `m` fits a plant variable of `kind` (a Bool on a bit, an Integer
// or Real on a word, scale exactly for a Real); `what` names the variable's type in the
// message ("Boolean (x.fmu/modelDescription.xml:12:5)", "INT"). Throws common::InputError
// at the entry's line and column. The one rule for FMU, ST and remapped built-in plants.
void check_binding(const MapEntry& m, ValueKind kind, const std::string& what);

// Reads and checks a plant file. Throws common::InputError ("FILE:LINE:COL: message").
PlantFile read_plant_file(const std::string& path);

// True when `arg` names a plant file rather than a built-in plant (it ends in .yaml/.yml).
bool is_plant_file(const std::string& arg);

}  // namespace plcfi::plant
