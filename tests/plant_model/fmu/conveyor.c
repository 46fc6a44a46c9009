/* conveyor.c: the `conveyor` test FMU, a belt that carries boxes past a light barrier and
   drops them off its end, for the plant-model tests and the conveyor demo
   (st_programs/conveyor).

   Value references (conveyor.xml), distinct per type:
     Boolean  1 Motor           input     2 LightBarrier  output
     Integer  1 BoxesDelivered  output
     Real     1 BeltSpeed       output (m/s)
             10 Speed (m/s)   11 RampTime (s)       12 BeltLength (m)
             13 BarrierPosition (m)   14 BoxLength (m)   15 BoxInterval (s)
                                                         (fixed parameters)

   Physics, in substeps of at most 1 ms:
   - the belt speed ramps linearly (Speed per RampTime) to Speed while Motor, to 0 when
     not;
   - a box is at position p when its rear edge is p metres from the belt start: it covers
     [p, p + BoxLength] and moves with the belt;
   - the feeder puts a box at position 0 at start time + 0.5 s and then every BoxInterval,
     on a fixed schedule; when a box is due while the entry [0, BoxLength] is still
     covered (the belt stopped with a box on it), that box is skipped, so boxes never touch
     and the barrier sees each one apart;
   - the light barrier at BarrierPosition is TRUE while a box covers it;
   - a box whose centre passes BeltLength falls off: BoxesDelivered counts it.
   With the defaults and the motor on from the start, a box covers the barrier from
   t = 3.1 s to 3.5 s, falls off at t = 4.3 s, and the next one comes at 4.5 s. */
#include <math.h>

#include "fmu_support.h"

#define MAX_BOXES 16        /* on the belt at once; the feeder skips a box while it is full */
#define FIRST_BOX_DELAY 0.5 /* seconds after the start time */

typedef struct {
  /* input */
  int motor;
  /* parameters */
  double speed;
  double ramp_time;
  double belt_length;
  double barrier_position;
  double box_length;
  double box_interval;
  /* outputs */
  int light_barrier;
  int boxes_delivered;
  double belt_speed;
  /* state: the boxes' rear edges in the order they came (the first is the farthest) */
  double box[MAX_BOXES];
  int n_boxes;
  double next_box_time; /* when the feeder puts the next box on */
} Conveyor;

#define VAR(name, type, vr, causality, field, range) {name, type, vr, causality, offsetof(Conveyor, field), range}
static const FmuVariable kVariables[] = {
    VAR("Motor", FMU_BOOLEAN, 1, FMU_INPUT, motor, FMU_ANY),
    VAR("LightBarrier", FMU_BOOLEAN, 2, FMU_OUTPUT, light_barrier, FMU_ANY),
    VAR("BoxesDelivered", FMU_INTEGER, 1, FMU_OUTPUT, boxes_delivered, FMU_ANY),
    VAR("BeltSpeed", FMU_REAL, 1, FMU_OUTPUT, belt_speed, FMU_ANY),
    VAR("Speed", FMU_REAL, 10, FMU_PARAMETER, speed, FMU_NON_NEGATIVE),
    VAR("RampTime", FMU_REAL, 11, FMU_PARAMETER, ramp_time, FMU_NON_NEGATIVE),
    VAR("BeltLength", FMU_REAL, 12, FMU_PARAMETER, belt_length, FMU_POSITIVE),
    VAR("BarrierPosition", FMU_REAL, 13, FMU_PARAMETER, barrier_position, FMU_NON_NEGATIVE),
    VAR("BoxLength", FMU_REAL, 14, FMU_PARAMETER, box_length, FMU_POSITIVE),
    VAR("BoxInterval", FMU_REAL, 15, FMU_PARAMETER, box_interval, FMU_POSITIVE),
};

static void defaults(Fmu* f) {
  Conveyor* m = f->data;
  m->motor = 0;
  m->speed = 0.5;
  m->ramp_time = 0.2;
  m->belt_length = 2.0;
  m->barrier_position = 1.5;
  m->box_length = 0.2;
  m->box_interval = 4.0;
}

static void update_outputs(Conveyor* m) {
  m->light_barrier = 0;
  for (int i = 0; i < m->n_boxes; ++i)
    if (m->box[i] <= m->barrier_position && m->barrier_position <= m->box[i] + m->box_length) m->light_barrier = 1;
}

static void initialize(Fmu* f) {
  Conveyor* m = f->data;
  m->belt_speed = 0.0;
  m->boxes_delivered = 0;
  m->n_boxes = 0;
  m->next_box_time = f->start_time + FIRST_BOX_DELAY;
  update_outputs(m);
}

/* One Euler substep of length dt that ends at time t. */
static void substep(Fmu* f, double t, double dt) {
  Conveyor* m = f->data;
  /* boxes move with the speed at the start of the substep (explicit Euler) */
  for (int i = 0; i < m->n_boxes; ++i) m->box[i] += m->belt_speed * dt;

  double target = m->motor ? m->speed : 0.0;
  if (m->ramp_time <= 0.0) {
    m->belt_speed = target;
  } else {
    double dv = m->speed / m->ramp_time * dt;
    m->belt_speed = m->belt_speed < target ? fmin(m->belt_speed + dv, target) : fmax(m->belt_speed - dv, target);
  }

  /* the first box is the farthest: boxes fall off in order */
  int off = 0;
  while (off < m->n_boxes && m->box[off] + m->box_length / 2.0 >= m->belt_length) ++off;
  if (off > 0) {
    for (int i = off; i < m->n_boxes; ++i) m->box[i - off] = m->box[i];
    m->n_boxes -= off;
    m->boxes_delivered += off;
  }

  if (t >= m->next_box_time - fmu_time_eps(t)) {
    int entry_free = m->n_boxes == 0 || m->box[m->n_boxes - 1] >= m->box_length;
    if (entry_free && m->n_boxes < MAX_BOXES) m->box[m->n_boxes++] = 0.0;
    /* a schedule: no drift from the substep grid; a BoxInterval shorter than a substep
       gives one box per substep */
    while (m->next_box_time <= t + fmu_time_eps(t)) m->next_box_time += m->box_interval;
  }
}

static fmi2Status do_step(Fmu* f, double h) {
  Conveyor* m = f->data;
  double t0 = f->time;
  size_t n = fmu_substeps(h);
  double dt = h / (double)n;
  for (size_t i = 1; i <= n; ++i) substep(f, t0 + (double)i * dt, dt);
  update_outputs(m);
  f->time = t0 + h;
  return fmi2OK;
}

const FmuModel fmu_model = {
    .data_size = sizeof(Conveyor),
    .variables = kVariables,
    .n_variables = sizeof kVariables / sizeof kVariables[0],
    .defaults = defaults,
    .initialize = initialize,
    .check = NULL,
    .do_step = do_step,
};
