/* fmu_support.h: the FMI 2.0 co-simulation interface shared by plcfi's test FMUs. A model
   file (tank.c, conveyor.c, probe.c) only describes its variables and its physics in an
   FmuModel; fmu_support.c, compiled into every FMU, defines all the exported fmi2
   functions on top of it: argument and state checks, logging, value access by value
   reference.

   The GUID is not part of the model: CMake reads it from the FMU's modelDescription.xml
   and defines FMU_GUID, so the two cannot disagree. */
#ifndef PLCFI_TEST_FMU_SUPPORT_H
#define PLCFI_TEST_FMU_SUPPORT_H

#include <stddef.h>

#include "fmi2.h"

typedef enum { FMU_REAL, FMU_INTEGER, FMU_BOOLEAN } FmuType;
typedef enum { FMU_INPUT, FMU_OUTPUT, FMU_PARAMETER } FmuCausality;

/* Allowed values of a parameter, checked when it is set. */
typedef enum { FMU_ANY, FMU_POSITIVE, FMU_NON_NEGATIVE } FmuRange;

/* One scalar variable of modelDescription.xml. Its value lives in the model's state struct
   at `offset` (offsetof): a double for FMU_REAL, an int for FMU_INTEGER and FMU_BOOLEAN. */
typedef struct {
  const char* name;
  FmuType type;
  fmi2ValueReference vr;
  FmuCausality causality;
  size_t offset;
  FmuRange range; /* parameters only */
} FmuVariable;

/* Life cycle of an instance (the co-simulation state machine of the standard, reduced). */
typedef enum {
  FMU_INSTANTIATED, /* after fmi2Instantiate or fmi2Reset */
  FMU_INIT_MODE,    /* between Enter- and ExitInitializationMode */
  FMU_STEP_MODE,    /* fmi2DoStep allowed (unless `terminated`) */
  FMU_TERMINATED,   /* after fmi2Terminate */
  FMU_ERROR         /* a step or the initialization failed: only Get*, Reset, FreeInstance */
} FmuState;

typedef struct FmuModel FmuModel;

/* An instance: what every FMU needs, plus the model's own state struct. */
typedef struct {
  const FmuModel* model;
  fmi2CallbackFunctions functions; /* a copy: the importer's struct need not outlive the call */
  char* name;
  int logging_on;
  FmuState state;
  double time;       /* the FMU's time: the end of the last successful step */
  double start_time; /* from fmi2SetupExperiment */
  int stop_time_defined;
  double stop_time;
  int terminated; /* the FMU ended the simulation itself (a step returned fmi2Discard) */
  void* data;     /* the model's state struct, model->data_size bytes, zeroed */
} Fmu;

struct FmuModel {
  size_t data_size;
  const FmuVariable* variables;
  size_t n_variables;
  /* Parameter and input start values (fmi2Instantiate, fmi2Reset). */
  void (*defaults)(Fmu* f);
  /* State at the start time from the parameters, with the outputs: at instantiation, after
     each parameter change before the simulation runs, and at ExitInitializationMode. */
  void (*initialize)(Fmu* f);
  /* Optional: a model-specific check of the experiment and the parameters, at
     fmi2SetupExperiment and fmi2EnterInitializationMode; logs its reason when it fails. */
  fmi2Status (*check)(Fmu* f);
  /* One communication step from f->time (checked to be the current communication point)
     by h > 0. Advances the state, the outputs and f->time; may stop early and return
     fmi2Discard after setting f->terminated, or fail with fmi2Error after logging why. */
  fmi2Status (*do_step)(Fmu* f, double h);
};

/* The model of this FMU, defined by the model file. */
extern const FmuModel fmu_model;

/* Logs through the importer's logger (if any). Errors, warnings and discards always go
   out; fmi2OK messages only with debug logging on. printf-style. */
void fmu_log(const Fmu* f, fmi2Status status, const char* format, ...)
    __attribute__((format(printf, 3, 4)));

/* Number of explicit-Euler substeps for a step of size h: substeps are at most
   FMU_MAX_SUBSTEP seconds long, so the result does not depend much on the communication
   step the importer chooses. */
#define FMU_MAX_SUBSTEP 1e-3
size_t fmu_substeps(double h);

/* Tolerance for comparing times given as sums of doubles. */
double fmu_time_eps(double t);

#endif /* PLCFI_TEST_FMU_SUPPORT_H */
