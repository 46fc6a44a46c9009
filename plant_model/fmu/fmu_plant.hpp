// A plant given as an FMI 2.0 co-simulation FMU: the plant file's map turns the FMU's
// inputs and outputs into plant signals, and the FMU steps at the plant file's step,
// whatever the PLC's cycle.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "plant_model/fmu/fmu.hpp"
#include "plant_model/plant.hpp"
#include "plant_model/plant_file.hpp"

namespace plcfi::plant::fmu {

class FmuPlant final : public Plant {
 public:
  // Loads the FMU of `pf` and checks the map and parameters against its
  // modelDescription.xml. Throws common::InputError (at the plant file's line and column
  // for a mismatch) or FmuError (the FMU failed to instantiate or initialize).
  static std::unique_ptr<FmuPlant> create(const PlantFile& pf);

  const std::string& name() const override { return name_; }
  const std::vector<SignalInfo>& signals() const override { return signals_; }
  void reset(uint64_t seed) override;
  // Steps the FMU at the plant step as the scans' time accumulates (a plant step coarser
  // than the cycle steps every few scans; a finer one several times per scan), the
  // actuators held over the scan. Throws FmuError when the FMU fails.
  void step(double dt, const double* actuators, double* sensors) override;
  void sense(double* sensors) const override;
  std::vector<std::pair<std::string, double>> stats() const override;
  std::string origin() const override { return origin_; }
  int64_t step_ns() const override { return step_ns_; }
  std::vector<std::string> notes() const override { return notes_; }

 private:
  FmuPlant() = default;
  // One group per FMI type and direction: value references and the signal of each.
  struct Group {
    std::vector<fmi2ValueReference> vr;
    std::vector<size_t> signal;
  };
  struct Binding {
    VarType type = VarType::Real;
    std::optional<Scale> scale;
  };
  void initialize();
  void exchange();  // inputs, the due steps, outputs: one batch of FMU calls
  void exchange_outputs();

  std::string name_, origin_;
  std::vector<std::string> notes_;
  std::vector<SignalInfo> signals_;
  std::vector<Binding> bind_;
  Group in_real_, in_int_, in_bool_, out_real_, out_int_, out_bool_;
  // Parameters: value references and values per type, set before initialization.
  Group par_real_, par_int_, par_bool_;
  std::vector<fmi2Real> par_real_v_;
  std::vector<fmi2Integer> par_int_v_;
  std::vector<fmi2Boolean> par_bool_v_;
  // Buffers of the exchange (sized once: a step allocates nothing).
  std::vector<fmi2Real> real_buf_;
  std::vector<fmi2Integer> int_buf_;
  std::vector<fmi2Boolean> bool_buf_;
  std::vector<double> values_;  // per signal, image units: sensors from the last step
  std::unique_ptr<FmuArchive> archive_;
  std::unique_ptr<FmuInstance> instance_;
  int64_t step_ns_ = 0, t_ns_ = 0, pending_ns_ = 0, stop_ns_ = 0;
  bool failed_ = false;    // an FMU call threw: the FMU is not called again
  bool has_seed_ = false;  // the plant file's seed_parameter: an Integer parameter
  fmi2ValueReference seed_ref_ = 0;
  fmi2Integer seed_ = 1;
  uint64_t steps_ = 0;
  double last_dt_ = -1.0;
  int64_t last_dt_ns_ = 0;
  const double* actuators_ = nullptr;  // of the step() in progress
  struct Stat {
    std::string name;
    VarType type;
    fmi2ValueReference vr;
  };
  std::vector<Stat> stats_;  // the plant file's stats: variables
};

}  // namespace plcfi::plant::fmu
