// The bead dispenser's plant model: two hoppers with solenoid gates and an infrared beam
// below them (the laboratory stand of CPTest+'s communication-aware system tests).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "plant_model/plant.hpp"

namespace plcfi::plant {

// Times in seconds. The defaults: a gate must be open 40 ms before a bead falls, and
// every further 70 ms while it stays open another one falls (open 40..110 ms: one bead);
// a bead reaches the beam 120 ms after it left and interrupts it for 15 ms.
struct BeadParams {
  double release_after = 0.040;
  double release_period = 0.070;
  double fall_time = 0.120;
  double beam_time = 0.015;
  int64_t hopper_beads[2] = {50, 50};  // black, white
};

// Reads a YAML parameter file over the defaults (see bead_dispenser.yaml). False with
// "FILE:LINE:COL: message" in err on a bad file.
bool load_bead_params(const std::string& path, BeadParams* params, std::string* err);

class BeadDispenserPlant final : public Plant {
 public:
  static constexpr int kGate1 = 0;       // %QX0.0, hopper 1 (black)
  static constexpr int kGate2 = 1;       // %QX0.1, hopper 2 (white)
  static constexpr int kBeadSensor = 2;  // %IX0.0, TRUE while a bead interrupts the beam
  static constexpr int kSignalCount = 3;

  explicit BeadDispenserPlant(BeadParams params = {});

  const std::string& name() const override;
  const std::vector<SignalInfo>& signals() const override;
  void reset(uint64_t seed) override;
  void step(double dt, const double* actuators, double* sensors) override;
  void sense(double* sensors) const override;
  std::vector<std::pair<std::string, double>> stats() const override;

  // Inspection for tests.
  const BeadParams& params() const { return params_; }
  int64_t released(int hopper) const { return released_[hopper]; }
  int64_t left_in_hopper(int hopper) const { return left_[hopper]; }
  int64_t passed_beam() const { return passed_; }
  int64_t double_releases() const { return doubles_; }
  double time() const { return static_cast<double>(t_ns_) * 1e-9; }

 private:
  bool beam_interrupted(int64_t t) const;
  void end_opening(int gate);

  BeadParams params_;
  int64_t after_ns_ = 0, period_ns_ = 0, fall_ns_ = 0, beam_ns_ = 0;

  int64_t t_ns_ = 0;
  int64_t open_ns_[2] = {0, 0};           // how long each gate has been open
  int64_t opening_released_[2] = {0, 0};  // beads released in the current opening
  int64_t left_[2] = {0, 0};
  // Beads in flight or in the beam: the time each reaches the beam. Sized in the
  // constructor for the most that can be under way at once; step() never allocates.
  std::vector<int64_t> arrivals_;
  size_t in_flight_ = 0;

  int64_t released_[2] = {0, 0};
  int64_t passed_ = 0;
  int64_t doubles_ = 0;
};

}  // namespace plcfi::plant
