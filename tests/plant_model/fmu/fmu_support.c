/* fmu_support.c: the exported FMI 2.0 co-simulation functions of a test FMU, generic over
   the FmuModel its model file defines (see fmu_support.h).

   The test FMUs are deliberately strict, so that the loader's tests catch a wrong call
   sequence instead of a quietly forgiving plant:
   - a call in the wrong state, an unknown value reference, setting an output or setting a
     fixed parameter after initialization is rejected with fmi2Error and a logged reason;
     such a rejected call leaves the instance as it was;
   - a failed step or a failed initialization check puts the instance in the error state,
     where only fmi2Get*, fmi2Get*Status, fmi2Reset and fmi2FreeInstance are allowed;
   - fmi2DoStep must start at the FMU's own time (the end of the previous step).
   Reading values (fmi2Get*) is allowed in every state, also before initialization.

   Built with FMU_OMIT_DOSTEP, fmi2DoStep is left out: the probe_missing_symbol FMU. */
#include "fmu_support.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Declared through the header's function types: a definition below that does not match
   the standard signature is a compile error. */
FMI2_EXPORT fmi2GetVersionTYPE fmi2GetVersion;
FMI2_EXPORT fmi2GetTypesPlatformTYPE fmi2GetTypesPlatform;
FMI2_EXPORT fmi2InstantiateTYPE fmi2Instantiate;
FMI2_EXPORT fmi2FreeInstanceTYPE fmi2FreeInstance;
FMI2_EXPORT fmi2SetDebugLoggingTYPE fmi2SetDebugLogging;
FMI2_EXPORT fmi2SetupExperimentTYPE fmi2SetupExperiment;
FMI2_EXPORT fmi2EnterInitializationModeTYPE fmi2EnterInitializationMode;
FMI2_EXPORT fmi2ExitInitializationModeTYPE fmi2ExitInitializationMode;
FMI2_EXPORT fmi2TerminateTYPE fmi2Terminate;
FMI2_EXPORT fmi2ResetTYPE fmi2Reset;
FMI2_EXPORT fmi2GetRealTYPE fmi2GetReal;
FMI2_EXPORT fmi2GetIntegerTYPE fmi2GetInteger;
FMI2_EXPORT fmi2GetBooleanTYPE fmi2GetBoolean;
FMI2_EXPORT fmi2SetRealTYPE fmi2SetReal;
FMI2_EXPORT fmi2SetIntegerTYPE fmi2SetInteger;
FMI2_EXPORT fmi2SetBooleanTYPE fmi2SetBoolean;
FMI2_EXPORT fmi2DoStepTYPE fmi2DoStep;
FMI2_EXPORT fmi2CancelStepTYPE fmi2CancelStep;
FMI2_EXPORT fmi2GetStatusTYPE fmi2GetStatus;
FMI2_EXPORT fmi2GetRealStatusTYPE fmi2GetRealStatus;
FMI2_EXPORT fmi2GetIntegerStatusTYPE fmi2GetIntegerStatus;
FMI2_EXPORT fmi2GetBooleanStatusTYPE fmi2GetBooleanStatus;

#ifndef FMU_GUID
#error "FMU_GUID must be defined: CMake takes it from the FMU's modelDescription.xml"
#endif

/* The log categories modelDescription.xml declares; one per status. */
static const char* const kCategories[] = {"logEvents", "logStatusWarning", "logStatusDiscard", "logStatusError"};
#define N_CATEGORIES (sizeof kCategories / sizeof kCategories[0])

static const char* category_of(fmi2Status status) {
  switch (status) {
    case fmi2OK:
    case fmi2Pending:
      return kCategories[0];
    case fmi2Warning:
      return kCategories[1];
    case fmi2Discard:
      return kCategories[2];
    default:
      return kCategories[3];
  }
}

void fmu_log(const Fmu* f, fmi2Status status, const char* format, ...) {
  if (f->functions.logger == NULL || (status == fmi2OK && !f->logging_on)) return;
  char text[512];
  va_list args;
  va_start(args, format);
  vsnprintf(text, sizeof text, format, args);
  va_end(args);
  /* The importer treats the message as a format string in which '#' starts a value
     reference: escape both, since the text is complete already. */
  char message[2 * sizeof text];
  size_t n = 0;
  for (const char* p = text; *p != '\0'; ++p) {
    if (*p == '%' || *p == '#') message[n++] = *p;
    message[n++] = *p;
  }
  message[n] = '\0';
  f->functions.logger(f->functions.componentEnvironment, f->name != NULL ? f->name : "?", status,
                      category_of(status), message);
}

size_t fmu_substeps(double h) {
  double n = ceil(h / FMU_MAX_SUBSTEP - 1e-9); /* 10 ms is 10 substeps, not 11 by rounding */
  return n < 1.0 ? 1 : (size_t)n;
}

double fmu_time_eps(double t) { return 1e-9 * fmax(1.0, fabs(t)); }

static const char* state_name(FmuState state) {
  switch (state) {
    case FMU_INSTANTIATED:
      return "instantiated";
    case FMU_INIT_MODE:
      return "initialization mode";
    case FMU_STEP_MODE:
      return "step mode";
    case FMU_TERMINATED:
      return "terminated";
    default:
      return "error";
  }
}

/* A call allowed only in `states` (a bit set): fmi2Error and a message otherwise. */
#define IN(state) (1u << (state))
static int allowed(Fmu* f, unsigned states, const char* function) {
  if (states & IN(f->state)) return 1;
  fmu_log(f, fmi2Error, "%s: not allowed in state '%s'", function, state_name(f->state));
  return 0;
}

static void* allocate(const fmi2CallbackFunctions* functions, size_t size) {
  /* The importer's allocator only as a pair: what it allocates, its freeMemory frees. */
  void* p = functions->allocateMemory != NULL && functions->freeMemory != NULL ? functions->allocateMemory(1, size)
                                                                             : calloc(1, size);
  if (p != NULL) memset(p, 0, size);
  return p;
}

static void release(const fmi2CallbackFunctions* functions, void* p) {
  if (p == NULL) return;
  if (functions->allocateMemory != NULL && functions->freeMemory != NULL)
    functions->freeMemory(p);
  else
    free(p);
}

/* Back to the start time: the model's initial state from the current parameters. */
static void restart(Fmu* f) {
  f->time = f->start_time;
  f->terminated = 0;
  f->model->initialize(f);
}

static const FmuVariable* find(const Fmu* f, FmuType type, fmi2ValueReference vr) {
  for (size_t i = 0; i < f->model->n_variables; ++i) {
    const FmuVariable* v = &f->model->variables[i];
    if (v->type == type && v->vr == vr) return v;
  }
  return NULL;
}

static const char* type_name(FmuType type) {
  return type == FMU_REAL ? "Real" : type == FMU_INTEGER ? "Integer" : "Boolean";
}

static double* real_at(Fmu* f, const FmuVariable* v) { return (double*)((char*)f->data + v->offset); }
static int* int_at(Fmu* f, const FmuVariable* v) { return (int*)((char*)f->data + v->offset); }

/* Looks up vr[i] for fmi2Get<type>: NULL (and a message) when there is none. */
static const FmuVariable* lookup(Fmu* f, FmuType type, const fmi2ValueReference vr[], size_t n, const void* value,
                                 size_t i, const char* function) {
  if (vr == NULL || value == NULL) {
    fmu_log(f, fmi2Error, "%s: NULL array for %zu value(s)", function, n);
    return NULL;
  }
  const FmuVariable* v = find(f, type, vr[i]);
  if (v == NULL) fmu_log(f, fmi2Error, "%s: no %s variable has value reference %u", function, type_name(type), vr[i]);
  return v;
}

/* Checks that vr[i] may be set now to a value of this type; range checks are the caller's. */
static const FmuVariable* lookup_settable(Fmu* f, FmuType type, const fmi2ValueReference vr[], size_t n,
                                          const void* value, size_t i, const char* function) {
  const FmuVariable* v = lookup(f, type, vr, n, value, i, function);
  if (v == NULL) return NULL;
  if (v->causality == FMU_OUTPUT) {
    fmu_log(f, fmi2Error, "%s: %s is an output and cannot be set", function, v->name);
    return NULL;
  }
  if (v->causality == FMU_PARAMETER && f->state != FMU_INSTANTIATED && f->state != FMU_INIT_MODE) {
    fmu_log(f, fmi2Error, "%s: %s is a fixed parameter: set it before fmi2ExitInitializationMode", function,
            v->name);
    return NULL;
  }
  return v;
}

/* After a parameter change before the simulation runs, the start state (and so the outputs
   an importer may read in initialization mode) follows the new value. */
static void parameters_changed(Fmu* f, int any_parameter) {
  if (any_parameter && (f->state == FMU_INSTANTIATED || f->state == FMU_INIT_MODE)) restart(f);
}

/* ---- common functions ---- */

FMI2_EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }

FMI2_EXPORT const char* fmi2GetVersion(void) { return "2.0"; }

FMI2_EXPORT fmi2Component fmi2Instantiate(fmi2String instance_name, fmi2Type type, fmi2String guid,
                                          fmi2String resource_location, const fmi2CallbackFunctions* functions,
                                          fmi2Boolean visible, fmi2Boolean logging_on) {
  if (functions == NULL) return NULL; /* nothing to log with */
  /* A stand-in instance for the messages until the real one exists. */
  Fmu early = {0};
  early.functions = *functions;
  early.name = (char*)(instance_name != NULL && instance_name[0] != '\0' ? instance_name : "?");
  if (instance_name == NULL || instance_name[0] == '\0') {
    fmu_log(&early, fmi2Error, "fmi2Instantiate: missing instance name");
    return NULL;
  }
  if (type != fmi2CoSimulation) {
    fmu_log(&early, fmi2Error, "fmi2Instantiate: this FMU supports co-simulation only (fmi2CoSimulation)");
    return NULL;
  }
  if (guid == NULL || strcmp(guid, FMU_GUID) != 0) {
    fmu_log(&early, fmi2Error, "fmi2Instantiate: GUID %s does not match the FMU's %s", guid != NULL ? guid : "(null)",
            FMU_GUID);
    return NULL;
  }
  Fmu* f = allocate(functions, sizeof(Fmu));
  if (f == NULL) {
    fmu_log(&early, fmi2Error, "fmi2Instantiate: out of memory");
    return NULL;
  }
  f->functions = *functions;
  f->model = &fmu_model;
  f->logging_on = logging_on != fmi2False;
  f->name = allocate(functions, strlen(instance_name) + 1);
  f->data = allocate(functions, fmu_model.data_size);
  if (f->name == NULL || f->data == NULL) {
    fmu_log(&early, fmi2Error, "fmi2Instantiate: out of memory");
    release(functions, f->name);
    release(functions, f->data);
    release(functions, f);
    return NULL;
  }
  strcpy(f->name, instance_name);
  f->state = FMU_INSTANTIATED;
  f->model->defaults(f);
  restart(f);
  fmu_log(f, fmi2OK, "instantiated (GUID %s)", guid);
  return f;
}

FMI2_EXPORT void fmi2FreeInstance(fmi2Component c) {
  Fmu* f = c;
  if (f == NULL) return;
  fmi2CallbackFunctions functions = f->functions; /* f itself is freed last */
  release(&functions, f->data);
  release(&functions, f->name);
  release(&functions, f);
}

FMI2_EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean logging_on, size_t n_categories,
                                           const fmi2String categories[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (n_categories > 0 && categories == NULL) {
    fmu_log(f, fmi2Error, "fmi2SetDebugLogging: NULL array for %zu categories", n_categories);
    return fmi2Error;
  }
  for (size_t i = 0; i < n_categories; ++i) {
    size_t k = 0;
    while (k < N_CATEGORIES && (categories[i] == NULL || strcmp(categories[i], kCategories[k]) != 0)) ++k;
    if (k == N_CATEGORIES) {
      fmu_log(f, fmi2Error, "fmi2SetDebugLogging: unknown log category '%s'",
              categories[i] != NULL ? categories[i] : "(null)");
      return fmi2Error;
    }
  }
  /* The categories are checked but not filtered on: debug logging is all or nothing. */
  f->logging_on = logging_on != fmi2False;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                           fmi2Real start_time, fmi2Boolean stop_time_defined, fmi2Real stop_time) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, IN(FMU_INSTANTIATED), "fmi2SetupExperiment")) return fmi2Error;
  if (!isfinite(start_time) || (stop_time_defined && !(stop_time >= start_time))) {
    fmu_log(f, fmi2Error, "fmi2SetupExperiment: bad interval: start time %g, stop time %g", start_time, stop_time);
    return fmi2Error;
  }
  f->start_time = start_time;
  f->stop_time_defined = stop_time_defined != fmi2False;
  f->stop_time = stop_time;
  restart(f);
  if (f->model->check != NULL && f->model->check(f) != fmi2OK) {
    f->state = FMU_ERROR;
    return fmi2Error;
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, IN(FMU_INSTANTIATED), "fmi2EnterInitializationMode")) return fmi2Error;
  /* Again here: a parameter may have changed since fmi2SetupExperiment. */
  if (f->model->check != NULL && f->model->check(f) != fmi2OK) {
    f->state = FMU_ERROR;
    return fmi2Error;
  }
  f->state = FMU_INIT_MODE;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, IN(FMU_INIT_MODE), "fmi2ExitInitializationMode")) return fmi2Error;
  restart(f);
  f->state = FMU_STEP_MODE;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, IN(FMU_STEP_MODE), "fmi2Terminate")) return fmi2Error;
  f->state = FMU_TERMINATED;
  fmu_log(f, fmi2OK, "terminated at t = %g", f->time);
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2Reset(fmi2Component c) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  memset(f->data, 0, f->model->data_size);
  f->model->defaults(f);
  f->start_time = 0.0;
  f->stop_time_defined = 0;
  f->stop_time = 0.0;
  f->state = FMU_INSTANTIATED;
  restart(f);
  return fmi2OK;
}

/* ---- values ---- */

#define ALL_STATES (IN(FMU_INSTANTIATED) | IN(FMU_INIT_MODE) | IN(FMU_STEP_MODE) | IN(FMU_TERMINATED) | IN(FMU_ERROR))
#define SET_STATES (IN(FMU_INSTANTIATED) | IN(FMU_INIT_MODE) | IN(FMU_STEP_MODE))

FMI2_EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  for (size_t i = 0; i < n; ++i) {
    const FmuVariable* v = lookup(f, FMU_REAL, vr, n, value, i, "fmi2GetReal");
    if (v == NULL) return fmi2Error;
    value[i] = *real_at(f, v);
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  for (size_t i = 0; i < n; ++i) {
    const FmuVariable* v = lookup(f, FMU_INTEGER, vr, n, value, i, "fmi2GetInteger");
    if (v == NULL) return fmi2Error;
    value[i] = *int_at(f, v);
  }
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  for (size_t i = 0; i < n; ++i) {
    const FmuVariable* v = lookup(f, FMU_BOOLEAN, vr, n, value, i, "fmi2GetBoolean");
    if (v == NULL) return fmi2Error;
    value[i] = *int_at(f, v) ? fmi2True : fmi2False;
  }
  return fmi2OK;
}

static int in_range(Fmu* f, const FmuVariable* v, double x, const char* function) {
  int ok = isfinite(x) && (v->range == FMU_ANY || (v->range == FMU_POSITIVE && x > 0.0) ||
                           (v->range == FMU_NON_NEGATIVE && x >= 0.0));
  if (!ok)
    fmu_log(f, fmi2Error, "%s: %s = %g is out of range (%s)", function, v->name, x,
            v->range == FMU_POSITIVE       ? "must be > 0"
            : v->range == FMU_NON_NEGATIVE ? "must be >= 0"
                                           : "must be finite");
  return ok;
}

FMI2_EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, SET_STATES, "fmi2SetReal")) return fmi2Error;
  int any_parameter = 0;
  fmi2Status status = fmi2OK;
  for (size_t i = 0; i < n && status == fmi2OK; ++i) {
    const FmuVariable* v = lookup_settable(f, FMU_REAL, vr, n, value, i, "fmi2SetReal");
    if (v == NULL || !in_range(f, v, value[i], "fmi2SetReal")) {
      status = fmi2Error;
    } else {
      *real_at(f, v) = value[i];
      any_parameter |= v->causality == FMU_PARAMETER;
    }
  }
  parameters_changed(f, any_parameter); /* also for the values set before a rejected one */
  return status;
}

FMI2_EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                      const fmi2Integer value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, SET_STATES, "fmi2SetInteger")) return fmi2Error;
  int any_parameter = 0;
  fmi2Status status = fmi2OK;
  for (size_t i = 0; i < n && status == fmi2OK; ++i) {
    const FmuVariable* v = lookup_settable(f, FMU_INTEGER, vr, n, value, i, "fmi2SetInteger");
    if (v == NULL || !in_range(f, v, value[i], "fmi2SetInteger")) {
      status = fmi2Error;
    } else {
      *int_at(f, v) = value[i];
      any_parameter |= v->causality == FMU_PARAMETER;
    }
  }
  parameters_changed(f, any_parameter);
  return status;
}

FMI2_EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                      const fmi2Boolean value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, SET_STATES, "fmi2SetBoolean")) return fmi2Error;
  int any_parameter = 0;
  fmi2Status status = fmi2OK;
  for (size_t i = 0; i < n && status == fmi2OK; ++i) {
    const FmuVariable* v = lookup_settable(f, FMU_BOOLEAN, vr, n, value, i, "fmi2SetBoolean");
    if (v == NULL) {
      status = fmi2Error;
    } else {
      *int_at(f, v) = value[i] != fmi2False; /* any non-zero int is true */
      any_parameter |= v->causality == FMU_PARAMETER;
    }
  }
  parameters_changed(f, any_parameter);
  return status;
}

/* No String variables: any value reference is unknown. */
FMI2_EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (n == 0) return fmi2OK;
  fmu_log(f, fmi2Error, "fmi2GetString: no String variable has value reference %u", vr != NULL ? vr[0] : 0u);
  return fmi2Error;
}

FMI2_EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                     const fmi2String value[]) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (n == 0) return fmi2OK;
  fmu_log(f, fmi2Error, "fmi2SetString: no String variable has value reference %u", vr != NULL ? vr[0] : 0u);
  return fmi2Error;
}

/* ---- co-simulation ---- */

#ifndef FMU_OMIT_DOSTEP
FMI2_EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real current_communication_point,
                                  fmi2Real communication_step_size, fmi2Boolean no_set_state_prior_to_current_point) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  if (!allowed(f, IN(FMU_STEP_MODE), "fmi2DoStep")) return fmi2Error;
  if (f->terminated) {
    fmu_log(f, fmi2Error, "fmi2DoStep: the simulation ended at t = %g", f->time);
    return fmi2Error;
  }
  if (!(communication_step_size > 0.0) || !isfinite(communication_step_size)) {
    fmu_log(f, fmi2Error, "fmi2DoStep: step size %g must be > 0", communication_step_size);
    return fmi2Error;
  }
  if (!(fabs(current_communication_point - f->time) <= fmu_time_eps(f->time))) {
    fmu_log(f, fmi2Error, "fmi2DoStep: communication point %.17g is not the FMU's time %.17g",
            current_communication_point, f->time);
    return fmi2Error;
  }
  /* The importer's clock wins over rounding differences: no drift between the two. */
  f->time = current_communication_point;
  fmi2Status status = f->model->do_step(f, communication_step_size);
  if (status == fmi2Error || status == fmi2Fatal) f->state = FMU_ERROR;
  return status;
}
#endif

FMI2_EXPORT fmi2Status fmi2CancelStep(fmi2Component c) {
  Fmu* f = c;
  if (f == NULL) return fmi2Error;
  fmu_log(f, fmi2Error, "fmi2CancelStep: steps are synchronous, there is none to cancel");
  return fmi2Error;
}

/* Status queries. Steps never return fmi2Pending, so only the last successful time and
   the terminated flag exist; the rest is fmi2Discard ("not available"), as the standard
   says. */
FMI2_EXPORT fmi2Status fmi2GetStatus(fmi2Component c, fmi2StatusKind kind, fmi2Status* value) {
  return c == NULL || value == NULL ? fmi2Error : fmi2Discard;
}

FMI2_EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, fmi2StatusKind kind, fmi2Real* value) {
  Fmu* f = c;
  if (f == NULL || value == NULL) return fmi2Error;
  if (kind != fmi2LastSuccessfulTime) return fmi2Discard;
  *value = f->time;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, fmi2StatusKind kind, fmi2Integer* value) {
  return c == NULL || value == NULL ? fmi2Error : fmi2Discard;
}

FMI2_EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, fmi2StatusKind kind, fmi2Boolean* value) {
  Fmu* f = c;
  if (f == NULL || value == NULL) return fmi2Error;
  if (kind != fmi2Terminated) return fmi2Discard;
  *value = f->terminated ? fmi2True : fmi2False;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, fmi2StatusKind kind, fmi2String* value) {
  return c == NULL || value == NULL ? fmi2Error : fmi2Discard;
}

/* ---- capabilities the model description does not claim: present, as the standard
   requires every function to be, but refusing ---- */

static fmi2Status unsupported(fmi2Component c, const char* function, const char* why) {
  Fmu* f = c;
  if (f != NULL) fmu_log(f, fmi2Error, "%s: not supported (%s)", function, why);
  return fmi2Error;
}

FMI2_EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state) {
  return unsupported(c, "fmi2GetFMUstate", "canGetAndSetFMUstate is false");
}

FMI2_EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
  return unsupported(c, "fmi2SetFMUstate", "canGetAndSetFMUstate is false");
}

FMI2_EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state) {
  return unsupported(c, "fmi2FreeFMUstate", "canGetAndSetFMUstate is false");
}

FMI2_EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t* size) {
  return unsupported(c, "fmi2SerializedFMUstateSize", "canSerializeFMUstate is false");
}

FMI2_EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte serialized[],
                                             size_t size) {
  return unsupported(c, "fmi2SerializeFMUstate", "canSerializeFMUstate is false");
}

FMI2_EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serialized[], size_t size,
                                               fmi2FMUstate* state) {
  return unsupported(c, "fmi2DeSerializeFMUstate", "canSerializeFMUstate is false");
}

FMI2_EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference unknown_refs[],
                                                    size_t n_unknown, const fmi2ValueReference known_refs[],
                                                    size_t n_known, const fmi2Real dv_known[],
                                                    fmi2Real dv_unknown[]) {
  return unsupported(c, "fmi2GetDirectionalDerivative", "providesDirectionalDerivative is false");
}

FMI2_EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                   const fmi2Integer order[], const fmi2Real value[]) {
  return unsupported(c, "fmi2SetRealInputDerivatives", "canInterpolateInputs is false");
}

FMI2_EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                                    const fmi2Integer order[], fmi2Real value[]) {
  return unsupported(c, "fmi2GetRealOutputDerivatives", "maxOutputDerivativeOrder is 0");
}
