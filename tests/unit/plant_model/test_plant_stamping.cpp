// Stamping plant model: one test per physical invariant of plant_model/stamping/README.md,
// driven through step() with actuator arrays at a 10 ms scan, plus the YAML loader.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <string>
#include <vector>

#include "plant_model/plant.hpp"
#include "plant_model/stamping/stamping_plant.hpp"

namespace plcfi::plant {
namespace {

using SP = StampingPlant;
constexpr double kDt = 0.01;

// A plant with its actuator and sensor arrays, stepped like the scan runtime does.
struct Rig {
  explicit Rig(StampingParams p = {}, uint64_t seed = 1) : plant(std::move(p)) {
    plant.reset(seed);
    plant.sense(sen.data());
  }
  void step(int n = 1) {
    for (int i = 0; i < n; ++i) plant.step(kDt, act.data(), sen.data());
  }
  // Steps until pred holds (checked after each step); returns the steps taken or -1.
  int until(const std::function<bool()>& pred, int max_steps = 100000) {
    for (int i = 1; i <= max_steps; ++i) {
      step();
      if (pred()) return i;
    }
    return -1;
  }
  bool s(int i) const { return sen[i] != 0.0; }
  void set(int i, double v) { act[i] = v; }
  double stat(const std::string& name) const {
    for (const auto& [n, v] : plant.stats())
      if (n == name) return v;
    ADD_FAILURE() << "no stat " << name;
    return -1;
  }

  StampingPlant plant;
  std::vector<double> act = std::vector<double>(SP::kSignalCount, 0.0);
  std::vector<double> sen = std::vector<double>(SP::kSignalCount, 0.0);
};

// Gets a WP onto the slider (on_demand supply) and clears StationEmpty.
void supply(Rig& r) {
  r.set(SP::kStationEmpty, 1);
  ASSERT_GT(r.until([&] { return r.s(SP::kFilled); }), 0);
  r.set(SP::kStationEmpty, 0);
}

// Supply, extend, lower for `hold` s after StampLowered at 6000, raise, retract, hand over.
void cycle(Rig& r, double hold) {
  supply(r);
  r.set(SP::kSliderExtend, 1);
  ASSERT_GT(r.until([&] { return r.s(SP::kPosStamp); }), 0);
  r.set(SP::kPressureSetpoint, 6000);
  r.set(SP::kStampDown, 1);
  ASSERT_GT(r.until([&] { return r.s(SP::kStampLowered); }), 0);
  r.step(static_cast<int>(std::lround(hold / kDt)));
  r.set(SP::kStampDown, 0);
  ASSERT_GT(r.until([&] { return r.s(SP::kStampUp); }), 0);
  r.set(SP::kSliderExtend, 0);
  ASSERT_GT(r.until([&] { return r.s(SP::kPosCrane); }), 0);
  r.set(SP::kWorkpieceReady, 1);
  ASSERT_GT(r.until([&] { return !r.s(SP::kFilled); }, 200), 0);
  r.set(SP::kWorkpieceReady, 0);
}

TEST(PlantStamping, SignalsFollowTheIoMap) {
  StampingPlant p;
  const auto& sig = p.signals();
  ASSERT_EQ(sig.size(), static_cast<size_t>(SP::kSignalCount));
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"PosCrane", "%IX0.0"}, {"PosStamp", "%IX0.1"}, {"Filled", "%IX0.2"}, {"StampUp", "%IX0.3"},
      {"StampLowered", "%IX0.4"}, {"ModeAuto", "%IX0.5"}, {"StartButton", "%IX0.6"}, {"AckButton", "%IX0.7"},
      {"NextReady", "%IX1.0"}, {"ManSlider", "%IX1.1"}, {"ManStamp", "%IX1.2"}, {"StampPressure", "%IW2"},
      {"SliderExtend", "%QX0.0"}, {"StampDown", "%QX0.1"}, {"WorkpieceReady", "%QX0.2"}, {"StationEmpty", "%QX0.3"},
      {"AlarmLamp", "%QX0.4"}, {"WarningLamp", "%QX0.5"}, {"PressureSetpoint", "%QW2"}};
  for (size_t i = 0; i < sig.size(); ++i) {
    EXPECT_EQ(sig[i].name, expected[i].first) << i;
    EXPECT_EQ(sig[i].address, expected[i].second) << i;
    EXPECT_EQ(sig[i].dir, i < 12 ? Direction::FromPlant : Direction::ToPlant) << i;
    EXPECT_EQ(sig[i].kind, i == 11 || i == 18 ? SignalKind::Analog : SignalKind::Bool) << i;
    EXPECT_FALSE(sig[i].description.empty()) << i;
  }
  EXPECT_EQ(p.name(), "stamping");
}

TEST(PlantStamping, InitialStateAfterReset) {
  Rig r;
  std::vector<double> expect(SP::kSignalCount, 0.0);
  expect[SP::kPosCrane] = expect[SP::kStampUp] = expect[SP::kModeAuto] = expect[SP::kNextReady] = 1.0;
  for (int i = 0; i < 12; ++i) EXPECT_EQ(r.sen[i], expect[i]) << r.plant.signals()[i].name;
  // dt 0 changes nothing.
  r.set(SP::kSliderExtend, 1);
  r.plant.step(0.0, r.act.data(), r.sen.data());
  EXPECT_EQ(r.plant.slider_position(), 0.0);
  EXPECT_EQ(r.plant.time(), 0.0);
}

TEST(PlantStamping, CylinderMovesOnlyWhileValveEnergizedAndBackOnlyWhileNot) {
  for (int cyl = 0; cyl < 2; ++cyl) {
    Rig r;
    const int valve = cyl == 0 ? SP::kSliderExtend : SP::kStampDown;
    auto pos = [&] { return cyl == 0 ? r.plant.slider_position() : r.plant.stamp_position(); };
    r.step(50);  // not energized: stays retracted
    EXPECT_EQ(pos(), 0.0);
    r.set(valve, 1);
    double last = pos();
    for (int i = 0; i < 10; ++i) {  // part of a stroke: strictly forward
      r.step();
      EXPECT_GT(pos(), last);
      last = pos();
    }
    EXPECT_LT(pos(), 1.0);
    r.set(valve, 0);
    for (int i = 0; i < 100; ++i) {  // released mid-stroke: only backward, to 0
      r.step();
      EXPECT_LE(pos(), last);
      last = pos();
    }
    EXPECT_EQ(pos(), 0.0);
    r.set(valve, 1);
    for (int i = 0; i < 100; ++i) {  // energized: only forward, to 1, and stays there
      r.step();
      EXPECT_GE(pos(), last);
      last = pos();
    }
    EXPECT_EQ(pos(), 1.0);
  }
}

TEST(PlantStamping, EndSensorsReflectPositions) {
  Rig r;
  uint32_t lcg = 12345;
  for (int i = 0; i < 5000; ++i) {
    if (i % 7 == 0) {  // pseudo-random valve pattern including partial strokes
      lcg = lcg * 1664525u + 1013904223u;
      r.set(SP::kSliderExtend, (lcg >> 16) & 1);
      r.set(SP::kStampDown, (lcg >> 17) & 1);
    }
    r.step();
    const double s = r.plant.slider_position(), m = r.plant.stamp_position();
    ASSERT_EQ(r.s(SP::kPosCrane), s == 0.0) << i;
    ASSERT_EQ(r.s(SP::kPosStamp), s == 1.0) << i;
    ASSERT_FALSE(r.s(SP::kPosCrane) && r.s(SP::kPosStamp)) << i;
    ASSERT_EQ(r.s(SP::kStampUp), m == 0.0) << i;
    ASSERT_EQ(r.s(SP::kStampLowered), m == 1.0) << i;
    ASSERT_FALSE(r.s(SP::kStampUp) && r.s(SP::kStampLowered)) << i;
  }
}

TEST(PlantStamping, EndSensorSwitchesExactlyAtEndOfTravel) {
  StampingParams p;
  p.variation = 0.0;
  Rig r(p);
  r.set(SP::kSliderExtend, 1);
  // 0.30 s at 10 ms: the 30th step completes the travel (despite rounding of 30 x 1/30).
  EXPECT_EQ(r.until([&] { return r.s(SP::kPosStamp); }), 30);
  EXPECT_FALSE(r.s(SP::kPosCrane));
  r.set(SP::kSliderExtend, 0);
  EXPECT_FALSE(r.s(SP::kPosCrane));
  EXPECT_EQ(r.until([&] { return r.s(SP::kPosCrane); }), 30);
  r.set(SP::kStampDown, 1);
  EXPECT_EQ(r.until([&] { return r.s(SP::kStampLowered); }), 20);
  // PosCrane fell in the first step of the stroke (the slider left the end).
  r.set(SP::kSliderExtend, 1);
  r.set(SP::kStampDown, 0);
  r.step();
  EXPECT_FALSE(r.s(SP::kPosCrane));
}

TEST(PlantStamping, TravelTimeWithinVariation) {
  const StampingParams p;
  for (uint64_t seed = 0; seed < 50; ++seed) {
    Rig r(p, seed);
    r.set(SP::kSliderExtend, 1);
    const double slider = r.until([&] { return r.s(SP::kPosStamp); }) * kDt;
    EXPECT_GE(slider, p.slider_travel * (1 - p.variation) - 1e-9);
    EXPECT_LE(slider, p.slider_travel * (1 + p.variation) + kDt);
    r.set(SP::kStampDown, 1);
    const double stamp = r.until([&] { return r.s(SP::kStampLowered); }) * kDt;
    EXPECT_GE(stamp, p.stamp_travel * (1 - p.variation) - 1e-9);
    EXPECT_LE(stamp, p.stamp_travel * (1 + p.variation) + kDt);
    EXPECT_NEAR(r.plant.slider_stroke_time(), p.slider_travel, p.slider_travel * p.variation);
    EXPECT_NEAR(r.plant.stamp_stroke_time(), p.stamp_travel, p.stamp_travel * p.variation);
  }
}

TEST(PlantStamping, PressureBuildsOnlyLoweredWithSetpoint) {
  Rig r;
  r.set(SP::kPressureSetpoint, 6000);
  r.step(100);  // setpoint with the stamp up: no pressure
  EXPECT_EQ(r.sen[SP::kStampPressure], 0.0);
  r.set(SP::kPressureSetpoint, 0);
  r.set(SP::kStampDown, 1);
  ASSERT_GT(r.until([&] { return r.s(SP::kStampLowered); }), 0);
  r.step(100);  // lowered without setpoint: no pressure
  EXPECT_EQ(r.sen[SP::kStampPressure], 0.0);
  r.set(SP::kStampDown, 0);
  ASSERT_GT(r.until([&] { return r.s(SP::kStampUp); }), 0);

  // Stamp() at 6000: nothing until StampLowered, then a monotone first-order rise.
  r.set(SP::kPressureSetpoint, 6000);
  r.set(SP::kStampDown, 1);
  int steps = 0;
  while (!r.s(SP::kStampLowered)) {
    EXPECT_EQ(r.sen[SP::kStampPressure], 0.0);
    r.step();
    ++steps;
  }
  double last = r.sen[SP::kStampPressure];
  int min_pressure_at = -1;
  for (int i = 1; i <= 50; ++i) {  // 0.5 s after StampLowered
    r.step();
    EXPECT_GE(r.sen[SP::kStampPressure], last);
    last = r.sen[SP::kStampPressure];
    if (min_pressure_at < 0 && last >= 5700) min_pressure_at = steps + i;
  }
  // Stamp() -> at least stamp.min_pressure within 0.5 s (the reference postcondition with
  // tolerance); within 0.5 s of lowering 1 - exp(-0.5/0.08) = 99.8 % of the setpoint.
  EXPECT_GT(min_pressure_at, 0);
  EXPECT_LE(min_pressure_at * kDt, 0.5 + 1e-9);
  EXPECT_GE(last, 5985);
  EXPECT_LE(last, 6000);
  r.step(50);  // and exactly the setpoint once settled (0.08 s * ln(12000) = 0.75 s)
  EXPECT_EQ(r.sen[SP::kStampPressure], 6000);

  // Raised: falls immediately and strictly (the sensor reads 0 after 0.6 s: tau 0.05 s).
  r.set(SP::kStampDown, 0);
  double raw = r.plant.pressure();
  for (int i = 0; i < 60; ++i) {
    r.step();
    EXPECT_LT(r.plant.pressure(), raw) << i;
    EXPECT_LE(r.sen[SP::kStampPressure], last) << i;
    raw = r.plant.pressure();
    last = r.sen[SP::kStampPressure];
  }
  EXPECT_EQ(r.sen[SP::kStampPressure], 0.0);
  r.step(100);
  EXPECT_EQ(r.plant.pressure(), 0.0);  // flushed to 0, no subnormal tail
}

TEST(PlantStamping, PressureSensorClampedAndRounded) {
  Rig r;
  r.set(SP::kPressureSetpoint, 30000);  // beyond full scale
  r.set(SP::kStampDown, 1);
  r.step(300);
  EXPECT_EQ(r.sen[SP::kStampPressure], 10000);
  r.set(SP::kPressureSetpoint, -500);  // negative setpoint: regulator goes to 0
  r.step(300);
  EXPECT_EQ(r.sen[SP::kStampPressure], 0);
  r.set(SP::kPressureSetpoint, 1234.4);
  r.step(300);
  EXPECT_EQ(r.sen[SP::kStampPressure], 1234);
}

TEST(PlantStamping, StampedOnlyIfPressedLongEnoughAtPressure) {
  struct Case {
    double hold;  // s after StampLowered at setpoint 6000
    bool stamped;
  };
  for (const Case c : {Case{0.5, false}, Case{1.5, true}, Case{4.0, false}}) {
    Rig r;
    cycle(r, c.hold);
    EXPECT_EQ(r.stat("workpieces_stamped"), c.stamped ? 1 : 0) << c.hold;
    EXPECT_EQ(r.stat("workpieces_defective"), c.stamped ? 0 : 1) << c.hold;
  }
  // Lowered long enough but below stamp.min_pressure: not stamped.
  Rig r;
  supply(r);
  r.set(SP::kSliderExtend, 1);
  r.step(50);
  r.set(SP::kPressureSetpoint, 5000);
  r.set(SP::kStampDown, 1);
  r.step(200);
  EXPECT_EQ(r.plant.press_time(), 0.0);
}

TEST(PlantStamping, PressingCountsOnlyWithWorkpieceUnderStamp) {
  Rig r;
  r.set(SP::kPressureSetpoint, 6000);
  r.set(SP::kStampDown, 1);  // slider at PosCrane: the WP is not under the stamp
  supply(r);
  r.step(200);
  EXPECT_EQ(r.plant.press_time(), 0.0);
}

TEST(PlantStamping, CollisionWhenSliderMovesWithStampNotUp) {
  Rig r;
  supply(r);
  r.set(SP::kSliderExtend, 1);
  r.step(50);
  r.set(SP::kPressureSetpoint, 6000);
  r.set(SP::kStampDown, 1);
  r.step(170);  // pressed long enough: would be stamped
  EXPECT_EQ(r.stat("collisions"), 0);
  r.set(SP::kSliderExtend, 0);  // retract under the lowered stamp
  r.step(50);
  EXPECT_EQ(r.stat("collisions"), 1);  // one event, not one per step
  r.set(SP::kStampDown, 0);
  r.step(50);
  r.set(SP::kWorkpieceReady, 1);
  r.step(60);
  EXPECT_FALSE(r.s(SP::kFilled));
  EXPECT_EQ(r.stat("workpieces_stamped"), 0);
  EXPECT_EQ(r.stat("workpieces_defective"), 1);

  // Stamp only slightly down (not StampUp) while the slider moves: also a collision.
  Rig q;
  q.set(SP::kStampDown, 1);
  q.step(2);
  q.set(SP::kStampDown, 0);
  q.set(SP::kSliderExtend, 1);
  q.step();
  EXPECT_EQ(q.stat("collisions"), 1);
  // Slider moving with the stamp up: none.
  Rig ok;
  ok.set(SP::kSliderExtend, 1);
  ok.step(100);
  ok.set(SP::kSliderExtend, 0);
  ok.step(100);
  EXPECT_EQ(ok.stat("collisions"), 0);
}

TEST(PlantStamping, SupplyOnDemand) {
  Rig r;
  r.step(500);  // StationEmpty FALSE: nothing arrives
  EXPECT_FALSE(r.s(SP::kFilled));
  r.set(SP::kStationEmpty, 1);
  r.step(50);
  r.set(SP::kStationEmpty, 0);  // dropped before supply.delay: the wait starts over
  r.step();
  r.set(SP::kStationEmpty, 1);
  EXPECT_EQ(r.until([&] { return r.s(SP::kFilled); }), 100);  // exactly supply.delay
  EXPECT_EQ(r.stat("workpieces_supplied"), 1);
  r.step(500);  // occupied: no second WP
  EXPECT_EQ(r.stat("workpieces_supplied"), 1);

  // Slider away from PosCrane: no supply.
  Rig away;
  away.set(SP::kSliderExtend, 1);
  away.set(SP::kStationEmpty, 1);
  away.step(500);
  EXPECT_FALSE(away.s(SP::kFilled));
}

TEST(PlantStamping, SupplySchedule) {
  StampingParams p;
  p.supply_mode = SupplyMode::Schedule;
  p.supply_schedule = {3.0, 0.5, 0.6};  // unsorted on purpose
  Rig r(p);
  r.set(SP::kStationEmpty, 1);
  EXPECT_EQ(r.until([&] { return r.s(SP::kFilled); }), 50);  // at 0.5 s
  // The 0.6 s WP waits until the first is handed over.
  r.set(SP::kWorkpieceReady, 1);
  r.until([&] { return !r.s(SP::kFilled); });
  EXPECT_NEAR(r.plant.time(), 1.0, 1e-9);
  r.set(SP::kWorkpieceReady, 0);
  r.step();
  EXPECT_TRUE(r.s(SP::kFilled));
  r.set(SP::kWorkpieceReady, 1);
  r.until([&] { return !r.s(SP::kFilled); });
  r.set(SP::kWorkpieceReady, 0);
  ASSERT_GT(r.until([&] { return r.s(SP::kFilled); }), 0);
  EXPECT_NEAR(r.plant.time(), 3.0, 1e-9);
  r.step(1000);
  EXPECT_EQ(r.stat("workpieces_supplied"), 3);
}

TEST(PlantStamping, HandOverRequiresReadyPosCraneAndNextReady) {
  {  // NextReady never: kept
    StampingParams p;
    p.next_ready = false;
    Rig r(p);
    supply(r);
    EXPECT_FALSE(r.s(SP::kNextReady));
    r.set(SP::kWorkpieceReady, 1);
    r.step(500);
    EXPECT_TRUE(r.s(SP::kFilled));
  }
  {  // not at PosCrane: kept
    Rig r;
    supply(r);
    r.set(SP::kSliderExtend, 1);
    r.set(SP::kWorkpieceReady, 1);
    r.step(500);
    EXPECT_TRUE(r.s(SP::kFilled));
  }
  {  // WorkpieceReady FALSE: kept
    Rig r;
    supply(r);
    r.step(500);
    EXPECT_TRUE(r.s(SP::kFilled));
  }
  {  // all three: taken after handover.delay
    Rig r;
    supply(r);
    r.set(SP::kWorkpieceReady, 1);
    EXPECT_EQ(r.until([&] { return !r.s(SP::kFilled); }), 50);
    EXPECT_EQ(r.stat("workpieces_defective"), 1);  // never stamped
  }
  {  // next module busy until 3 s: taken 0.5 s after it becomes ready
    StampingParams p;
    p.next_busy = {{0.0, 3.0}};
    Rig r(p);
    supply(r);
    r.set(SP::kWorkpieceReady, 1);
    r.until([&] { return !r.s(SP::kFilled); });
    EXPECT_NEAR(r.plant.time(), 3.5, 0.011);
  }
}

TEST(PlantStamping, OperatorStartPressModeAckAndJog) {
  StampingParams p;
  p.operator_ack_at = {1.0, 1.1};  // overlapping presses merge into one
  p.operator_jogs = {{JogButton::Slider, {2.0, 2.5}}, {JogButton::Stamp, {3.0, 3.25}}};
  Rig r(p);
  EXPECT_TRUE(r.s(SP::kModeAuto));
  std::vector<int> start, ack, jog_slider, jog_stamp;
  for (int i = 1; i <= 400; ++i) {
    r.step();
    if (r.s(SP::kStartButton)) start.push_back(i);
    if (r.s(SP::kAckButton)) ack.push_back(i);
    if (r.s(SP::kManSlider)) jog_slider.push_back(i);
    if (r.s(SP::kManStamp)) jog_stamp.push_back(i);
  }
  // Sensors at the end of step i show t = i * 10 ms; a press spans [at, at + press_time).
  ASSERT_EQ(start.size(), 20u);
  EXPECT_EQ(start.front(), 10);
  EXPECT_EQ(start.back(), 29);
  ASSERT_EQ(ack.size(), 30u);
  EXPECT_EQ(ack.front(), 100);
  ASSERT_EQ(jog_slider.size(), 50u);
  EXPECT_EQ(jog_slider.front(), 200);
  ASSERT_EQ(jog_stamp.size(), 25u);
  EXPECT_EQ(jog_stamp.front(), 300);
  // Jog buttons are only sensors: the plant does not move on its own.
  EXPECT_EQ(r.plant.slider_position(), 0.0);

  StampingParams m;
  m.operator_mode = OperatorMode::Manual;
  m.operator_start = false;
  Rig man(m);
  EXPECT_FALSE(man.s(SP::kModeAuto));
  for (int i = 0; i < 100; ++i) {
    man.step();
    ASSERT_FALSE(man.s(SP::kStartButton));
  }
}

// A fixed pseudo-random actuator script (valves, interface, setpoint).
void scripted(Rig& r, int steps, std::vector<double>* trace) {
  uint32_t lcg = 777;
  for (int i = 0; i < steps; ++i) {
    if (i % 13 == 0) {
      lcg = lcg * 1664525u + 1013904223u;
      r.set(SP::kSliderExtend, (lcg >> 20) & 1);
      r.set(SP::kStampDown, (lcg >> 21) & 1);
      r.set(SP::kWorkpieceReady, (lcg >> 22) & 1);
      r.set(SP::kStationEmpty, (lcg >> 23) & 1);
      r.set(SP::kPressureSetpoint, static_cast<double>((lcg >> 8) % 10001));
    }
    r.step();
    trace->insert(trace->end(), r.sen.begin(), r.sen.begin() + 12);
  }
}

TEST(PlantStamping, DeterministicForASeed) {
  std::vector<double> a, b, c;
  Rig ra({}, 42), rb({}, 42);
  scripted(ra, 10000, &a);
  scripted(rb, 10000, &b);
  EXPECT_EQ(a, b);
  EXPECT_EQ(ra.plant.stats(), rb.plant.stats());
  // reset() replays the same run.
  ra.plant.reset(42);
  scripted(ra, 10000, &c);
  EXPECT_EQ(a, c);

  // A different seed: different travel times.
  Rig x({}, 1), y({}, 2);
  x.set(SP::kSliderExtend, 1);
  y.set(SP::kSliderExtend, 1);
  x.step();
  y.step();
  EXPECT_NE(x.plant.slider_stroke_time(), y.plant.slider_stroke_time());
  std::vector<double> d;
  Rig rd({}, 43);
  scripted(rd, 10000, &d);
  EXPECT_NE(a, d);
}

TEST(PlantStamping, FullCycleStampsOneWorkpiece) {
  Rig r;
  // Supply.
  r.set(SP::kStationEmpty, 1);
  ASSERT_EQ(r.until([&] { return r.s(SP::kFilled); }), 100);
  r.set(SP::kStationEmpty, 0);
  // Extend: at PosStamp within 0.5 s of Filled.
  r.set(SP::kSliderExtend, 1);
  int steps = r.until([&] { return r.s(SP::kPosStamp); });
  ASSERT_GT(steps, 0);
  EXPECT_LE(steps * kDt, 0.5);
  // Stamp(AnalogPressure := 6000): StampLowered within 0.5 s, then 1.5 s at 6000.
  ASSERT_TRUE(r.s(SP::kStampUp));
  ASSERT_EQ(r.sen[SP::kStampPressure], 0);
  r.set(SP::kPressureSetpoint, 6000);
  r.set(SP::kStampDown, 1);
  steps = r.until([&] { return r.s(SP::kStampLowered); });
  ASSERT_GT(steps, 0);
  EXPECT_LE(steps * kDt, 0.5);
  r.step(150);
  EXPECT_EQ(r.sen[SP::kStampPressure], 6000);
  // Raise, retract.
  r.set(SP::kStampDown, 0);
  ASSERT_GT(r.until([&] { return r.s(SP::kStampUp); }), 0);
  r.set(SP::kSliderExtend, 0);
  ASSERT_GT(r.until([&] { return r.s(SP::kPosCrane); }), 0);
  EXPECT_TRUE(r.s(SP::kFilled));
  // Hand over.
  r.set(SP::kWorkpieceReady, 1);
  ASSERT_EQ(r.until([&] { return !r.s(SP::kFilled); }), 50);
  EXPECT_EQ(r.stat("workpieces_supplied"), 1);
  EXPECT_EQ(r.stat("workpieces_stamped"), 1);
  EXPECT_EQ(r.stat("workpieces_defective"), 0);
  EXPECT_EQ(r.stat("collisions"), 0);
  EXPECT_EQ(r.stat("slider_strokes"), 1);
  EXPECT_EQ(r.stat("stamp_strokes"), 1);
}

// ---- YAML parameters ----

class PlantStampingYaml : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (std::filesystem::temp_directory_path() / "plcfi_plant_XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& text) {
    const std::string path = (dir_ / ("p" + std::to_string(n_++) + ".yaml")).string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
  int n_ = 0;
};

TEST_F(PlantStampingYaml, DefaultsWithoutFile) {
  std::string err;
  auto plant = make_builtin_plant("stamping", "", &err);
  ASSERT_TRUE(plant) << err;
  const auto& p = static_cast<StampingPlant&>(*plant).params();
  EXPECT_EQ(p.slider_travel, 0.30);
  EXPECT_EQ(p.stamp_travel, 0.20);
  EXPECT_EQ(p.variation, 0.02);
  EXPECT_EQ(p.pressure_tau_rise, 0.08);
  EXPECT_EQ(p.pressure_tau_fall, 0.05);
  EXPECT_EQ(p.stamp_min_pressure, 5700);
  EXPECT_EQ(p.stamp_min_time, 1.0);
  EXPECT_EQ(p.stamp_max_time, 3.5);
  EXPECT_EQ(p.supply_mode, SupplyMode::OnDemand);
  EXPECT_EQ(p.supply_delay, 1.0);
  EXPECT_EQ(p.handover_delay, 0.5);
  EXPECT_TRUE(p.next_ready);
  EXPECT_TRUE(p.next_busy.empty());
  EXPECT_EQ(p.operator_mode, OperatorMode::Auto);
  EXPECT_TRUE(p.operator_start);
  EXPECT_EQ(p.operator_start_at, 0.1);
  EXPECT_EQ(p.operator_press_time, 0.2);
  EXPECT_TRUE(p.operator_ack_at.empty());
  EXPECT_TRUE(p.operator_jogs.empty());
  EXPECT_EQ(builtin_plant_names(), (std::vector<std::string>{"stamping", "bead_dispenser"}));
}

TEST_F(PlantStampingYaml, DocumentedFileIsTheDefaults) {
  // The shipped stamping.yaml (all keys commented out) loads and changes nothing.
  // From the repository root CMake passes in (__FILE__ is relative under ccache's base_dir).
  const std::string shipped = (std::filesystem::path(PLCFI_SOURCE_DIR) / "plant_model/stamping/stamping.yaml").string();
  StampingParams p;
  std::string err;
  ASSERT_TRUE(load_stamping_params(shipped, &p, &err)) << err;
  EXPECT_EQ(p.slider_travel, 0.30);
  // With every comment marker before a key removed it still loads, to the same values.
  std::ifstream in(shipped);
  std::string line, text;
  while (std::getline(in, line)) {
    if (std::regex_search(line, std::regex("^# ( *)[a-z_]+:"))) line = std::regex_replace(line, std::regex("^# "), "");
    text += line + "\n";
  }
  StampingParams q;
  ASSERT_TRUE(load_stamping_params(write(text), &q, &err)) << err << "\n" << text;
  EXPECT_EQ(q.slider_travel, 0.30);
  EXPECT_EQ(q.stamp_travel, 0.20);
  EXPECT_EQ(q.variation, 0.02);
  EXPECT_EQ(q.pressure_tau_rise, 0.08);
  EXPECT_EQ(q.pressure_tau_fall, 0.05);
  EXPECT_EQ(q.stamp_min_pressure, 5700);
  EXPECT_EQ(q.stamp_min_time, 1.0);
  EXPECT_EQ(q.stamp_max_time, 3.5);
  EXPECT_EQ(q.supply_delay, 1.0);
  EXPECT_EQ(q.handover_delay, 0.5);
  EXPECT_EQ(q.operator_start_at, 0.1);
  EXPECT_EQ(q.operator_press_time, 0.2);
}

TEST_F(PlantStampingYaml, EachKeyOverrides) {
  const std::string text = R"(variation: 0.05
slider:
  travel: 0.4
stamp:
  travel: 0.25
  min_pressure: 5000
  min_time: 1.2
  max_time: 2.5
pressure:
  tau_rise: 0.1
  tau_fall: 0.04
supply:
  mode: schedule
  delay: 2
  schedule: [1, 5.5]
handover:
  delay: 0.7
next:
  ready: false
  busy: [{from: 1, to: 2}]
operator:
  mode: manual
  start_at: 0.3
  press_time: 0.4
  ack_at: [7, 8]
  jog:
    - {button: stamp, from: 1, to: 2}
)";
  std::string err;
  auto plant = make_builtin_plant("stamping", write(text), &err);
  ASSERT_TRUE(plant) << err;
  const auto& p = static_cast<StampingPlant&>(*plant).params();
  EXPECT_EQ(p.variation, 0.05);
  EXPECT_EQ(p.slider_travel, 0.4);
  EXPECT_EQ(p.stamp_travel, 0.25);
  EXPECT_EQ(p.stamp_min_pressure, 5000);
  EXPECT_EQ(p.stamp_min_time, 1.2);
  EXPECT_EQ(p.stamp_max_time, 2.5);
  EXPECT_EQ(p.pressure_tau_rise, 0.1);
  EXPECT_EQ(p.pressure_tau_fall, 0.04);
  EXPECT_EQ(p.supply_mode, SupplyMode::Schedule);
  EXPECT_EQ(p.supply_delay, 2.0);
  EXPECT_EQ(p.supply_schedule, (std::vector<double>{1, 5.5}));
  EXPECT_EQ(p.handover_delay, 0.7);
  EXPECT_FALSE(p.next_ready);
  ASSERT_EQ(p.next_busy.size(), 1u);
  EXPECT_EQ(p.next_busy[0].from, 1.0);
  EXPECT_EQ(p.next_busy[0].to, 2.0);
  EXPECT_EQ(p.operator_mode, OperatorMode::Manual);
  EXPECT_EQ(p.operator_start_at, 0.3);
  EXPECT_EQ(p.operator_press_time, 0.4);
  EXPECT_EQ(p.operator_ack_at, (std::vector<double>{7, 8}));
  ASSERT_EQ(p.operator_jogs.size(), 1u);
  EXPECT_EQ(p.operator_jogs[0].button, JogButton::Stamp);
  EXPECT_EQ(p.operator_jogs[0].span.to, 2.0);

  // start_at with an empty value: never pressed.
  StampingParams q;
  ASSERT_TRUE(load_stamping_params(write("operator:\n  start_at:\n"), &q, &err)) << err;
  EXPECT_FALSE(q.operator_start);
  // An empty file: the defaults.
  StampingParams e;
  ASSERT_TRUE(load_stamping_params(write(""), &e, &err)) << err;
  EXPECT_EQ(e.slider_travel, 0.30);
}

TEST_F(PlantStampingYaml, ErrorsNameFileLineColumn) {
  struct Case {
    std::string text;
    std::string expected;  // after "FILE:"
  };
  const std::vector<Case> cases = {
      {"slider:\n  travle: 0.3\n", "2:3: unknown key 'travle' in slider (expected one of: travel)"},
      {"stamp:\n  min_time: abc\n", "2:13: stamp.min_time: expected a number, got 'abc'"},
      {"handover:\n  delay: -1\n", "2:10: handover.delay: a time must not be negative, got -1"},
      {"slider:\n  travel: 0\n", "2:11: slider.travel: must be greater than 0, got 0"},
      {"supply:\n  mode: sometimes\n", "2:9: supply.mode: expected on_demand or schedule, got 'sometimes'"},
      {"supply:\n  schedule: [1]\n", "2:13: supply.schedule is only used with supply.mode: schedule"},
      {"supply:\n  mode: schedule\n  schedule: [1, -2]\n", "3:17: supply.schedule entry: a time must not be negative, got -2"},
      {"stamp:\n  min_time: 2\n  max_time: 1\n", "3:13: stamp.max_time must not be less than stamp.min_time"},
      {"stamp:\n  min_pressure: 12000\n", "2:17: stamp.min_pressure: expected 0..10000, got 12000"},
      {"variation: 0.7\n", "1:12: variation: expected a fraction in [0, 0.5), got 0.7"},
      {"variation: 0.1\nvariation: 0.2\n", "2:1: duplicate key 'variation' (first at 1:1)"},
      {"- 1\n- 2\n", "1:1: the plant parameters: expected a map, got a list"},
      {"stamp: 5\n", "1:8: stamp: expected a map, got '5'"},
      {"next:\n  ready: maybe\n", "2:10: next.ready: expected true or false, got 'maybe'"},
      {"next:\n  busy: [{from: 3, to: 2}]\n", "2:24: next.busy: 'to' must be later than 'from'"},
      {"operator:\n  jog: [{from: 1, to: 2}]\n", "2:9: missing key 'button' in operator.jog"},
      {"operator:\n  jog: [{button: arm, from: 1, to: 2}]\n", "2:18: operator.jog.button: expected slider or stamp, got 'arm'"},
      {"operator:\n  press_time: [1]\n", "2:15: operator.press_time: expected a number, got a list"},
  };
  for (const auto& c : cases) {
    const std::string path = write(c.text);
    std::string err;
    EXPECT_EQ(make_builtin_plant("stamping", path, &err), nullptr) << c.text;
    EXPECT_EQ(err, path + ":" + c.expected) << c.text;
  }
}

TEST_F(PlantStampingYaml, SyntaxErrorMissingFileUnknownPlant) {
  const std::string path = write("stamp:\n  travel: [0.2\n");
  std::string err;
  EXPECT_EQ(make_builtin_plant("stamping", path, &err), nullptr);
  EXPECT_TRUE(std::regex_match(err, std::regex(std::regex_replace(path, std::regex("[.]"), "[.]") + ":[0-9]+:[0-9]+: .+"))) << err;

  const std::string missing = (dir_ / "nope.yaml").string();
  EXPECT_EQ(make_builtin_plant("stamping", missing, &err), nullptr);
  EXPECT_EQ(err, missing + ": cannot open (No such file or directory)");
  EXPECT_EQ(make_builtin_plant("stamping", dir_.string(), &err), nullptr);
  EXPECT_EQ(err, dir_.string() + ": is a directory");

  EXPECT_EQ(make_builtin_plant("press", "", &err), nullptr);
  EXPECT_EQ(err, "unknown plant 'press' (known: stamping, bead_dispenser)");
}

}  // namespace
}  // namespace plcfi::plant
