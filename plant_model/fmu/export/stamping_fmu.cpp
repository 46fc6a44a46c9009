// The built-in stamping plant as an FMI 2.0 co-simulation FMU binary (the library that
// `plcfi plant export-fmu` packs). Variables follow the plant's signal list: signal i has
// value reference i, an actuator is an input, a sensor an output, a BOOL signal Boolean,
// an analog one Integer in the image's units. Integer parameter "seed" (value reference
// 1000) seeds the plant's random variation, as --seed does for the built-in plant; local
// Integer variables from value reference 2000 count workpieces, strokes and collisions.
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "plant_model/fmu/export/stamping_fmu.hpp"
#include "plant_model/fmu/fmi2.h"
#include "plant_model/stamping/stamping_plant.hpp"

namespace {

using plcfi::plant::Direction;
using plcfi::plant::SignalKind;
using plcfi::plant::StampingPlant;

constexpr const char* kGuid = plcfi::plant::fmu::kStampingFmuGuid;
constexpr fmi2ValueReference kSeedRef = plcfi::plant::fmu::kStampingFmuSeedRef;
constexpr fmi2ValueReference kStatsRef = plcfi::plant::fmu::kStampingFmuStatsRef;

enum class State { Instantiated, Initialization, Stepping, Terminated, Error };

struct Instance {
  std::string name;
  fmi2CallbackFunctions cb{};
  StampingPlant plant;
  std::vector<double> act, sen;
  fmi2Integer seed = 1;
  double time = 0.0;
  State state = State::Instantiated;
};

void log(Instance* in, fmi2Status status, const char* fmt, ...) {
  if (!in || !in->cb.logger) return;
  char text[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  in->cb.logger(in->cb.componentEnvironment, in->name.c_str(), status, status >= fmi2Error ? "logStatusError" : "logAll",
                "%s", text);
}

Instance* as(fmi2Component c) { return static_cast<Instance*>(c); }

// The signal of a value reference with the wanted FMI type, or -1.
int signal_of(const Instance* in, fmi2ValueReference vr, SignalKind kind) {
  const auto& sigs = in->plant.signals();
  if (vr >= sigs.size() || sigs[vr].kind != kind) return -1;
  return static_cast<int>(vr);
}

fmi2Status fail(Instance* in, const char* fmt, fmi2ValueReference vr) {
  log(in, fmi2Error, fmt, vr);
  return fmi2Error;
}

// A function of a capability the description does not claim.
fmi2Status unsupported(fmi2Component c, const char* function, const char* why) {
  log(as(c), fmi2Error, "%s: not supported (%s)", function, why);
  return fmi2Error;
}

void restart(Instance* in) {
  in->plant.reset(static_cast<uint64_t>(in->seed));
  std::fill(in->act.begin(), in->act.end(), 0.0);
  std::fill(in->sen.begin(), in->sen.end(), 0.0);
  in->plant.sense(in->sen.data());
  in->time = 0.0;
}

}  // namespace

extern "C" {

FMI2_EXPORT const char* fmi2GetVersion(void) { return "2.0"; }
FMI2_EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }

FMI2_EXPORT fmi2Component fmi2Instantiate(fmi2String instance_name, fmi2Type type, fmi2String guid, fmi2String,
                                          const fmi2CallbackFunctions* functions, fmi2Boolean, fmi2Boolean) {
  Instance probe_for_log;
  if (functions) probe_for_log.cb = *functions;
  probe_for_log.name = instance_name ? instance_name : "";
  if (type != fmi2CoSimulation) {
    log(&probe_for_log, fmi2Error, "this FMU supports co-simulation only");
    return nullptr;
  }
  if (!guid || std::strcmp(guid, kGuid) != 0) {
    log(&probe_for_log, fmi2Error, "wrong GUID %s (expected %s)", guid ? guid : "(null)", kGuid);
    return nullptr;
  }
  auto* in = new (std::nothrow) Instance();
  if (!in) return nullptr;
  in->cb = probe_for_log.cb;
  in->name = probe_for_log.name;
  in->act.assign(in->plant.signals().size(), 0.0);
  in->sen.assign(in->plant.signals().size(), 0.0);
  restart(in);
  return in;
}

FMI2_EXPORT void fmi2FreeInstance(fmi2Component c) { delete as(c); }

FMI2_EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component, fmi2Boolean, size_t, const fmi2String[]) { return fmi2OK; }

FMI2_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean, fmi2Real, fmi2Real start, fmi2Boolean,
                                           fmi2Real) {
  Instance* in = as(c);
  if (in->state != State::Instantiated) return fmi2Error;
  if (start != 0.0) {
    log(in, fmi2Error, "the stamping plant starts at time 0, not %g", start);
    return fmi2Error;
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  Instance* in = as(c);
  if (in->state != State::Instantiated) return fmi2Error;
  in->state = State::Initialization;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  Instance* in = as(c);
  if (in->state != State::Initialization) return fmi2Error;
  restart(in);  // the seed is known now
  in->state = State::Stepping;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
  as(c)->state = State::Terminated;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2Reset(fmi2Component c) {
  Instance* in = as(c);
  in->state = State::Instantiated;
  restart(in);
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real[]) {
  return n == 0 ? fmi2OK : fail(as(c), "no Real variable %u", vr[0]);
}
FMI2_EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real[]) {
  return n == 0 ? fmi2OK : fail(as(c), "no Real variable %u", vr[0]);
}

FMI2_EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
  Instance* in = as(c);
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] == kSeedRef) {
      value[k] = in->seed;
      continue;
    }
    if (vr[k] >= kStatsRef) {
      const auto stats = in->plant.stats();
      if (vr[k] - kStatsRef >= stats.size()) return fail(in, "no Integer variable %u", vr[k]);
      value[k] = static_cast<fmi2Integer>(stats[vr[k] - kStatsRef].second);
      continue;
    }
    const int i = signal_of(in, vr[k], SignalKind::Analog);
    if (i < 0) return fail(in, "no Integer variable %u", vr[k]);
    const double v = in->plant.signals()[static_cast<size_t>(i)].dir == Direction::FromPlant ? in->sen[static_cast<size_t>(i)]
                                                                                          : in->act[static_cast<size_t>(i)];
    value[k] = static_cast<fmi2Integer>(std::lround(v));
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
  Instance* in = as(c);
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] == kSeedRef) {
      if (in->state != State::Instantiated && in->state != State::Initialization)
        return fail(in, "seed (value reference %u) is a fixed parameter: set it before initialization", vr[k]);
      in->seed = value[k];
      continue;
    }
    const int i = signal_of(in, vr[k], SignalKind::Analog);
    if (i < 0 || in->plant.signals()[static_cast<size_t>(i)].dir != Direction::ToPlant)
      return fail(in, "no Integer input %u", vr[k]);
    in->act[static_cast<size_t>(i)] = value[k];
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
  Instance* in = as(c);
  for (size_t k = 0; k < n; ++k) {
    const int i = signal_of(in, vr[k], SignalKind::Bool);
    if (i < 0) return fail(in, "no Boolean variable %u", vr[k]);
    const double v = in->plant.signals()[static_cast<size_t>(i)].dir == Direction::FromPlant ? in->sen[static_cast<size_t>(i)]
                                                                                          : in->act[static_cast<size_t>(i)];
    value[k] = v != 0.0 ? fmi2True : fmi2False;
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
  Instance* in = as(c);
  for (size_t k = 0; k < n; ++k) {
    const int i = signal_of(in, vr[k], SignalKind::Bool);
    if (i < 0 || in->plant.signals()[static_cast<size_t>(i)].dir != Direction::ToPlant)
      return fail(in, "no Boolean input %u", vr[k]);
    in->act[static_cast<size_t>(i)] = value[k] != fmi2False ? 1.0 : 0.0;
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String[]) {
  return n == 0 ? fmi2OK : fail(as(c), "no String variable %u", vr[0]);
}
FMI2_EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String[]) {
  return n == 0 ? fmi2OK : fail(as(c), "no String variable %u", vr[0]);
}

FMI2_EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean) {
  Instance* in = as(c);
  if (in->state != State::Stepping) {
    log(in, fmi2Error, "fmi2DoStep before initialization");
    return fmi2Error;
  }
  if (!(h > 0.0) || std::fabs(t - in->time) > 1e-9 * std::max(1.0, std::fabs(t))) {
    log(in, fmi2Error, "fmi2DoStep(t = %g, h = %g): the plant is at t = %g", t, h, in->time);
    return fmi2Error;
  }
  in->plant.step(h, in->act.data(), in->sen.data());
  in->time = t + h;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2CancelStep(fmi2Component) { return fmi2Error; }

FMI2_EXPORT fmi2Status fmi2GetStatus(fmi2Component, fmi2StatusKind, fmi2Status*) { return fmi2Discard; }
FMI2_EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, fmi2StatusKind kind, fmi2Real* value) {
  if (kind != fmi2LastSuccessfulTime) return fmi2Discard;
  *value = as(c)->time;
  return fmi2OK;
}
FMI2_EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component, fmi2StatusKind, fmi2Integer*) { return fmi2Discard; }
FMI2_EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component, fmi2StatusKind kind, fmi2Boolean* value) {
  if (kind != fmi2Terminated) return fmi2Discard;
  *value = fmi2False;
  return fmi2OK;
}
FMI2_EXPORT fmi2Status fmi2GetStringStatus(fmi2Component, fmi2StatusKind, fmi2String*) { return fmi2Discard; }

// ---- FMU state: a copy of the instance (the plant's state is a few hundred bytes and a
// delivery schedule), so a master can go back to an earlier communication point.
// Serialization and derivatives are not offered; the description says so and the
// functions refuse with a log message, as the standard asks of every FMU.

FMI2_EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state) {
  Instance* in = as(c);
  if (!in || !state) return fmi2Error;
  if (*state) {
    *static_cast<Instance*>(*state) = *in;  // the importer hands an earlier state back to be reused
    return fmi2OK;
  }
  auto* copy = new (std::nothrow) Instance(*in);
  if (!copy) {
    log(in, fmi2Error, "fmi2GetFMUstate: out of memory");
    return fmi2Error;
  }
  *state = copy;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
  Instance* in = as(c);
  if (!in) return fmi2Error;
  if (!state) {
    log(in, fmi2Error, "fmi2SetFMUstate: no state (NULL)");
    return fmi2Error;
  }
  const auto* from = static_cast<const Instance*>(state);
  // The state of the instance, not its identity: name and callbacks stay.
  in->plant = from->plant;
  in->act = from->act;
  in->sen = from->sen;
  in->seed = from->seed;
  in->time = from->time;
  in->state = from->state;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state) {
  if (!c || !state) return fmi2Error;
  delete static_cast<Instance*>(*state);
  *state = nullptr;
  return fmi2OK;
}

#include "plant_model/fmu/export/fmi2_refusals.inc"

}  // extern "C"
