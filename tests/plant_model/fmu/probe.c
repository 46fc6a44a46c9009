/* probe.c: the `probe` test FMU, outputs that are plain functions of time plus switchable
   failures (error, crash, early end, missing stop time), for the FMU loader's error
   handling tests. Also built without fmi2DoStep as probe_missing_symbol.

   Value references (probe.xml), distinct per type:
     Boolean  1 Enable        input
              2 Toggle        output: floor(t / TogglePeriod) is odd
              3 EnableEcho    output: Enable as it was during the last step (before the
                              first step: its value at initialization), to see that an
                              input reaches the FMU
             10 NeedStopTime  fixed parameter
     Integer  1 Steps         output: fmi2DoStep calls that advanced the time
     Real     1 Ramp          output: t
             10 TogglePeriod (s)   11 FailAt (s)   12 CrashAt (s)   13 EndAt (s)
             14 InternalStep (s)   15 HangAt (s)   16 ExitAt (s)   17 AbortAt (s)
                                                                   (fixed parameters)

   Failures (a negative time means never; "a step passes T" means it would end after T):
   - FailAt: a step that passes FailAt returns fmi2Error, logs "step failed at t = ..."
     with the step's start, and the time stays there;
   - CrashAt: a step that passes CrashAt writes through a NULL pointer (SIGSEGV);
   - HangAt: a step that passes HangAt never returns (an endless loop);
   - ExitAt: a step that passes ExitAt ends the process with exit(0), as an FMU written
     for a stand-alone tool may;
   - AbortAt: a step that passes AbortAt calls abort();
   - EndAt: a step that passes EndAt advances to EndAt only and returns fmi2Discard; then
     fmi2GetBooleanStatus(fmi2Terminated) is fmi2True and
     fmi2GetRealStatus(fmi2LastSuccessfulTime) is EndAt;
   - NeedStopTime: fmi2SetupExperiment without a stop time (or fmi2EnterInitializationMode
     when the parameter was set after it) fails with "probe needs a stop time", and a
     step that passes the stop time returns fmi2Error.
   When one step passes several of these times, the earliest wins.
   InternalStep > 0 makes Ramp and Toggle sample-and-hold at multiples of InternalStep,
   like an FMU with a coarse internal solver. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "fmu_support.h"

typedef struct {
  /* input */
  int enable;
  /* parameters */
  double toggle_period;
  double fail_at;
  double crash_at;
  double end_at;
  double hang_at;
  double exit_at;
  double abort_at;
  double internal_step;
  int need_stop_time;
  /* outputs */
  double ramp;
  int toggle;
  int enable_echo;
  int steps;
} Probe;

#define VAR(name, type, vr, causality, field, range) {name, type, vr, causality, offsetof(Probe, field), range}
static const FmuVariable kVariables[] = {
    VAR("Enable", FMU_BOOLEAN, 1, FMU_INPUT, enable, FMU_ANY),
    VAR("Ramp", FMU_REAL, 1, FMU_OUTPUT, ramp, FMU_ANY),
    VAR("Toggle", FMU_BOOLEAN, 2, FMU_OUTPUT, toggle, FMU_ANY),
    VAR("Steps", FMU_INTEGER, 1, FMU_OUTPUT, steps, FMU_ANY),
    VAR("EnableEcho", FMU_BOOLEAN, 3, FMU_OUTPUT, enable_echo, FMU_ANY),
    VAR("TogglePeriod", FMU_REAL, 10, FMU_PARAMETER, toggle_period, FMU_POSITIVE),
    VAR("FailAt", FMU_REAL, 11, FMU_PARAMETER, fail_at, FMU_ANY),
    VAR("CrashAt", FMU_REAL, 12, FMU_PARAMETER, crash_at, FMU_ANY),
    VAR("EndAt", FMU_REAL, 13, FMU_PARAMETER, end_at, FMU_ANY),
    VAR("NeedStopTime", FMU_BOOLEAN, 10, FMU_PARAMETER, need_stop_time, FMU_ANY),
    VAR("InternalStep", FMU_REAL, 14, FMU_PARAMETER, internal_step, FMU_NON_NEGATIVE),
    VAR("HangAt", FMU_REAL, 15, FMU_PARAMETER, hang_at, FMU_ANY),
    VAR("ExitAt", FMU_REAL, 16, FMU_PARAMETER, exit_at, FMU_ANY),
    VAR("AbortAt", FMU_REAL, 17, FMU_PARAMETER, abort_at, FMU_ANY),
};

static void defaults(Fmu* f) {
  Probe* m = f->data;
  m->enable = 0;
  m->toggle_period = 1.0;
  m->fail_at = -1.0;
  m->crash_at = -1.0;
  m->end_at = -1.0;
  m->hang_at = -1.0;
  m->exit_at = -1.0;
  m->abort_at = -1.0;
  m->internal_step = 0.0;
  m->need_stop_time = 0;
}

/* floor(x) for a quotient of times that should be an integer at the boundaries: 3.0 / 0.1 is
   29.999999999999996 in doubles, and the sample at 3.0 must count as the 30th. */
static double time_floor(double x) { return floor(x + 1e-9 * fmax(1.0, fabs(x))); }

/* Outputs at time t. */
static void sample(Probe* m, double t) {
  double ts = m->internal_step > 0.0 ? time_floor(t / m->internal_step) * m->internal_step : t;
  m->ramp = ts;
  m->toggle = fmod(time_floor(ts / m->toggle_period), 2.0) != 0.0; /* odd, also for t < 0 */
}

static void initialize(Fmu* f) {
  Probe* m = f->data;
  m->steps = 0;
  m->enable_echo = m->enable;
  sample(m, f->time);
}

static fmi2Status check(Fmu* f) {
  Probe* m = f->data;
  if (m->need_stop_time && !f->stop_time_defined) {
    fmu_log(f, fmi2Error, "probe needs a stop time");
    return fmi2Error;
  }
  return fmi2OK;
}

/* The crash of CrashAt. Both volatile: the pointer, so that the compiler cannot prove it
   NULL (and replace the store by a trap instruction), and the pointee, so that the store
   is an access it must do (GCC drops a plain store through an unknown pointer here). */
static void crash(void) {
  volatile int* volatile null_pointer = NULL;
  *null_pointer = 1;
}

/* The hang of HangAt: an endless loop the compiler must keep (a volatile read each turn). */
static void hang(void) {
  volatile int spin = 1;
  while (spin) {
  }
}

typedef enum { NONE, CRASH, HANG, EXIT, ABORT, FAIL, STOP, END } Event;

static fmi2Status do_step(Fmu* f, double h) {
  Probe* m = f->data;
  double t0 = f->time;
  double t1 = t0 + h;
  double eps = fmu_time_eps(t1);

  /* the earliest failure time that this step passes */
  Event event = NONE;
  double at = INFINITY;
  const struct {
    Event event;
    int active;
    double time;
  } candidates[] = {
      {CRASH, m->crash_at >= 0.0, m->crash_at},
      {HANG, m->hang_at >= 0.0, m->hang_at},
      {EXIT, m->exit_at >= 0.0, m->exit_at},
      {ABORT, m->abort_at >= 0.0, m->abort_at},
      {FAIL, m->fail_at >= 0.0, m->fail_at},
      {STOP, m->need_stop_time && f->stop_time_defined, f->stop_time},
      {END, m->end_at >= 0.0, m->end_at},
  };
  for (size_t i = 0; i < sizeof candidates / sizeof candidates[0]; ++i)
    if (candidates[i].active && t1 > candidates[i].time + eps && candidates[i].time < at) {
      event = candidates[i].event;
      at = candidates[i].time;
    }

  switch (event) {
    case CRASH:
      fmu_log(f, fmi2OK, "crashing at t = %g (CrashAt %g)", t0, m->crash_at); /* seen with debug logging */
      crash();
      return fmi2Fatal; /* not reached */
    case HANG:
      hang();
      return fmi2Fatal; /* not reached */
    case EXIT:
      exit(0);
    case ABORT:
      abort();
    case FAIL:
      fmu_log(f, fmi2Error, "step failed at t = %g (FailAt %g)", t0, m->fail_at);
      return fmi2Error;
    case STOP:
      fmu_log(f, fmi2Error, "step from t = %g to %g goes past the stop time %g", t0, t1, f->stop_time);
      return fmi2Error;
    case END:
      f->time = fmax(t0, m->end_at); /* a start time after EndAt ends at once */
      m->enable_echo = m->enable;
      m->steps += 1;
      sample(m, f->time);
      f->terminated = 1;
      fmu_log(f, fmi2Discard, "simulation ended at t = %g (EndAt)", f->time);
      return fmi2Discard;
    case NONE:
      break;
  }
  f->time = t1;
  m->enable_echo = m->enable;
  m->steps += 1;
  sample(m, t1);
  return fmi2OK;
}

const FmuModel fmu_model = {
    .data_size = sizeof(Probe),
    .variables = kVariables,
    .n_variables = sizeof kVariables / sizeof kVariables[0],
    .defaults = defaults,
    .initialize = initialize,
    .check = check,
    .do_step = do_step,
};
