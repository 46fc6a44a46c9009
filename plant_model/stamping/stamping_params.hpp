// Parameters of the stamping-module plant model and their YAML loader (see stamping.yaml).
#pragma once

#include <string>
#include <vector>

namespace plcfi::plant {

enum class SupplyMode { OnDemand, Schedule };
enum class OperatorMode { Auto, Manual };
enum class JogButton { Slider, Stamp };

// A time span [from, to) in seconds of virtual time.
struct TimeSpan {
  double from = 0.0;
  double to = 0.0;
};

struct JogInterval {
  JogButton button = JogButton::Slider;
  TimeSpan span;
};

// Every number is in seconds, except pressures (sensor/setpoint units, 0..10000) and the
// relative variation. The defaults are the plcfi reference plant (stamping-module.md).
struct StampingParams {
  double slider_travel = 0.30;  // s, full stroke of the slider
  double stamp_travel = 0.20;   // s, full stroke of the stamp cylinder
  double variation = 0.02;      // relative, each stroke's travel time is nominal * (1 +- variation)

  double pressure_tau_rise = 0.08;  // s, first-order rise toward the setpoint once lowered
  double pressure_tau_fall = 0.05;  // s, first-order fall toward 0 otherwise

  double stamp_min_pressure = 5700.0;  // pressure that counts as pressing
  double stamp_min_time = 1.0;         // s of pressing for a stamped WP
  double stamp_max_time = 3.5;         // s of pressing beyond which the WP is defective

  SupplyMode supply_mode = SupplyMode::OnDemand;
  double supply_delay = 1.0;                 // s, on_demand: StationEmpty held this long -> WP
  std::vector<double> supply_schedule;       // s, schedule: delivery times

  double handover_delay = 0.5;  // s, hand-over conditions held this long -> WP taken

  bool next_ready = true;           // the next module's NextReady outside busy spans
  std::vector<TimeSpan> next_busy;  // spans in which NextReady is FALSE

  OperatorMode operator_mode = OperatorMode::Auto;
  bool operator_start = true;         // false: the start button is never pressed
  double operator_start_at = 0.1;     // s
  double operator_press_time = 0.2;   // s, duration of every button press (start, ack)
  std::vector<double> operator_ack_at;     // s, acknowledge presses
  std::vector<JogInterval> operator_jogs;  // manual jog buttons held during spans
};

// Reads a YAML parameter file over the defaults. On error returns false and sets err to
// "FILE:LINE:COL: message" (1-based; the wording of common/yaml.hpp), or a file error
// ("FILE: cannot open (REASON)", "FILE: is a directory", ...).
bool load_stamping_params(const std::string& path, StampingParams* params, std::string* err);

}  // namespace plcfi::plant
