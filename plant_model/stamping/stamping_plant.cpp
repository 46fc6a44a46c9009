// Physics of the stamping module (README.md beside this file): two pneumatic cylinders, a
// first-order pressure, workpiece supply/stamping/hand-over and a scripted operator.
#include "plant_model/stamping/stamping_plant.hpp"

#include <algorithm>
#include <cmath>

namespace plcfi::plant {

namespace {

const std::string kName = "stamping";

// Positions accumulate 1/travel * dt per step; after n steps the sum may miss 1.0 by a
// few ulps. Snapping within this distance makes the end sensor switch in the step in
// which the travel is complete instead of one step late.
constexpr double kEndEps = 1e-9;
// Below this the falling pressure is set to 0: the sensor reads 0 anyway, and repeated
// multiplication would otherwise end in subnormal numbers, which are slow on x86.
constexpr double kPressureFloor = 1e-6;

int64_t to_ns(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e9)); }

// splitmix64: tiny, fast, and fully specified integer arithmetic, so the same seed gives
// the same variation on every platform (std:: distributions are not portable).
uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Moves a cylinder position toward 1 (energized) or 0 at the given stroke fraction.
inline void move(double& pos, bool energized, double delta) {
  if (energized) {
    pos += delta;
    if (pos >= 1.0 - kEndEps) pos = 1.0;
  } else {
    pos -= delta;
    if (pos <= kEndEps) pos = 0.0;
  }
}

inline double flag(bool b) { return b ? 1.0 : 0.0; }

std::vector<SignalInfo> make_signals() {
  using D = Direction;
  using K = SignalKind;
  return {
      {"PosCrane", D::FromPlant, K::Bool, "%IX0.0", "slider retracted (crane / hand-over position)"},
      {"PosStamp", D::FromPlant, K::Bool, "%IX0.1", "slider extended (WP under the stamp)"},
      {"Filled", D::FromPlant, K::Bool, "%IX0.2", "a WP lies on the slider"},
      {"StampUp", D::FromPlant, K::Bool, "%IX0.3", "stamp cylinder retracted"},
      {"StampLowered", D::FromPlant, K::Bool, "%IX0.4", "stamp cylinder extended (on the WP)"},
      {"ModeAuto", D::FromPlant, K::Bool, "%IX0.5", "operating-mode switch: TRUE automatic, FALSE manual"},
      {"StartButton", D::FromPlant, K::Bool, "%IX0.6", "start push-button (momentary)"},
      {"AckButton", D::FromPlant, K::Bool, "%IX0.7", "alarm acknowledge push-button (momentary)"},
      {"NextReady", D::FromPlant, K::Bool, "%IX1.0", "module interface: the next module can take a WP"},
      {"ManSlider", D::FromPlant, K::Bool, "%IX1.1", "manual mode: jog button \"slider extend\" (held)"},
      {"ManStamp", D::FromPlant, K::Bool, "%IX1.2", "manual mode: jog button \"stamp down\" (held)"},
      {"StampPressure", D::FromPlant, K::Analog, "%IW2", "stamping pressure, 0..10000 (same units as the setpoint)"},
      {"SliderExtend", D::ToPlant, K::Bool, "%QX0.0", "slider valve (5/2 monostable: energized = extend, else retract)"},
      {"StampDown", D::ToPlant, K::Bool, "%QX0.1", "stamp valve (energized = lower, else raise)"},
      {"WorkpieceReady", D::ToPlant, K::Bool, "%QX0.2", "module interface: a stamped WP can be taken"},
      {"StationEmpty", D::ToPlant, K::Bool, "%QX0.3", "module interface: ready to receive a WP"},
      {"AlarmLamp", D::ToPlant, K::Bool, "%QX0.4", "red lamp: class-1 alarm, module stopped"},
      {"WarningLamp", D::ToPlant, K::Bool, "%QX0.5", "yellow lamp: class-2 warning"},
      {"PressureSetpoint", D::ToPlant, K::Analog, "%QW2", "stamping pressure setpoint, 0..10000"},
  };
}

std::pair<int64_t, int64_t> span_ns(double from, double to) { return {to_ns(from), to_ns(to)}; }

}  // namespace

void SpanTrack::assign(std::vector<std::pair<int64_t, int64_t>> spans) {
  std::sort(spans.begin(), spans.end());
  spans_.clear();
  for (const auto& s : spans) {
    if (s.second <= s.first) continue;
    if (!spans_.empty() && s.first <= spans_.back().second) spans_.back().second = std::max(spans_.back().second, s.second);
    else spans_.push_back(s);
  }
  cursor_ = 0;
}

StampingPlant::StampingPlant(StampingParams params) : params_(std::move(params)) {
  const StampingParams& p = params_;
  supply_delay_ns_ = to_ns(p.supply_delay);
  handover_delay_ns_ = to_ns(p.handover_delay);
  min_press_ns_ = to_ns(p.stamp_min_time);
  max_press_ns_ = to_ns(p.stamp_max_time);
  for (double t : p.supply_schedule) schedule_ns_.push_back(to_ns(t));
  std::sort(schedule_ns_.begin(), schedule_ns_.end());

  if (p.operator_start) start_span_.assign({span_ns(p.operator_start_at, p.operator_start_at + p.operator_press_time)});
  std::vector<std::pair<int64_t, int64_t>> acks, jog_slider, jog_stamp, busy;
  for (double t : p.operator_ack_at) acks.push_back(span_ns(t, t + p.operator_press_time));
  for (const auto& j : p.operator_jogs) (j.button == JogButton::Slider ? jog_slider : jog_stamp).push_back(span_ns(j.span.from, j.span.to));
  for (const auto& b : p.next_busy) busy.push_back(span_ns(b.from, b.to));
  ack_spans_.assign(std::move(acks));
  jog_slider_spans_.assign(std::move(jog_slider));
  jog_stamp_spans_.assign(std::move(jog_stamp));
  busy_spans_.assign(std::move(busy));
  reset(0);
}

const std::string& StampingPlant::name() const { return kName; }

const std::vector<SignalInfo>& StampingPlant::signals() const {
  static const std::vector<SignalInfo> kSignals = make_signals();
  return kSignals;
}

void StampingPlant::reset(uint64_t seed) {
  rng_ = seed;
  t_ns_ = 0;
  // At rest before any valve change: nominal rates (a stroke draws its own on start).
  slider_pos_ = 0.0;
  slider_rate_ = 1.0 / params_.slider_travel;
  slider_valve_ = false;
  stamp_pos_ = 0.0;
  stamp_rate_ = 1.0 / params_.stamp_travel;
  stamp_valve_ = false;
  pressure_ = 0.0;
  wp_present_ = false;
  press_ns_ = 0;
  wp_collided_ = false;
  colliding_ = false;
  supply_timer_ns_ = 0;
  handover_timer_ns_ = 0;
  schedule_next_ = 0;
  start_span_.rewind();
  ack_spans_.rewind();
  jog_slider_spans_.rewind();
  jog_stamp_spans_.rewind();
  busy_spans_.rewind();
  update_operator();
  supplied_ = stamped_ = defective_ = collisions_ = slider_strokes_ = stamp_strokes_ = 0;
}

void StampingPlant::set_dt(double dt) {
  cached_dt_ = dt;
  dt_ns_ = to_ns(dt);
  rise_decay_ = std::exp(-dt / params_.pressure_tau_rise);
  fall_decay_ = std::exp(-dt / params_.pressure_tau_fall);
}

double StampingPlant::draw_rate(double nominal_travel) {
  // 53 random bits -> u in [0, 1) -> factor uniform in [1 - variation, 1 + variation).
  const double u = static_cast<double>(splitmix64(rng_) >> 11) * 0x1.0p-53;
  return 1.0 / (nominal_travel * (1.0 + params_.variation * (2.0 * u - 1.0)));
}

void StampingPlant::place_workpiece() {
  wp_present_ = true;
  press_ns_ = 0;
  wp_collided_ = false;
  supply_timer_ns_ = 0;
  ++supplied_;
}

void StampingPlant::take_workpiece() {
  wp_present_ = false;
  handover_timer_ns_ = 0;
  if (press_ns_ >= min_press_ns_ && press_ns_ <= max_press_ns_ && !wp_collided_) ++stamped_;
  else ++defective_;
}

void StampingPlant::update_operator() {
  start_on_ = start_span_.active(t_ns_);
  ack_on_ = ack_spans_.active(t_ns_);
  jog_slider_on_ = jog_slider_spans_.active(t_ns_);
  jog_stamp_on_ = jog_stamp_spans_.active(t_ns_);
  next_ready_on_ = params_.next_ready && !busy_spans_.active(t_ns_);
  operator_change_ns_ = std::min({start_span_.next_change(t_ns_), ack_spans_.next_change(t_ns_),
                                  jog_slider_spans_.next_change(t_ns_), jog_stamp_spans_.next_change(t_ns_),
                                  busy_spans_.next_change(t_ns_)});
}

void StampingPlant::step(double dt, const double* actuators, double* sensors) {
  if (!(dt > 0.0)) {  // also NaN: nothing happens in no time
    StampingPlant::sense(sensors);
    return;
  }
  if (dt != cached_dt_) set_dt(dt);
  const bool slider_cmd = actuators[kSliderExtend] != 0.0;
  const bool stamp_cmd = actuators[kStampDown] != 0.0;
  const bool ready_cmd = actuators[kWorkpieceReady] != 0.0;
  const bool empty_cmd = actuators[kStationEmpty] != 0.0;
  // The regulator cannot go below 0 or beyond full scale; !(x > 0) also maps NaN to 0.
  double setpoint = actuators[kPressureSetpoint];
  if (!(setpoint > 0.0)) setpoint = 0.0;
  if (setpoint > kMaxPressure) setpoint = kMaxPressure;
  // NextReady as the PLC saw it during this scan (the value sensed at the end of the last step).
  const bool next_ready = next_ready_on_;

  // Cylinders: a valve change starts a stroke with its own random travel time.
  if (slider_cmd != slider_valve_) {
    slider_valve_ = slider_cmd;
    slider_rate_ = draw_rate(params_.slider_travel);
  }
  if (stamp_cmd != stamp_valve_) {
    stamp_valve_ = stamp_cmd;
    stamp_rate_ = draw_rate(params_.stamp_travel);
  }
  const double slider_old = slider_pos_;
  const double stamp_old = stamp_pos_;
  move(slider_pos_, slider_cmd, slider_rate_ * dt);
  move(stamp_pos_, stamp_cmd, stamp_rate_ * dt);
  if (slider_cmd && slider_old < 1.0 && slider_pos_ == 1.0) ++slider_strokes_;
  if (stamp_cmd && stamp_old < 1.0 && stamp_pos_ == 1.0) ++stamp_strokes_;

  // Part of this step spent fully lowered with the valve energized: the stamp reaches the
  // end mid-step, and the pressure and pressing time count only from there.
  double lowered_dt = 0.0;
  if (stamp_cmd && stamp_pos_ == 1.0) {
    lowered_dt = stamp_old == 1.0 ? dt : dt - (1.0 - stamp_old) / stamp_rate_;
    if (lowered_dt < 0.0) lowered_dt = 0.0;
  }

  // Pressure: first order toward the setpoint while lowered, toward 0 otherwise.
  if (lowered_dt == dt) {
    pressure_ = setpoint + (pressure_ - setpoint) * rise_decay_;
  } else if (lowered_dt > 0.0) {  // rare: the step in which the stamp arrives
    pressure_ *= std::exp(-(dt - lowered_dt) / params_.pressure_tau_fall);
    pressure_ = setpoint + (pressure_ - setpoint) * std::exp(-lowered_dt / params_.pressure_tau_rise);
  } else if (pressure_ != 0.0) {
    pressure_ *= fall_decay_;
  }
  if (pressure_ < kPressureFloor) pressure_ = 0.0;

  // Pressing counts with the WP under the stamp for the whole step (the slider at
  // PosStamp), the stamp lowered and the pressure at least min_pressure.
  if (wp_present_ && lowered_dt > 0.0 && slider_old == 1.0 && slider_pos_ == 1.0 && pressure_ >= params_.stamp_min_pressure)
    press_ns_ += lowered_dt == dt ? dt_ns_ : to_ns(lowered_dt);

  // Collision: the slider moves while the stamp is not up (at start or end of the step).
  // The model does not jam the slider; it counts the event once and spoils the WP.
  const bool collision = slider_pos_ != slider_old && (stamp_old > 0.0 || stamp_pos_ > 0.0);
  if (collision && !colliding_) ++collisions_;
  if (collision && wp_present_) wp_collided_ = true;
  colliding_ = collision;

  t_ns_ += dt_ns_;

  // Supply first: it needs an empty slider, so a WP taken in this step is replaced no
  // earlier than the next one.
  const bool can_receive = empty_cmd && !wp_present_ && slider_pos_ == 0.0;
  if (params_.supply_mode == SupplyMode::OnDemand) {
    if (can_receive) {
      supply_timer_ns_ += dt_ns_;
      if (supply_timer_ns_ >= supply_delay_ns_) place_workpiece();
    } else {
      supply_timer_ns_ = 0;
    }
  } else if (can_receive && schedule_next_ < schedule_ns_.size() && t_ns_ >= schedule_ns_[schedule_next_]) {
    ++schedule_next_;  // a WP due earlier waited on the crane until now
    place_workpiece();
  }

  if (ready_cmd && wp_present_ && slider_pos_ == 0.0 && next_ready) {
    handover_timer_ns_ += dt_ns_;
    if (handover_timer_ns_ >= handover_delay_ns_) take_workpiece();
  } else {
    handover_timer_ns_ = 0;
  }

  if (t_ns_ >= operator_change_ns_) update_operator();
  StampingPlant::sense(sensors);  // qualified: no virtual dispatch inside step()
}

void StampingPlant::sense(double* sensors) const {
  sensors[kPosCrane] = flag(slider_pos_ == 0.0);
  sensors[kPosStamp] = flag(slider_pos_ == 1.0);
  sensors[kFilled] = flag(wp_present_);
  sensors[kStampUp] = flag(stamp_pos_ == 0.0);
  sensors[kStampLowered] = flag(stamp_pos_ == 1.0);
  sensors[kModeAuto] = flag(params_.operator_mode == OperatorMode::Auto);
  sensors[kStartButton] = flag(start_on_);
  sensors[kAckButton] = flag(ack_on_);
  sensors[kNextReady] = flag(next_ready_on_);
  sensors[kManSlider] = flag(jog_slider_on_);
  sensors[kManStamp] = flag(jog_stamp_on_);
  // pressure_ is within [0, kMaxPressure] (clamped setpoint), so truncation of +0.5 rounds.
  sensors[kStampPressure] = static_cast<double>(static_cast<int32_t>(pressure_ + 0.5));
}

std::vector<std::pair<std::string, double>> StampingPlant::stats() const {
  return {
      {"workpieces_supplied", static_cast<double>(supplied_)},
      {"workpieces_stamped", static_cast<double>(stamped_)},
      {"workpieces_defective", static_cast<double>(defective_)},
      {"collisions", static_cast<double>(collisions_)},
      {"slider_strokes", static_cast<double>(slider_strokes_)},
      {"stamp_strokes", static_cast<double>(stamp_strokes_)},
  };
}

}  // namespace plcfi::plant
