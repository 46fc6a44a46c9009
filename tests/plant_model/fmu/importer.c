/* importer.c: an FMI 2.0 co-simulation importer of its own, for checking the FMUs plcfi
   exports the way another tool would load them: it resolves every one of the 34 functions
   the standard requires (as FMPy does when it loads an FMU), then drives the FMU through
   the standard's calling sequence and calls every function once.

   usage: plcfi_fmu_importer DIR MODEL_IDENTIFIER GUID STEP_S STEPS [options]
     DIR: the unpacked FMU (binaries/linux64/MODEL_IDENTIFIER.so below it)
     --bool-in VR@K    set Boolean input VR to true before step K (0-based), false before
     --bool-out VR     print Boolean output VR after every step (in the order given)
     --string VR=TEXT  set String parameter VR to TEXT before initialization
     --state           get the FMU state halfway, finish, set the state back and run the
                       second half again: the outputs must be the same (canGetAndSetFMUstate)
   Prints "missing: NAME" for each function the binary lacks (exit 1), the outputs as one
   line of 0/1 per step, and "ok" at the end. Any status other than the one the standard
   asks for is a message and exit 1. */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plant_model/fmu/fmi2.h"

#define MAX_VR 64

static int logged = 0; /* messages the FMU logged since the last reset of the counter */

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
  (void)env;
  (void)category;
  va_list ap;
  va_start(ap, message);
  fprintf(stderr, "[%s status %d] ", instance ? instance : "?", (int)status);
  vfprintf(stderr, message, ap);
  fputc('\n', stderr);
  va_end(ap);
  ++logged;
}

static void fail(const char* what) {
  fprintf(stderr, "importer: %s\n", what);
  exit(1);
}

static void expect(fmi2Status s, fmi2Status want, const char* call) {
  if (s != want) {
    fprintf(stderr, "importer: %s returned %d, expected %d\n", call, (int)s, (int)want);
    exit(1);
  }
}

/* Every function of the FMI 2.0 co-simulation API, by name. */
static const char* const kNames[] = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate", "fmi2FreeInstance",
    "fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate",
    "fmi2Reset", "fmi2GetReal", "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal",
    "fmi2SetInteger", "fmi2SetBoolean", "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate",
    "fmi2FreeFMUstate", "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative", "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives",
    "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus", "fmi2GetRealStatus", "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus", "fmi2GetStringStatus"};
enum { N_FUNCTIONS = sizeof kNames / sizeof kNames[0] };
/* dlsym's object pointers, copied into function pointers (ISO C has no cast between the
   two; POSIX guarantees the representation). */
typedef void (*AnyFunction)(void);
static AnyFunction fn[N_FUNCTIONS];

static AnyFunction get(const char* name) {
  for (size_t i = 0; i < N_FUNCTIONS; ++i)
    if (strcmp(kNames[i], name) == 0) return fn[i];
  fail("internal: unknown function name");
  return NULL;
}
#define F(name) ((name##TYPE*)get(#name))

typedef struct {
  fmi2ValueReference in[MAX_VR];
  long in_step[MAX_VR];
  size_t n_in;
  fmi2ValueReference out[MAX_VR];
  size_t n_out;
} Io;

/* Steps k0..k1-1 from time k0 * h; writes one line of outputs per step into lines. */
static void run(fmi2Component c, const Io* io, double h, long k0, long k1, char* lines, size_t width) {
  for (long k = k0; k < k1; ++k) {
    for (size_t i = 0; i < io->n_in; ++i) {
      fmi2Boolean v = k >= io->in_step[i] ? fmi2True : fmi2False;
      expect(F(fmi2SetBoolean)(c, &io->in[i], 1, &v), fmi2OK, "fmi2SetBoolean");
    }
    expect(F(fmi2DoStep)(c, (double)k * h, h, fmi2True), fmi2OK, "fmi2DoStep");
    fmi2Boolean out[MAX_VR];
    if (io->n_out) expect(F(fmi2GetBoolean)(c, io->out, io->n_out, out), fmi2OK, "fmi2GetBoolean");
    char* line = lines + (size_t)k * width;
    for (size_t i = 0; i < io->n_out; ++i) line[i] = out[i] ? '1' : '0';
    line[io->n_out] = '\0';
  }
}

int main(int argc, char** argv) {
  if (argc < 6) fail("usage: plcfi_fmu_importer DIR MODEL_IDENTIFIER GUID STEP_S STEPS [options]");
  const char* dir = argv[1];
  const char* id = argv[2];
  const char* guid = argv[3];
  const double h = atof(argv[4]);
  const long steps = atol(argv[5]);
  if (!(h > 0) || steps < 2) fail("STEP_S must be > 0 and STEPS at least 2");
  Io io;
  memset(&io, 0, sizeof io);
  int state = 0;
  fmi2ValueReference str_vr[MAX_VR];
  fmi2String str_value[MAX_VR];
  size_t n_str = 0;
  for (int i = 6; i < argc; ++i) {
    if (strcmp(argv[i], "--state") == 0) {
      state = 1;
    } else if (strcmp(argv[i], "--string") == 0 && i + 1 < argc && n_str < MAX_VR) {
      char* eq = strchr(argv[++i], '=');
      if (!eq) fail("--string VR=TEXT");
      str_vr[n_str] = (fmi2ValueReference)strtoul(argv[i], NULL, 10);
      str_value[n_str++] = eq + 1;
    } else if (strcmp(argv[i], "--bool-in") == 0 && i + 1 < argc && io.n_in < MAX_VR) {
      unsigned vr;
      long k;
      if (sscanf(argv[++i], "%u@%ld", &vr, &k) != 2) fail("--bool-in VR@K");
      io.in[io.n_in] = vr;
      io.in_step[io.n_in++] = k;
    } else if (strcmp(argv[i], "--bool-out") == 0 && i + 1 < argc && io.n_out < MAX_VR) {
      io.out[io.n_out++] = (fmi2ValueReference)strtoul(argv[++i], NULL, 10);
    } else {
      fprintf(stderr, "importer: unknown option %s\n", argv[i]);
      return 2;
    }
  }

  /* Load, and resolve every function before calling any. */
  char path[4096];
  snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", dir, id);
  void* lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    fprintf(stderr, "importer: %s\n", dlerror());
    return 1;
  }
  int missing = 0;
  for (size_t i = 0; i < N_FUNCTIONS; ++i) {
    void* p = dlsym(lib, kNames[i]);
    memcpy(&fn[i], &p, sizeof p);
    if (!p) {
      printf("missing: %s\n", kNames[i]);
      ++missing;
    }
  }
  if (missing) return 1;
  printf("resolved all %d functions\n", (int)N_FUNCTIONS);
  if (strcmp(F(fmi2GetVersion)(), "2.0") != 0) fail("fmi2GetVersion is not 2.0");
  if (strcmp(F(fmi2GetTypesPlatform)(), "default") != 0) fail("fmi2GetTypesPlatform is not default");

  /* The calling sequence: instantiate, set up, initialize, step. */
  char uri[4200];
  snprintf(uri, sizeof uri, "file://%s/resources", dir);
  fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
  fmi2Component c = F(fmi2Instantiate)("importer", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
  if (!c) fail("fmi2Instantiate returned NULL");
  expect(F(fmi2SetDebugLogging)(c, fmi2False, 0, NULL), fmi2OK, "fmi2SetDebugLogging");
  expect(F(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK, "fmi2SetupExperiment");
  expect(F(fmi2EnterInitializationMode)(c), fmi2OK, "fmi2EnterInitializationMode");
  if (n_str) expect(F(fmi2SetString)(c, str_vr, n_str, str_value), fmi2OK, "fmi2SetString");
  expect(F(fmi2ExitInitializationMode)(c), fmi2OK, "fmi2ExitInitializationMode");

  const size_t width = io.n_out + 1;
  char* first = calloc((size_t)steps, width);
  char* again = calloc((size_t)steps, width);
  if (!first || !again) fail("out of memory");
  const long half = steps / 2;
  fmi2FMUstate saved = NULL;
  run(c, &io, h, 0, half, first, width);
  if (state) expect(F(fmi2GetFMUstate)(c, &saved), fmi2OK, "fmi2GetFMUstate");
  run(c, &io, h, half, steps, first, width);
  for (long k = 0; k < steps; ++k) printf("%s\n", first + (size_t)k * width);
  if (state) {
    expect(F(fmi2SetFMUstate)(c, saved), fmi2OK, "fmi2SetFMUstate");
    fmi2Real t = -1;
    expect(F(fmi2GetRealStatus)(c, fmi2LastSuccessfulTime, &t), fmi2OK, "fmi2GetRealStatus");
    if (t < (double)half * h - 1e-9 || t > (double)half * h + 1e-9) fail("the restored state is not at the saved time");
    run(c, &io, h, half, steps, again, width);
    for (long k = half; k < steps; ++k)
      if (strcmp(first + (size_t)k * width, again + (size_t)k * width) != 0) {
        fprintf(stderr, "importer: step %ld after fmi2SetFMUstate: %s, first run: %s\n", k, again + (size_t)k * width,
                first + (size_t)k * width);
        return 1;
      }
    printf("state restored: the second half ran the same\n");
    expect(F(fmi2FreeFMUstate)(c, &saved), fmi2OK, "fmi2FreeFMUstate");
    if (saved) fail("fmi2FreeFMUstate left the pointer set");
  }

  /* The rest of the API, once each: a function of a capability the FMU does not claim
     must refuse with fmi2Error and say why in its log. */
  struct {
    const char* name;
    fmi2Status status;
  } refused[7];
  fmi2ValueReference vr0 = 0;
  fmi2Real r = 0;
  fmi2Integer order = 1;
  size_t size = 0;
  fmi2Byte bytes[16];
  fmi2FMUstate other = NULL;
  logged = 0;
  refused[0].name = "fmi2SerializedFMUstateSize";
  refused[0].status = F(fmi2SerializedFMUstateSize)(c, saved, &size);
  refused[1].name = "fmi2SerializeFMUstate";
  refused[1].status = F(fmi2SerializeFMUstate)(c, saved, bytes, sizeof bytes);
  refused[2].name = "fmi2DeSerializeFMUstate";
  refused[2].status = F(fmi2DeSerializeFMUstate)(c, bytes, sizeof bytes, &other);
  refused[3].name = "fmi2GetDirectionalDerivative";
  refused[3].status = F(fmi2GetDirectionalDerivative)(c, &vr0, 1, &vr0, 1, &r, &r);
  refused[4].name = "fmi2SetRealInputDerivatives";
  refused[4].status = F(fmi2SetRealInputDerivatives)(c, &vr0, 1, &order, &r);
  refused[5].name = "fmi2GetRealOutputDerivatives";
  refused[5].status = F(fmi2GetRealOutputDerivatives)(c, &vr0, 1, &order, &r);
  refused[6].name = "fmi2CancelStep";
  refused[6].status = F(fmi2CancelStep)(c);
  for (int i = 0; i < 7; ++i)
    if (refused[i].status != fmi2Error) {
      fprintf(stderr, "importer: %s returned %d; an FMU without the capability returns fmi2Error\n", refused[i].name,
              (int)refused[i].status);
      return 1;
    }
  if (logged < 6) fail("the refusals did not say why in the FMU's log");
  printf("refused with a log message: serialization, derivatives, cancel\n");
  /* The status queries and the empty exchanges of the other types. */
  fmi2Status st;
  fmi2Integer iv;
  fmi2Boolean bv;
  fmi2String sv;
  (void)F(fmi2GetStatus)(c, fmi2DoStepStatus, &st);
  (void)F(fmi2GetIntegerStatus)(c, fmi2DoStepStatus, &iv);
  expect(F(fmi2GetBooleanStatus)(c, fmi2Terminated, &bv), fmi2OK, "fmi2GetBooleanStatus");
  (void)F(fmi2GetStringStatus)(c, fmi2DoStepStatus, &sv);
  expect(F(fmi2GetReal)(c, NULL, 0, NULL), fmi2OK, "fmi2GetReal (none)");
  expect(F(fmi2SetReal)(c, NULL, 0, NULL), fmi2OK, "fmi2SetReal (none)");
  expect(F(fmi2GetInteger)(c, NULL, 0, NULL), fmi2OK, "fmi2GetInteger (none)");
  expect(F(fmi2SetInteger)(c, NULL, 0, NULL), fmi2OK, "fmi2SetInteger (none)");
  expect(F(fmi2GetString)(c, NULL, 0, NULL), fmi2OK, "fmi2GetString (none)");
  expect(F(fmi2SetString)(c, NULL, 0, NULL), fmi2OK, "fmi2SetString (none)");

  /* Reset, a second run from the start: the same outputs (the first half). */
  expect(F(fmi2Reset)(c), fmi2OK, "fmi2Reset");
  expect(F(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK, "fmi2SetupExperiment");
  expect(F(fmi2EnterInitializationMode)(c), fmi2OK, "fmi2EnterInitializationMode");
  if (n_str) expect(F(fmi2SetString)(c, str_vr, n_str, str_value), fmi2OK, "fmi2SetString");
  expect(F(fmi2ExitInitializationMode)(c), fmi2OK, "fmi2ExitInitializationMode");
  run(c, &io, h, 0, half, again, width);
  for (long k = 0; k < half; ++k)
    if (strcmp(first + (size_t)k * width, again + (size_t)k * width) != 0) fail("after fmi2Reset the run differs");
  expect(F(fmi2Terminate)(c), fmi2OK, "fmi2Terminate");
  F(fmi2FreeInstance)(c);
  free(first);
  free(again);
  dlclose(lib);
  printf("ok\n");
  return 0;
}
