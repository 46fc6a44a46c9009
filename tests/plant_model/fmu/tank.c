/* tank.c: the `tank` test FMU, a water tank with an inlet and an outlet valve, for the
   plant-model tests and the tank demo (st_programs/tank).

   Value references (tank.xml), distinct per type; the Real and the Boolean 1 are different
   variables on purpose, so that a loader mixing the types up is caught:
     Boolean  1 InletValve    input      2 OutletValve  input
              3 LowSwitch     output     4 HighSwitch   output
     Real     1 Level         output (m)
             10 Area (m2)    11 Inflow (m3/s)   12 OutflowCoeff (m3/s per sqrt(m))
             13 Height (m)   14 LowMark (m)     15 HighMark (m)   16 InitialLevel (m)
                                                                  (fixed parameters)

   Physics: Area * dLevel/dt = Inflow [InletValve] - OutflowCoeff * sqrt(Level) [OutletValve]
   (Torricelli outflow), explicit Euler in substeps of at most 1 ms, Level clamped to
   [0, Height]. The inputs are held over a communication step. */
#include <math.h>

#include "fmu_support.h"

typedef struct {
  /* inputs */
  int inlet_valve;
  int outlet_valve;
  /* parameters */
  double area;
  double inflow;
  double outflow_coeff;
  double height;
  double low_mark;
  double high_mark;
  double initial_level;
  /* outputs; Level is the state */
  double level;
  int low_switch;
  int high_switch;
} Tank;

#define VAR(name, type, vr, causality, field, range) {name, type, vr, causality, offsetof(Tank, field), range}
static const FmuVariable kVariables[] = {
    VAR("InletValve", FMU_BOOLEAN, 1, FMU_INPUT, inlet_valve, FMU_ANY),
    VAR("OutletValve", FMU_BOOLEAN, 2, FMU_INPUT, outlet_valve, FMU_ANY),
    VAR("Level", FMU_REAL, 1, FMU_OUTPUT, level, FMU_ANY),
    VAR("LowSwitch", FMU_BOOLEAN, 3, FMU_OUTPUT, low_switch, FMU_ANY),
    VAR("HighSwitch", FMU_BOOLEAN, 4, FMU_OUTPUT, high_switch, FMU_ANY),
    VAR("Area", FMU_REAL, 10, FMU_PARAMETER, area, FMU_POSITIVE),
    VAR("Inflow", FMU_REAL, 11, FMU_PARAMETER, inflow, FMU_NON_NEGATIVE),
    VAR("OutflowCoeff", FMU_REAL, 12, FMU_PARAMETER, outflow_coeff, FMU_NON_NEGATIVE),
    VAR("Height", FMU_REAL, 13, FMU_PARAMETER, height, FMU_POSITIVE),
    VAR("LowMark", FMU_REAL, 14, FMU_PARAMETER, low_mark, FMU_NON_NEGATIVE),
    VAR("HighMark", FMU_REAL, 15, FMU_PARAMETER, high_mark, FMU_NON_NEGATIVE),
    VAR("InitialLevel", FMU_REAL, 16, FMU_PARAMETER, initial_level, FMU_NON_NEGATIVE),
};

static void defaults(Fmu* f) {
  Tank* m = f->data;
  m->inlet_valve = 0;
  m->outlet_valve = 0;
  m->area = 1.0;
  m->inflow = 0.02;
  m->outflow_coeff = 0.03;
  m->height = 2.0;
  m->low_mark = 0.2;
  m->high_mark = 1.6;
  m->initial_level = 0.5;
}

static void update_outputs(Tank* m) {
  m->low_switch = m->level <= m->low_mark;
  m->high_switch = m->level >= m->high_mark;
}

static double clamp_level(const Tank* m, double level) { return fmin(fmax(level, 0.0), m->height); }

static void initialize(Fmu* f) {
  Tank* m = f->data;
  m->level = clamp_level(m, m->initial_level);
  update_outputs(m);
}

static fmi2Status do_step(Fmu* f, double h) {
  Tank* m = f->data;
  size_t n = fmu_substeps(h);
  double dt = h / (double)n;
  for (size_t i = 0; i < n; ++i) {
    double q = (m->inlet_valve ? m->inflow : 0.0) - (m->outlet_valve ? m->outflow_coeff * sqrt(m->level) : 0.0);
    m->level = clamp_level(m, m->level + q * dt / m->area);
  }
  update_outputs(m);
  f->time += h;
  return fmi2OK;
}

const FmuModel fmu_model = {
    .data_size = sizeof(Tank),
    .variables = kVariables,
    .n_variables = sizeof kVariables / sizeof kVariables[0],
    .defaults = defaults,
    .initialize = initialize,
    .check = NULL,
    .do_step = do_step,
};
