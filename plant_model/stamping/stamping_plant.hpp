// The stamping module's plant model: slider, stamp cylinder, pressure, workpieces, operator.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "plant_model/plant.hpp"
#include "plant_model/stamping/stamping_params.hpp"

namespace plcfi::plant {

// Disjoint, sorted time spans [from, to) in nanoseconds with a forward-only cursor: virtual
// time only grows between resets, so asking "is t inside a span" is amortized O(1).
class SpanTrack {
 public:
  // Sorts and merges overlapping spans (allocates: call outside step()).
  void assign(std::vector<std::pair<int64_t, int64_t>> spans);
  void rewind() { cursor_ = 0; }
  bool active(int64_t t) {
    while (cursor_ < spans_.size() && t >= spans_[cursor_].second) ++cursor_;
    return cursor_ < spans_.size() && t >= spans_[cursor_].first;
  }
  // The first span boundary after t, or INT64_MAX (call after active(t)).
  int64_t next_change(int64_t t) const {
    if (cursor_ >= spans_.size()) return INT64_MAX;
    return t >= spans_[cursor_].first ? spans_[cursor_].second : spans_[cursor_].first;
  }

 private:
  std::vector<std::pair<int64_t, int64_t>> spans_;
  size_t cursor_ = 0;
};

class StampingPlant final : public Plant {
 public:
  // Signal indices: the README's I/O map order, fixed because PLC programs bind to it.
  static constexpr int kPosCrane = 0;
  static constexpr int kPosStamp = 1;
  static constexpr int kFilled = 2;
  static constexpr int kStampUp = 3;
  static constexpr int kStampLowered = 4;
  static constexpr int kModeAuto = 5;
  static constexpr int kStartButton = 6;
  static constexpr int kAckButton = 7;
  static constexpr int kNextReady = 8;
  static constexpr int kManSlider = 9;
  static constexpr int kManStamp = 10;
  static constexpr int kStampPressure = 11;
  static constexpr int kSliderExtend = 12;
  static constexpr int kStampDown = 13;
  static constexpr int kWorkpieceReady = 14;
  static constexpr int kStationEmpty = 15;
  static constexpr int kAlarmLamp = 16;
  static constexpr int kWarningLamp = 17;
  static constexpr int kPressureSetpoint = 18;
  static constexpr int kSignalCount = 19;

  // Full scale of the pressure sensor and setpoint.
  static constexpr double kMaxPressure = 10000.0;

  explicit StampingPlant(StampingParams params = {});

  const std::string& name() const override;
  const std::vector<SignalInfo>& signals() const override;
  void reset(uint64_t seed) override;
  void step(double dt, const double* actuators, double* sensors) override;
  void sense(double* sensors) const override;
  std::vector<std::pair<std::string, double>> stats() const override;

  // Inspection for tests and traces (not part of the Plant interface).
  const StampingParams& params() const { return params_; }
  double time() const { return static_cast<double>(t_ns_) * 1e-9; }
  double slider_position() const { return slider_pos_; }
  double stamp_position() const { return stamp_pos_; }
  double pressure() const { return pressure_; }
  bool workpiece_present() const { return wp_present_; }
  double press_time() const { return static_cast<double>(press_ns_) * 1e-9; }
  // Nominal travel time of the current (or last) stroke, variation included.
  double slider_stroke_time() const { return 1.0 / slider_rate_; }
  double stamp_stroke_time() const { return 1.0 / stamp_rate_; }

 private:
  void set_dt(double dt);
  double draw_rate(double nominal_travel);
  void place_workpiece();
  void take_workpiece();
  void update_operator();

  StampingParams params_;

  // Precomputed from params_ (constructor) so that step() is plain arithmetic.
  int64_t supply_delay_ns_ = 0;
  int64_t handover_delay_ns_ = 0;
  int64_t min_press_ns_ = 0;
  int64_t max_press_ns_ = 0;
  std::vector<int64_t> schedule_ns_;  // sorted delivery times
  SpanTrack start_span_, ack_spans_, jog_slider_spans_, jog_stamp_spans_, busy_spans_;

  // Per-dt cache: the runtime steps with a constant scan period, so exp() runs once.
  double cached_dt_ = -1.0;
  int64_t dt_ns_ = 0;
  double rise_decay_ = 0.0;  // exp(-dt / tau_rise)
  double fall_decay_ = 0.0;  // exp(-dt / tau_fall)

  // Physical state.
  uint64_t rng_ = 0;
  int64_t t_ns_ = 0;  // virtual time in integer ns: event times compare exactly, no drift
  double slider_pos_ = 0.0;  // 0 retracted (PosCrane) .. 1 extended (PosStamp)
  double slider_rate_ = 0.0;  // stroke fractions per second of the current stroke
  bool slider_valve_ = false;
  double stamp_pos_ = 0.0;  // 0 up .. 1 lowered
  double stamp_rate_ = 0.0;
  bool stamp_valve_ = false;
  double pressure_ = 0.0;
  bool wp_present_ = false;
  int64_t press_ns_ = 0;  // time the current WP has been pressed at min_pressure or more
  bool wp_collided_ = false;
  bool colliding_ = false;  // a collision is in progress (counted once)
  int64_t supply_timer_ns_ = 0;
  int64_t handover_timer_ns_ = 0;
  size_t schedule_next_ = 0;

  // Operator and neighbour signals at the current time.
  bool start_on_ = false;
  bool ack_on_ = false;
  bool jog_slider_on_ = false;
  bool jog_stamp_on_ = false;
  bool next_ready_on_ = true;
  // When the next of them changes: step() skips update_operator() until then.
  int64_t operator_change_ns_ = 0;

  // Statistics.
  uint64_t supplied_ = 0;
  uint64_t stamped_ = 0;
  uint64_t defective_ = 0;
  uint64_t collisions_ = 0;
  uint64_t slider_strokes_ = 0;
  uint64_t stamp_strokes_ = 0;
};

}  // namespace plcfi::plant
