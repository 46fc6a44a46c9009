// The bead dispenser's plant model and its parameter loader.
#include "plant_model/bead_dispenser/bead_dispenser.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/yaml.hpp"

namespace plcfi::plant {

namespace {

int64_t to_ns(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }

// A time in seconds from lo to an hour (the stand's times are milliseconds).
double seconds(const common::YamlDoc& doc, const YAML::Node& n, const std::string& what, double lo) {
  double v = doc.number(n, what);
  if (v < lo || v > 3600.0) doc.fail(n, fmt::format("{}: {} is outside {}..3600 (seconds)", what, n.Scalar(), lo));
  return v;
}

void read_root(const common::YamlDoc& doc, BeadParams& p) {
  const YAML::Node& root = doc.root();
  doc.check_keys(root, {"gate", "fall_time", "beam_time", "hoppers"}, "the plant parameters", true);
  if (root.IsNull()) return;
  if (const auto g = root["gate"]) {
    doc.check_keys(g, {"release_after", "release_period"}, "gate", true);
    if (const auto v = g["release_after"]) p.release_after = seconds(doc, v, "gate.release_after", 0.0);
    // At least 1 ms: bounds how many beads can be under way at once.
    if (const auto v = g["release_period"]) p.release_period = seconds(doc, v, "gate.release_period", 0.001);
  }
  if (const auto v = root["fall_time"]) p.fall_time = seconds(doc, v, "fall_time", 0.0);
  if (const auto v = root["beam_time"]) p.beam_time = seconds(doc, v, "beam_time", 0.001);
  if (const auto h = root["hoppers"]) {
    doc.check_keys(h, {"black", "white"}, "hoppers", true);
    if (const auto v = h["black"]) p.hopper_beads[0] = doc.integer(v, "hoppers.black", 0, 1'000'000);
    if (const auto v = h["white"]) p.hopper_beads[1] = doc.integer(v, "hoppers.white", 0, 1'000'000);
  }
}

}  // namespace

bool load_bead_params(const std::string& path, BeadParams* params, std::string* err) {
  BeadParams p = *params;
  std::string e;
  if (!common::catch_input_error(&e, [&] { read_root(common::YamlDoc::open(path), p); })) {
    if (err) *err = e;
    return false;
  }
  *params = p;
  return true;
}

BeadDispenserPlant::BeadDispenserPlant(BeadParams params) : params_(params) {
  after_ns_ = to_ns(params_.release_after);
  period_ns_ = std::max<int64_t>(to_ns(params_.release_period), 1'000'000);
  fall_ns_ = to_ns(params_.fall_time);
  beam_ns_ = std::max<int64_t>(to_ns(params_.beam_time), 1);
  // A gate releases at most one bead per period; a bead is under way fall + beam time.
  arrivals_.resize(static_cast<size_t>(2 * ((fall_ns_ + beam_ns_) / period_ns_ + 2)));
  reset(0);
}

const std::string& BeadDispenserPlant::name() const {
  static const std::string n = "bead_dispenser";
  return n;
}

const std::vector<SignalInfo>& BeadDispenserPlant::signals() const {
  static const std::vector<SignalInfo> s = {
      {"Gate1", Direction::ToPlant, SignalKind::Bool, "%QX0.0", "gate of hopper 1 (black): solenoid on = open"},
      {"Gate2", Direction::ToPlant, SignalKind::Bool, "%QX0.1", "gate of hopper 2 (white): solenoid on = open"},
      {"BeadSensor", Direction::FromPlant, SignalKind::Bool, "%IX0.0", "infrared beam below the gates: TRUE while a bead interrupts it"},
  };
  return s;
}

void BeadDispenserPlant::reset(uint64_t /*seed: the stand has no random variation*/) {
  t_ns_ = 0;
  in_flight_ = 0;
  for (int g = 0; g < 2; ++g) {
    open_ns_[g] = 0;
    opening_released_[g] = 0;
    left_[g] = params_.hopper_beads[g];
    released_[g] = 0;
  }
  passed_ = 0;
  doubles_ = 0;
}

void BeadDispenserPlant::end_opening(int gate) {
  if (opening_released_[gate] > 1) ++doubles_;
  open_ns_[gate] = 0;
  opening_released_[gate] = 0;
}

bool BeadDispenserPlant::beam_interrupted(int64_t t) const {
  for (size_t i = 0; i < in_flight_; ++i)
    if (arrivals_[i] <= t && t < arrivals_[i] + beam_ns_) return true;
  return false;
}

void BeadDispenserPlant::step(double dt, const double* actuators, double* sensors) {
  const int64_t dt_ns = std::max<int64_t>(to_ns(dt), 0);
  const int64_t t0 = t_ns_;
  for (int g = 0; g < 2; ++g) {
    if (actuators[g] < 0.5) {
      end_opening(g);
      continue;
    }
    // The gate stays open through this step: every release threshold it passes drops a
    // bead at the moment the threshold is reached.
    const int64_t before = open_ns_[g];
    open_ns_[g] += dt_ns;
    for (;;) {
      const int64_t threshold = after_ns_ + opening_released_[g] * period_ns_;
      if (threshold > open_ns_[g] || left_[g] == 0 || in_flight_ == arrivals_.size()) break;
      const int64_t at = t0 + std::max<int64_t>(threshold - before, 0);
      arrivals_[in_flight_++] = at + fall_ns_;
      ++opening_released_[g];
      ++released_[g];
      --left_[g];
    }
  }
  t_ns_ = t0 + dt_ns;
  // Beads that have left the beam have passed it.
  size_t keep = 0;
  for (size_t i = 0; i < in_flight_; ++i) {
    if (arrivals_[i] + beam_ns_ <= t_ns_) ++passed_;
    else arrivals_[keep++] = arrivals_[i];
  }
  // A bead that entered and left the beam within this step is counted above but was
  // never under the beam at a sample time: a slow scan misses it, as on the stand.
  in_flight_ = keep;
  sense(sensors);
}

void BeadDispenserPlant::sense(double* sensors) const { sensors[kBeadSensor] = beam_interrupted(t_ns_) ? 1.0 : 0.0; }

std::vector<std::pair<std::string, double>> BeadDispenserPlant::stats() const {
  return {{"beads_released_black", static_cast<double>(released_[0])},
          {"beads_released_white", static_cast<double>(released_[1])},
          {"beads_through_beam", static_cast<double>(passed_)},
          {"double_releases", static_cast<double>(doubles_)}};
}

}  // namespace plcfi::plant
