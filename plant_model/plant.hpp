// The Plant interface: a machine model that stands in for the real process in virtual
// time. Physics only: no knowledge of ST, images or faults. The runtime binds each
// signal to an I/O image address and exchanges values once per scan.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace plcfi::plant {

enum class Direction : uint8_t {
  ToPlant,    // actuator: written by the PLC program (%Q), read by the plant
  FromPlant,  // sensor: written by the plant, read by the PLC program (%I)
};

enum class SignalKind : uint8_t {
  Bool,    // 0 or 1, bound to a bit (%IX/%QX)
  Analog,  // 16-bit signed register value (%IW/%QW), engineering units of the plant
};

struct SignalInfo {
  std::string name;         // e.g. "StampLowered"
  Direction dir;
  SignalKind kind;
  std::string address;      // default image binding, e.g. "%IX0.4", "%QW2"
  std::string description;  // one line for humans (reports, --help)
  std::string where = {};   // where the binding was written (a plant file's FILE:LINE:COL), or ""
};

// Contract: single-threaded. reset() before the first step(). step() must not allocate
// and must be deterministic for a given seed and sequence of actuator values.
class Plant {
 public:
  virtual ~Plant() = default;

  virtual const std::string& name() const = 0;
  // All signals; the index of a signal in this vector is its index in step()'s arrays.
  virtual const std::vector<SignalInfo>& signals() const = 0;

  // Back to the initial physical state; the seed drives the random variation.
  virtual void reset(uint64_t seed) = 0;

  // Advances the physics by dt seconds under the given actuator values (entries of
  // ToPlant signals; others are ignored), then writes every FromPlant entry of sensors.
  // Sensors reflect the state at the end of the step.
  virtual void step(double dt, const double* actuators, double* sensors) = 0;

  // Sensor values of the current state without advancing (after reset: the initial state).
  virtual void sense(double* sensors) const = 0;

  // Counters for summaries: e.g. {"workpieces_stamped", 12}, {"workpieces_defective", 0}.
  virtual std::vector<std::pair<std::string, double>> stats() const = 0;

  // Where the plant comes from, for reports: "" for a built-in plant named by --plant,
  // else the plant file and what it loads ("tank.yaml (FMU tank.fmu, FMI 2.0 co-simulation)").
  virtual std::string origin() const { return ""; }
  // The plant's own step in ns; 0: it steps with every scan, by the scan's tick.
  virtual int64_t step_ns() const { return 0; }
  // What a user should know about how the plant is stepped (an FMU stepped at another
  // step than its DefaultExperiment suggests, ...): one line each, for summaries.
  virtual std::vector<std::string> notes() const { return {}; }
};

// Creates a built-in plant by name ("stamping"); config_path may be empty (defaults).
// Returns null and fills err (with file:line for a bad config) when the name or config is
// invalid. Commands and campaigns open plants through io::open_plant, which also takes
// plant files (an FMU, an ST plant, a built-in one with its map) and calls this one.
std::unique_ptr<Plant> make_builtin_plant(const std::string& name, const std::string& config_path, std::string* err);
// Names accepted by make_builtin_plant.
std::vector<std::string> builtin_plant_names();

}  // namespace plcfi::plant
