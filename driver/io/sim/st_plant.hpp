// A plant written in Structured Text: a PROGRAM compiled by plcfi's own engine and scanned
// in virtual time at the plant file's step, its variables bound to the PLC's image by the
// plant file's map. The adapter between the ST engine and the Plant interface.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine.hpp"
#include "plant_model/plant.hpp"
#include "plant_model/plant_file.hpp"
#include "runtime/runtime.hpp"

namespace plcfi::io {

class StPlant final : public plant::Plant {
 public:
  // Compiles the plant's ST files and resolves the map. Throws common::InputError: the
  // compiler's diagnostics (file:line:col in the ST files), or a map entry that names no
  // variable or one of the wrong type (at the plant file's line and column).
  static std::unique_ptr<StPlant> create(const plant::PlantFile& pf);

  const std::string& name() const override { return name_; }
  const std::vector<plant::SignalInfo>& signals() const override { return signals_; }
  // Cold restart of the plant program (its variables to their initial values, its
  // parameters from the plant file applied again).
  void reset(uint64_t seed) override;
  // Scans the plant program once per plant step as time accumulates, the actuators
  // written into its variables first. A runtime error in the plant program throws
  // PlantProgramError.
  void step(double dt, const double* actuators, double* sensors) override;
  void sense(double* sensors) const override;
  std::vector<std::pair<std::string, double>> stats() const override;
  std::string origin() const override { return origin_; }
  int64_t step_ns() const override { return step_ns_; }

 private:
  StPlant() = default;
  enum class Kind { Bool, Int, Real };
  struct Binding {
    st::VarHandle var;
    Kind kind = Kind::Bool;
    std::optional<plant::Scale> scale;
  };
  struct Preset {
    st::VarHandle var;
    std::string text;
    std::string where;
  };
  void read_sensors();

  std::string name_, origin_;
  std::vector<plant::SignalInfo> signals_;
  std::vector<Binding> bind_;
  std::vector<Preset> presets_;
  std::vector<st::VarHandle> stats_;
  std::unique_ptr<st::Build> build_;
  std::unique_ptr<rt::Runtime> runtime_;
  std::vector<double> values_;
  int64_t step_ns_ = 0, pending_ns_ = 0;
  uint64_t scans_ = 0;
  bool failed_ = false;
};

// A runtime error (trap) in an ST plant: the run cannot go on with the plant stopped.
class PlantProgramError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace plcfi::io
