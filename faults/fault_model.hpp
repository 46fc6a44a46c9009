// Fault models: component failures as rules of the I/O image overlay. A sensor fault
// rewrites what the program reads from %I (the plant's raw value stays as delivered); an
// actuator fault rewrites what reaches the plant from %Q (the program's variables stay as
// the program wrote them). Written in spec files as e.g. "stuck", "stuck_at(1)",
// "drift(100/s)", "intermittent(1s, 0.5)", "no_effect"; faults/README.md lists them all.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "runtime/image.hpp"

namespace plcfi::faults {

enum class Kind {
  // sensor (input area)
  StuckAt,       // stuck_at(v): reads v
  StuckCurrent,  // stuck: keeps the value it had at the injection (the pre-transition value)
  Frozen,        // frozen: an analog value frozen at the injection (same rule as stuck)
  Offset,        // offset(d): value + d
  Gain,          // gain(k): value * k
  Drift,         // drift(r/s): value + r * time since the injection
  Noise,         // noise(sigma): value + gaussian noise, seeded
  Delay,         // delay(t): transport delay
  Intermittent,  // intermittent(period, duty) | intermittent(random, p, interval): drops to the pre-fault value
  Inverted,      // inverted: BOOL negated
  OpenWire,      // open_wire | open_wire(v): BOOL FALSE, analog v (default 0)
  // actuator (output area)
  NoEffect,      // no_effect: the plant keeps receiving the pre-fault command
  StuckOn,       // stuck_on: BOOL TRUE
  StuckOff,      // stuck_off: FALSE / 0
  Delayed,       // delayed(t): the plant receives commands t late
};

struct FaultSpec {
  Kind kind = Kind::StuckCurrent;
  double value = 0;          // stuck_at / offset / gain / drift per second / sigma / open-wire value / duty or p
  int64_t duration_ns = 0;   // delay, delayed, intermittent period or interval
  bool random = false;       // intermittent(random, ...)
  bool has_value = false;    // open_wire(v) given
  std::string text;          // canonical form, e.g. "drift(100/s)"
};

// Parses a fault model. Names are case-insensitive, spaces are free, durations may be
// written 200ms or T#200ms. On error: false, a message in *err and in *err_col the
// 0-based column of `text` where the problem is (callers add file:line).
bool parse_fault(const std::string& text, FaultSpec* out, std::string* err, uint32_t* err_col);

bool is_actuator_fault(Kind k);
std::string kind_name(Kind k);

// What the driver knows at the moment of the injection.
struct InjectionContext {
  rt::ImageRef ref;        // the faulted location
  int64_t baseline = 0;    // its value before the injection: the raw input (sensor) or the
                           // command last delivered to the plant (actuator)
  int64_t inject_ns = 0;   // injection time on the scan clock
  int64_t tick_ns = 0;     // base tick (sizes the delay buffers; 0: 1 ms assumed)
  uint64_t seed = 0;       // noise and random intermittence
};

// Checks that the fault fits the location (sensor faults on %I, actuator faults on %Q;
// offset, gain, drift and noise need an integer value; inverted and stuck_on a BOOL) and
// creates its overlay rule. On a misfit: null and a message naming fault and address.
// The rule's apply() never allocates.
std::unique_ptr<rt::OverlayRule> make_rule(const FaultSpec& f, const InjectionContext& ctx, std::string* err);

}  // namespace plcfi::faults
