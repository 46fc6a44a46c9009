/* cosim.c: a co-simulation master of its own (C, dlopen, the FMI 2.0 calling sequence) that
   couples FMUs as a tool like OMSimulator or FMPy would: the PLC program exported by
   `plcfi export-fmu` against the stamping plant exported by `plcfi plant export-fmu`.

   usage: plcfi_fmu_cosim SETUP STEP_S STEPS
   SETUP is a text file, one statement per line ('#' starts a comment):
     fmu NAME DIR MODEL_IDENTIFIER GUID       an unpacked FMU; they step in this order
     param NAME TYPE VR VALUE                 set before initialization (TYPE Real, Integer,
                                              Boolean or String; a String runs to the line's end)
     link TYPE FROM VR TO VR                  before TO steps, TO's input VR gets FROM's output VR
     watch NAME TYPE VR LABEL                 printed after every step
   Each step k (time k * STEP_S): for each FMU in order, its links are copied in, then
   fmi2DoStep. The program FMU first, reading the plant's outputs of time t, then the
   plant with the program's commands: the order of a scan in `plcfi sim`.
   Prints a CSV trace (time, then the watches) to stdout, the FMUs' log messages to
   stderr. Exit 1 when a call does not return fmi2OK (or fmi2Warning from fmi2DoStep). */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plant_model/fmu/fmi2.h"

#define MAX_FMUS 4
#define MAX_ITEMS 256

typedef struct {
  char name[64];
  void* lib;
  fmi2Component c;
  fmi2InstantiateTYPE* instantiate;
  fmi2SetupExperimentTYPE* setup;
  fmi2EnterInitializationModeTYPE* enter;
  fmi2ExitInitializationModeTYPE* exit_init;
  fmi2DoStepTYPE* step;
  fmi2GetRealTYPE* get_real;
  fmi2SetRealTYPE* set_real;
  fmi2GetIntegerTYPE* get_int;
  fmi2SetIntegerTYPE* set_int;
  fmi2GetBooleanTYPE* get_bool;
  fmi2SetBooleanTYPE* set_bool;
  fmi2SetStringTYPE* set_string;
  fmi2TerminateTYPE* terminate;
  fmi2FreeInstanceTYPE* free_instance;
} Fmu;

typedef enum { T_REAL, T_INTEGER, T_BOOLEAN, T_STRING } Type;

typedef struct {
  Type type;
  int from, to;  /* FMU indices; for param and watch only `to` */
  fmi2ValueReference from_vr, to_vr;
  char text[256]; /* param value or watch label */
} Item;

static Fmu fmus[MAX_FMUS];
static int n_fmus;
static Item links[MAX_ITEMS], params[MAX_ITEMS], watches[MAX_ITEMS];
static int n_links, n_params, n_watches;

static void log_message(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                        fmi2String message, ...) {
  (void)env;
  (void)category;
  va_list ap;
  va_start(ap, message);
  fprintf(stderr, "[%s status %d] ", instance ? instance : "?", (int)status);
  vfprintf(stderr, message, ap);
  fputc('\n', stderr);
  va_end(ap);
}

static void die(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fputs("cosim: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
  exit(1);
}

static void check(fmi2Status s, const char* call, const Fmu* f) {
  if (s != fmi2OK) die("%s of %s returned status %d", call, f->name, (int)s);
}

static void* sym(void* lib, const char* name) {
  void* p = dlsym(lib, name);
  if (!p) die("missing function %s", name);
  return p;
}

/* dlsym's object pointers into function pointers (POSIX guarantees the representation). */
#define LOAD(field, name) memcpy(&f->field, &(void*){sym(f->lib, name)}, sizeof(void*))

static int fmu_index(const char* name, int line) {
  for (int i = 0; i < n_fmus; ++i)
    if (strcmp(fmus[i].name, name) == 0) return i;
  die("line %d: no fmu named %s", line, name);
  return -1;
}

static Type type_of(const char* s, int line) {
  if (strcmp(s, "Real") == 0) return T_REAL;
  if (strcmp(s, "Integer") == 0) return T_INTEGER;
  if (strcmp(s, "Boolean") == 0) return T_BOOLEAN;
  if (strcmp(s, "String") == 0) return T_STRING;
  die("line %d: unknown type %s", line, s);
  return T_REAL;
}

static void open_fmu(const char* name, const char* dir, const char* id, const char* guid) {
  if (n_fmus == MAX_FMUS) die("too many FMUs");
  Fmu* f = &fmus[n_fmus++];
  snprintf(f->name, sizeof f->name, "%.63s", name);
  char path[4096];
  snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", dir, id);
  f->lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!f->lib) die("%s", dlerror());
  LOAD(instantiate, "fmi2Instantiate");
  LOAD(setup, "fmi2SetupExperiment");
  LOAD(enter, "fmi2EnterInitializationMode");
  LOAD(exit_init, "fmi2ExitInitializationMode");
  LOAD(step, "fmi2DoStep");
  LOAD(get_real, "fmi2GetReal");
  LOAD(set_real, "fmi2SetReal");
  LOAD(get_int, "fmi2GetInteger");
  LOAD(set_int, "fmi2SetInteger");
  LOAD(get_bool, "fmi2GetBoolean");
  LOAD(set_bool, "fmi2SetBoolean");
  LOAD(set_string, "fmi2SetString");
  LOAD(terminate, "fmi2Terminate");
  LOAD(free_instance, "fmi2FreeInstance");
  char uri[4200];
  snprintf(uri, sizeof uri, "file://%s/resources", dir);
  static fmi2CallbackFunctions cb = {log_message, calloc, free, NULL, NULL};
  f->c = f->instantiate(name, fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
  if (!f->c) die("fmi2Instantiate of %s returned NULL", name);
}

static void read_setup(const char* file) {
  FILE* in = fopen(file, "r");
  if (!in) die("cannot open %s", file);
  char line[1024];
  int n = 0;
  while (fgets(line, sizeof line, in)) {
    ++n;
    line[strcspn(line, "\r\n")] = '\0';
    char* hash = strchr(line, '#');
    if (hash && strncmp(line, "param", 5) != 0) *hash = '\0';
    char kw[16], a[1024], b[1024], c[1024], d[1024], e[1024];
    int got = sscanf(line, "%15s %1023s %1023s %1023s %1023s %1023s", kw, a, b, c, d, e);
    if (got <= 0) continue;
    if (strcmp(kw, "fmu") == 0 && got == 5) {
      open_fmu(a, b, c, d);
    } else if (strcmp(kw, "param") == 0 && got >= 4 && n_params < MAX_ITEMS) {
      Item* it = &params[n_params++];
      it->to = fmu_index(a, n);
      it->type = type_of(b, n);
      it->to_vr = (fmi2ValueReference)strtoul(c, NULL, 10);
      /* The value: the rest of the line after the value reference (may be empty or hold spaces). */
      const char* p = strstr(line, c) + strlen(c);
      while (*p == ' ') ++p;
      snprintf(it->text, sizeof it->text, "%.255s", p);
    } else if (strcmp(kw, "link") == 0 && got == 6 && n_links < MAX_ITEMS) {
      Item* it = &links[n_links++];
      it->type = type_of(a, n);
      it->from = fmu_index(b, n);
      it->from_vr = (fmi2ValueReference)strtoul(c, NULL, 10);
      it->to = fmu_index(d, n);
      it->to_vr = (fmi2ValueReference)strtoul(e, NULL, 10);
    } else if (strcmp(kw, "watch") == 0 && got == 5 && n_watches < MAX_ITEMS) {
      Item* it = &watches[n_watches++];
      it->to = fmu_index(a, n);
      it->type = type_of(b, n);
      it->to_vr = (fmi2ValueReference)strtoul(c, NULL, 10);
      snprintf(it->text, sizeof it->text, "%.255s", d);
    } else {
      die("%s:%d: not a statement: %s", file, n, line);
    }
  }
  fclose(in);
}

static void set_param(const Item* it) {
  Fmu* f = &fmus[it->to];
  switch (it->type) {
    case T_REAL: {
      fmi2Real v = atof(it->text);
      check(f->set_real(f->c, &it->to_vr, 1, &v), "fmi2SetReal", f);
      break;
    }
    case T_INTEGER: {
      fmi2Integer v = atoi(it->text);
      check(f->set_int(f->c, &it->to_vr, 1, &v), "fmi2SetInteger", f);
      break;
    }
    case T_BOOLEAN: {
      fmi2Boolean v = strcmp(it->text, "true") == 0 || strcmp(it->text, "1") == 0;
      check(f->set_bool(f->c, &it->to_vr, 1, &v), "fmi2SetBoolean", f);
      break;
    }
    case T_STRING: {
      fmi2String v = it->text;
      check(f->set_string(f->c, &it->to_vr, 1, &v), "fmi2SetString", f);
      break;
    }
  }
}

static void copy_link(const Item* it) {
  Fmu* from = &fmus[it->from];
  Fmu* to = &fmus[it->to];
  switch (it->type) {
    case T_REAL: {
      fmi2Real v;
      check(from->get_real(from->c, &it->from_vr, 1, &v), "fmi2GetReal", from);
      check(to->set_real(to->c, &it->to_vr, 1, &v), "fmi2SetReal", to);
      break;
    }
    case T_INTEGER: {
      fmi2Integer v;
      check(from->get_int(from->c, &it->from_vr, 1, &v), "fmi2GetInteger", from);
      check(to->set_int(to->c, &it->to_vr, 1, &v), "fmi2SetInteger", to);
      break;
    }
    case T_BOOLEAN: {
      fmi2Boolean v;
      check(from->get_bool(from->c, &it->from_vr, 1, &v), "fmi2GetBoolean", from);
      check(to->set_bool(to->c, &it->to_vr, 1, &v), "fmi2SetBoolean", to);
      break;
    }
    case T_STRING: die("String links are not supported");
  }
}

static void print_watch(const Item* it) {
  Fmu* f = &fmus[it->to];
  switch (it->type) {
    case T_REAL: {
      fmi2Real v;
      check(f->get_real(f->c, &it->to_vr, 1, &v), "fmi2GetReal", f);
      printf(",%.10g", v);
      break;
    }
    case T_INTEGER: {
      fmi2Integer v;
      check(f->get_int(f->c, &it->to_vr, 1, &v), "fmi2GetInteger", f);
      printf(",%d", v);
      break;
    }
    case T_BOOLEAN: {
      fmi2Boolean v;
      check(f->get_bool(f->c, &it->to_vr, 1, &v), "fmi2GetBoolean", f);
      printf(",%d", v ? 1 : 0);
      break;
    }
    case T_STRING: die("String watches are not supported");
  }
}

int main(int argc, char** argv) {
  if (argc != 4) die("usage: plcfi_fmu_cosim SETUP STEP_S STEPS");
  const double h = atof(argv[2]);
  const long steps = atol(argv[3]);
  if (!(h > 0) || steps < 1) die("STEP_S must be > 0 and STEPS at least 1");
  read_setup(argv[1]);
  if (n_fmus == 0) die("no fmu in %s", argv[1]);
  for (int i = 0; i < n_fmus; ++i) {
    check(fmus[i].setup(fmus[i].c, fmi2False, 0.0, 0.0, fmi2False, 0.0), "fmi2SetupExperiment", &fmus[i]);
    check(fmus[i].enter(fmus[i].c), "fmi2EnterInitializationMode", &fmus[i]);
  }
  for (int i = 0; i < n_params; ++i) set_param(&params[i]);
  for (int i = 0; i < n_fmus; ++i) check(fmus[i].exit_init(fmus[i].c), "fmi2ExitInitializationMode", &fmus[i]);
  printf("time");
  for (int i = 0; i < n_watches; ++i) printf(",%s", watches[i].text);
  printf("\n");
  int warned = 0;
  for (long k = 0; k < steps; ++k) {
    const double t = (double)k * h;
    for (int i = 0; i < n_fmus; ++i) {
      for (int j = 0; j < n_links; ++j)
        if (links[j].to == i) copy_link(&links[j]);
      fmi2Status s = fmus[i].step(fmus[i].c, t, h, fmi2True);
      if (s == fmi2Warning) {
        ++warned;
      } else {
        check(s, "fmi2DoStep", &fmus[i]);
      }
    }
    printf("%.10g", t);
    for (int i = 0; i < n_watches; ++i) print_watch(&watches[i]);
    printf("\n");
  }
  for (int i = 0; i < n_fmus; ++i) {
    check(fmus[i].terminate(fmus[i].c), "fmi2Terminate", &fmus[i]);
    fmus[i].free_instance(fmus[i].c);
    dlclose(fmus[i].lib);
  }
  if (warned) fprintf(stderr, "cosim: %d step(s) ended with fmi2Warning\n", warned);
  return 0;
}
