#!/usr/bin/env python3
"""Generate a large, plant-like IEC 61131-3 Structured Text program (issue 31's scale benchmark).

usage: gen_scale.py [--fbs N] [--seed S] [-o FILE]

Writes one .st file (stdout without -o) holding
  * TYPE declarations: a few STRUCTs (alarm record, unit status, valve diagnostics) and one
    enumerated type per group of sequencers;
  * a handful of FUNCTIONs (scaling, clamping, first-order lag);
  * N FUNCTION_BLOCKs (default 2,000, ~21 lines each: 40,000+ lines in all) in four levels:
      leaves (~72 %): valves, motors, conveyors (ARRAY OF BOOL shift register), PID-like
        loops, sequencers (CASE on an enum, TON dwell), alarm monitors (STRUCT, STRING,
        hysteresis), moving-average filters (ARRAY OF REAL, FOR) and totalizers (R_TRIG,
        CTU), with TON/TOF timers;
      units (~20 %) each holding 2-6 leaves, areas (~6 %) holding units, lines (~2 %)
        holding areas, every FB instantiated exactly once;
  * PROGRAMs calling the lines, reading two globals through VAR_EXTERNAL;
  * a CONFIGURATION with one RESOURCE, two cyclic TASKs and `PROGRAM instanceK WITH taskJ`,
    so that MATIEC's iec2c accepts the file as well as plcfi.

Every FB has the same interface (enable, demand, resetCmd -> ready, alarm, actual), so the
levels compose freely; values stay bounded (clamped REALs, counters taken MOD), so any
number of scans runs without a trap. Names avoid MATIEC's library names and keywords
(P, Q, PT, IN, STEP, MID, LIMIT, PID, RAMP, ...).

The output depends only on --fbs and --seed (Python's random.Random, no hash ordering):
the same arguments give the same bytes on every machine.
"""

import argparse
import random
import re
import sys

COMMON_IO = """  VAR_INPUT enable : BOOL; demand : REAL; resetCmd : BOOL; END_VAR
  VAR_OUTPUT ready : BOOL; alarm : BOOL; actual : REAL; END_VAR
"""

LEAF_KINDS = ["valve", "motor", "conveyor", "pidloop", "sequencer", "alarmmon", "filter", "totalizer"]
LEAF_WEIGHTS = [18, 16, 10, 14, 14, 10, 10, 8]
TYPE_PREFIX = {"valve": "ValveCtl", "motor": "MotorDrv", "conveyor": "ConvZone", "pidloop": "LoopCtl",
               "sequencer": "SeqBatch", "alarmmon": "AlarmMon", "filter": "FilterAvg",
               "totalizer": "FlowTotal", "unit": "ProcUnit", "area": "PlantArea", "line": "ProdLine"}
INST_PREFIX = {"valve": "vlv", "motor": "mtr", "conveyor": "cnv", "pidloop": "loop", "sequencer": "seq",
               "alarmmon": "almMon", "filter": "filt", "totalizer": "totz", "unit": "unit", "area": "area",
               "line": "line"}
STATE_NAMES = ["IDLE", "CHECK", "FILL", "HEAT", "MIX", "HOLD", "DRAIN", "RINSE", "COOL", "DONE"]
SEQ_PER_ENUM = 4
SHORT_IF = re.compile(r"^( *)IF ([^\n]*) THEN\n *([^\n]*;)\n *END_IF;$", re.M)


def real(x):
    """A REAL literal MATIEC accepts (always with a decimal point)."""
    s = "%.3f" % x
    s = s.rstrip("0")
    if s.endswith("."):
        s += "0"
    return s


def ms(rng, lo, hi):
    return "T#%dms" % (rng.randrange(lo, hi) * 10)


class Gen:
    def __init__(self, fbs, seed):
        self.rng = random.Random(seed)
        self.fbs = fbs
        self.out = []
        self.enums = []  # (name, prefix, states)

    def emit(self, text):
        self.out.append(text)

    # ------------------------------------------------------------------ plan
    def plan(self):
        n = self.fbs
        n_lines = max(1, round(n * 0.02))
        n_areas = max(n_lines, round(n * 0.06))
        n_units = max(n_areas, round(n * 0.20))
        n_leaves = n - n_lines - n_areas - n_units
        if n_leaves < n_units:
            raise SystemExit("gen_scale.py: --fbs %d is too small (at least 10)" % n)
        rng = self.rng
        leaves = []
        for i in range(n_leaves):
            kind = rng.choices(LEAF_KINDS, LEAF_WEIGHTS)[0] if i >= len(LEAF_KINDS) else LEAF_KINDS[i]
            leaves.append(kind)
        self.leaves = [(k, "%s_%04d" % (TYPE_PREFIX[k], i + 1)) for i, k in enumerate(leaves)]
        n_seq = sum(1 for k in leaves if k == "sequencer")
        for e in range((n_seq + SEQ_PER_ENUM - 1) // SEQ_PER_ENUM):
            count = rng.randrange(4, len(STATE_NAMES) + 1)
            states = ["IDLE"] + sorted(rng.sample(STATE_NAMES[1:-1], count - 2),
                                       key=STATE_NAMES.index) + ["DONE"]
            self.enums.append(("SeqState_%03d" % (e + 1), "Q%03d" % (e + 1), states))

        def split(children, parents):
            """Distribute children over parents, every parent at least one, in order."""
            groups = [[] for _ in range(parents)]
            order = list(range(len(children)))
            for i, c in enumerate(order):
                groups[i % parents].append(children[c])
            rng.shuffle(groups)
            return groups

        self.units = [("unit", "%s_%04d" % (TYPE_PREFIX["unit"], i + 1), g)
                      for i, g in enumerate(split(self.leaves, n_units))]
        self.areas = [("area", "%s_%03d" % (TYPE_PREFIX["area"], i + 1), g)
                      for i, g in enumerate(split([(k, t) for k, t, _ in self.units], n_areas))]
        self.lines = [("line", "%s_%02d" % (TYPE_PREFIX["line"], i + 1), g)
                      for i, g in enumerate(split([(k, t) for k, t, _ in self.areas], n_lines))]
        n_progs = max(1, (n_lines + 3) // 4)
        self.programs = [("PlantPrg_%02d" % (i + 1), g)
                         for i, g in enumerate(split([(k, t) for k, t, _ in self.lines], n_progs))]

    # ------------------------------------------------------------------ types
    def types(self):
        self.emit("""TYPE
  AlarmRecord : STRUCT
    active : BOOL;
    hits : DINT;
    peak : REAL;
    text : STRING;
  END_STRUCT;
  UnitStatus : STRUCT
    running : BOOL;
    faulted : BOOL;
    faultCount : DINT;
    lastActual : REAL;
  END_STRUCT;
  ValveDiag : STRUCT
    strokes : DINT;
    travelFaults : DINT;
    position : REAL;
  END_STRUCT;
""")
        for name, prefix, states in self.enums:
            self.emit("  %s : (%s);\n" % (name, ", ".join("%s_%s" % (prefix, s) for s in states)))
        self.emit("END_TYPE\n\n")

    def functions(self):
        self.emit("""FUNCTION ScaleLin : REAL
  VAR_INPUT
    raw : REAL;
    gainFactor : REAL;
    offsetVal : REAL;
  END_VAR
  ScaleLin := raw * gainFactor + offsetVal;
END_FUNCTION

FUNCTION ClampReal : REAL
  VAR_INPUT
    val : REAL;
    lowBound : REAL;
    highBound : REAL;
  END_VAR
  IF val < lowBound THEN
    ClampReal := lowBound;
  ELSIF val > highBound THEN
    ClampReal := highBound;
  ELSE
    ClampReal := val;
  END_IF;
END_FUNCTION

FUNCTION LagFirst : REAL
  VAR_INPUT
    prev : REAL;
    target : REAL;
    factor : REAL;
  END_VAR
  LagFirst := prev + (target - prev) * factor;
END_FUNCTION

""")

    # ------------------------------------------------------------------ leaves
    def fb_head(self, name, comment, local_vars):
        self.emit("(* %s *)\nFUNCTION_BLOCK %s\n%s  VAR\n" % (comment, name, COMMON_IO))
        for i in range(0, len(local_vars), 3):  # three declarations a line
            self.emit("    %s;\n" % "; ".join(local_vars[i:i + 3]))
        self.emit("  END_VAR\n")

    def fb_tail(self):
        self.emit("END_FUNCTION_BLOCK\n\n")

    def leaf(self, kind, name):
        getattr(self, "leaf_" + kind)(name)

    def leaf_valve(self, name):
        r = self.rng
        thr, up, down, travel = r.uniform(5, 40), r.uniform(4, 15), r.uniform(4, 15), r.uniform(85, 98)
        diag = r.random() < 0.5
        vs = ["openCmd : BOOL", "position : REAL", "travelTmr : TON", "cmdEdge : R_TRIG", "strokes : DINT"]
        if diag:
            vs.append("diag : ValveDiag")
        self.fb_head(name, "on/off valve with travel supervision", vs)
        self.emit(f"""  openCmd := enable AND demand > {real(thr)};
  cmdEdge(CLK := openCmd);
  IF cmdEdge.Q THEN
    strokes := (strokes + 1) MOD 100000;
  END_IF;
  IF openCmd THEN
    position := position + {real(up)};
  ELSE
    position := position - {real(down)};
  END_IF;
  position := ClampReal(position, 0.0, 100.0);
  travelTmr(IN := openCmd AND position < {real(travel)}, PT := {ms(r, 50, 400)});
  IF travelTmr.Q THEN
    alarm := TRUE;
  END_IF;
  IF resetCmd THEN
    alarm := FALSE;
  END_IF;
  ready := NOT alarm AND (position >= {real(travel)} OR NOT openCmd);
  actual := position;
""")
        if diag:
            self.emit("""  diag.strokes := strokes;
  diag.position := position;
  IF travelTmr.Q THEN
    diag.travelFaults := (diag.travelFaults + 1) MOD 100000;
  END_IF;
""")
        self.fb_tail()

    def leaf_motor(self, name):
        r = self.rng
        top, acc, dec = r.uniform(900, 3000), r.uniform(20, 120), r.uniform(30, 150)
        vs = ["runReq : BOOL", "speed : REAL", "startTmr : TON", "runOn : TOF", "runScans : DINT",
              "startCount : DINT", "startEdge : R_TRIG"]
        self.fb_head(name, "motor drive with start delay, run-on and speed ramp", vs)
        self.emit(f"""  runReq := enable AND NOT alarm;
  startTmr(IN := runReq, PT := {ms(r, 5, 60)});
  runOn(IN := startTmr.Q, PT := {ms(r, 5, 80)});
  startEdge(CLK := startTmr.Q);
  IF startEdge.Q THEN
    startCount := (startCount + 1) MOD 100000;
  END_IF;
  IF runOn.Q THEN
    speed := MIN(speed + {real(acc)}, demand * {real(top / 100.0)});
    runScans := (runScans + 1) MOD 1000000;
  ELSE
    speed := MAX(speed - {real(dec)}, 0.0);
  END_IF;
  speed := LIMIT(0.0, speed, {real(top)});
  IF speed > {real(top * 0.98)} AND demand < 1.0 THEN
    alarm := TRUE;
  END_IF;
  IF resetCmd THEN
    alarm := FALSE;
  END_IF;
  ready := runOn.Q;
  actual := speed * {real(100.0 / top)};
""")
        self.fb_tail()

    def leaf_conveyor(self, name):
        r = self.rng
        zones = r.randrange(4, 13)
        vs = [f"zones : ARRAY [0..{zones - 1}] OF BOOL", "zoneIdx : INT", "items : DINT",
              "jamTmr : TON", "feedEdge : R_TRIG", "occupied : INT"]
        self.fb_head(name, f"conveyor of {zones} zones: a shift register of parts", vs)
        self.emit(f"""  feedEdge(CLK := enable AND demand > {real(r.uniform(10, 60))});
  IF enable THEN
    IF zones[{zones - 1}] THEN
      items := (items + 1) MOD 1000000;
    END_IF;
    FOR zoneIdx := {zones - 1} TO 1 BY -1 DO
      zones[zoneIdx] := zones[zoneIdx - 1];
    END_FOR;
    zones[0] := feedEdge.Q;
  END_IF;
  occupied := 0;
  FOR zoneIdx := 0 TO {zones - 1} DO
    IF zones[zoneIdx] THEN
      occupied := occupied + 1;
    END_IF;
  END_FOR;
  jamTmr(IN := enable AND occupied >= {max(2, zones - 1)}, PT := {ms(r, 20, 200)});
  alarm := jamTmr.Q AND NOT resetCmd;
  ready := enable AND NOT alarm;
  actual := INT_TO_REAL(occupied) * {real(100.0 / zones)};
""")
        self.fb_tail()

    def leaf_pidloop(self, name):
        r = self.rng
        kp, ki, kd = r.uniform(0.2, 2.0), r.uniform(0.01, 0.5), r.uniform(0.0, 0.2)
        lag = r.uniform(0.02, 0.2)
        vs = ["err : REAL", "errPrev : REAL", "errSum : REAL", "outRaw : REAL", "outVal : REAL",
              "procVal : REAL", "settleTmr : TON", f"gainProp : REAL := {real(kp)}",
              f"gainInt : REAL := {real(ki)}", f"gainDer : REAL := {real(kd)}", "dtSec : REAL := 0.01"]
        self.fb_head(name, "PID-like loop on a first-order process", vs)
        self.emit(f"""  IF enable THEN
    err := demand - procVal;
    errSum := ClampReal(errSum + err * dtSec, -1000.0, 1000.0);
    outRaw := gainProp * err + gainInt * errSum + gainDer * (err - errPrev) / dtSec;
    errPrev := err;
    outVal := ClampReal(outRaw, 0.0, 100.0);
  ELSE
    errSum := 0.0;
    outVal := 0.0;
  END_IF;
  procVal := LagFirst(procVal, outVal, {real(lag)});
  settleTmr(IN := enable AND ABS(err) > {real(r.uniform(5, 30))}, PT := {ms(r, 30, 300)});
  alarm := settleTmr.Q AND NOT resetCmd;
  ready := enable AND ABS(err) < {real(r.uniform(1, 10))};
  actual := procVal;
""")
        self.fb_tail()

    def leaf_sequencer(self, name, enum):
        r = self.rng
        ename, prefix, states = enum
        vs = [f"state : {ename} := {prefix}_IDLE", "dwellTmr : TON", "advance : BOOL", "batches : DINT",
              "abortEdge : R_TRIG"]
        self.fb_head(name, f"batch sequencer over {ename}", vs)
        self.emit(f"""  dwellTmr(IN := enable, PT := {ms(r, 2, 30)});
  advance := dwellTmr.Q;
  abortEdge(CLK := resetCmd);
  CASE state OF
""")
        for i, s in enumerate(states):
            cur = "%s_%s" % (prefix, s)
            if s == "IDLE":
                self.emit(f"""    {cur}:
      alarm := FALSE;
      IF advance AND demand > {real(r.uniform(1, 30))} THEN
        state := {prefix}_{states[1]};
      END_IF;
""")
            elif s == "DONE":
                self.emit(f"""    {cur}:
      batches := (batches + 1) MOD 100000;
      state := {prefix}_IDLE;
""")
            else:
                nxt = "%s_%s" % (prefix, states[i + 1])
                if r.random() < 0.3:
                    self.emit(f"""    {cur}:
      IF advance AND demand > {real(r.uniform(50, 90))} THEN
        alarm := TRUE;
        state := {prefix}_IDLE;
      ELSIF advance THEN
        state := {nxt};
      END_IF;
""")
                else:
                    self.emit(f"""    {cur}:
      IF advance THEN
        state := {nxt};
      END_IF;
""")
        self.emit(f"""  END_CASE;
  IF advance THEN
    dwellTmr(IN := FALSE);
  END_IF;
  IF abortEdge.Q THEN
    state := {prefix}_IDLE;
  END_IF;
  ready := state = {prefix}_IDLE;
  actual := DINT_TO_REAL(batches MOD 100);
""")
        self.fb_tail()

    def leaf_alarmmon(self, name):
        r = self.rng
        hi = r.uniform(40, 90)
        hyst = r.uniform(2, 10)
        vs = ["rec : AlarmRecord", f"tagName : STRING := 'TAG{r.randrange(1000, 9999)}'", "onDelay : TON",
              "ackEdge : R_TRIG", "textLen : INT"]
        self.fb_head(name, "high alarm with hysteresis, delay and a text", vs)
        self.emit(f"""  onDelay(IN := enable AND demand > {real(hi)}, PT := {ms(r, 5, 50)});
  IF onDelay.Q AND NOT rec.active THEN
    rec.active := TRUE;
    rec.hits := (rec.hits + 1) MOD 100000;
    rec.text := CONCAT('HIGH ', tagName);
  ELSIF demand < {real(hi - hyst)} THEN
    rec.active := FALSE;
  END_IF;
  IF demand > rec.peak THEN
    rec.peak := demand;
  END_IF;
  ackEdge(CLK := resetCmd);
  IF ackEdge.Q THEN
    rec.peak := 0.0;
    rec.text := '';
  END_IF;
  textLen := LEN(rec.text);
  alarm := rec.active;
  ready := NOT rec.active AND textLen = 0;
  actual := rec.peak;
""")
        self.fb_tail()

    def leaf_filter(self, name):
        r = self.rng
        size = r.choice([4, 8, 8, 16])
        vs = [f"samples : ARRAY [0..{size - 1}] OF REAL", "head : INT", "fillIdx : INT", "total : REAL",
              "mean : REAL", "spread : REAL"]
        self.fb_head(name, f"moving average over {size} samples", vs)
        self.emit(f"""  IF enable THEN
    samples[head] := ScaleLin(demand, {real(r.uniform(0.5, 1.5))}, {real(r.uniform(-5, 5))});
    head := (head + 1) MOD {size};
  END_IF;
  total := 0.0;
  spread := 0.0;
  FOR fillIdx := 0 TO {size - 1} DO
    total := total + samples[fillIdx];
    spread := MAX(spread, ABS(samples[fillIdx] - mean));
  END_FOR;
  mean := total / {real(size)};
  alarm := spread > {real(r.uniform(20, 80))} AND NOT resetCmd;
  ready := enable;
  actual := mean;
""")
        self.fb_tail()

    def leaf_totalizer(self, name):
        r = self.rng
        vs = ["pulseEdge : R_TRIG", "pulses : CTU", "volume : REAL", "batchDone : BOOL", "pulseOn : BOOL"]
        self.fb_head(name, "flow totalizer: pulses counted by CTU", vs)
        self.emit(f"""  pulseOn := enable AND demand > {real(r.uniform(1, 20))} AND NOT pulseOn;
  pulseEdge(CLK := pulseOn);
  pulses(CU := pulseEdge.Q, R := resetCmd OR pulses.Q, PV := {r.randrange(10, 500)});
  IF pulseEdge.Q THEN
    volume := volume + {real(r.uniform(0.1, 2.5))};
  END_IF;
  IF volume > 10000.0 THEN
    volume := 0.0;
  END_IF;
  batchDone := pulses.Q;
  alarm := FALSE;
  ready := NOT batchDone;
  actual := INT_TO_REAL(pulses.CV);
""")
        self.fb_tail()

    # ------------------------------------------------------------------ composites
    def composite(self, kind, name, children):
        r = self.rng
        insts = []
        counts = {}
        for ck, ct in children:
            counts[ck] = counts.get(ck, 0) + 1
            insts.append(("%s%d" % (INST_PREFIX[ck], counts[ck]), ct))
        trend = r.randrange(3, 8)
        vs = ["%s : %s" % (i, t) for i, t in insts]
        vs += ["startDelay : TON", "allReady : BOOL", "anyAlarm : BOOL", "status : UnitStatus",
               f"trend : ARRAY [0..{trend - 1}] OF REAL", "trendIdx : INT", "sumActual : REAL"]
        what = {"unit": "process unit", "area": "plant area", "line": "production line"}[kind]
        self.fb_head(name, f"{what} of {len(insts)} parts", vs)
        self.emit(f"  startDelay(IN := enable, PT := {ms(r, 1, 10)});\n")
        prev = None
        for inst, _ in insts:
            en = "startDelay.Q" if prev is None else f"startDelay.Q AND NOT {prev}.alarm"
            dem = f"demand * {real(r.uniform(0.6, 1.1))}" if prev is None or r.random() < 0.5 \
                else f"ClampReal({prev}.actual + {real(r.uniform(-5, 15))}, 0.0, 100.0)"
            self.emit(f"  {inst}(enable := {en}, demand := {dem}, resetCmd := resetCmd);\n")
            prev = inst
        self.emit("  allReady := %s;\n" % " AND ".join("%s.ready" % i for i, _ in insts))
        self.emit("  anyAlarm := %s;\n" % " OR ".join("%s.alarm" % i for i, _ in insts))
        self.emit("  sumActual := %s;\n" % " + ".join("%s.actual" % i for i, _ in insts))
        self.emit(f"""  IF anyAlarm AND NOT status.faulted THEN
    status.faultCount := (status.faultCount + 1) MOD 100000;
  END_IF;
  status.faulted := anyAlarm;
  status.running := enable AND allReady;
  status.lastActual := sumActual / {real(len(insts))};
  trend[trendIdx] := status.lastActual;
  trendIdx := (trendIdx + 1) MOD {trend};
  alarm := anyAlarm;
  ready := allReady;
  actual := status.lastActual;
""")
        self.fb_tail()

    def program(self, name, children):
        r = self.rng
        insts = [("%s%d" % (INST_PREFIX[k], i + 1), t) for i, (k, t) in enumerate(children)]
        self.emit(f"PROGRAM {name}\n  VAR_EXTERNAL\n    plantEnable : BOOL;\n    plantReset : BOOL;\n  END_VAR\n  VAR\n")
        for i, t in insts:
            self.emit(f"    {i} : {t};\n")
        self.emit("    scanCount : DINT;\n    profile : REAL;\n    lineAlarms : INT;\n  END_VAR\n")
        self.emit(f"""  scanCount := (scanCount + 1) MOD 1000000;
  profile := DINT_TO_REAL(scanCount MOD {r.randrange(50, 400)}) * {real(r.uniform(0.2, 0.6))};
  lineAlarms := 0;
""")
        for i, _ in insts:
            self.emit(f"""  {i}(enable := plantEnable, demand := profile, resetCmd := plantReset);
  IF {i}.alarm THEN
    lineAlarms := lineAlarms + 1;
  END_IF;
""")
        self.emit("END_PROGRAM\n\n")

    def configuration(self):
        self.emit("""CONFIGURATION PlantCfg
  VAR_GLOBAL
    plantEnable : BOOL := TRUE;
    plantReset : BOOL := FALSE;
  END_VAR
  RESOURCE PlantRes ON PLC
    TASK task0(INTERVAL := T#10ms, PRIORITY := 1);
    TASK task1(INTERVAL := T#20ms, PRIORITY := 2);
""")
        for k, (name, _) in enumerate(self.programs):
            self.emit(f"    PROGRAM instance{k} WITH task{k % 2} : {name};\n")
        self.emit("  END_RESOURCE\nEND_CONFIGURATION\n")

    def generate(self):
        self.plan()
        self.emit("(* Generated by tests/bench/scale/gen_scale.py --fbs %d --seed %d: a plant-like program\n"
                  "   for plcfi's scale benchmark (issue 31). Do not edit; regenerate. *)\n\n"
                  % (self.fbs, self.seed_value))
        self.types()
        self.functions()
        seq = 0
        for kind, name in self.leaves:
            if kind == "sequencer":
                self.leaf_sequencer(name, self.enums[seq // SEQ_PER_ENUM])
                seq += 1
            else:
                self.leaf(kind, name)
        for group in (self.units, self.areas, self.lines):
            for kind, name, children in group:
                self.composite(kind, name, children)
        for name, children in self.programs:
            self.program(name, children)
        self.configuration()
        # A one-statement IF without ELSE on one line, as such code is often written.
        return SHORT_IF.sub(r"\1IF \2 THEN \3 END_IF;", "".join(self.out))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fbs", type=int, default=2000, help="number of FUNCTION_BLOCKs (default 2000)")
    ap.add_argument("--seed", type=int, default=31, help="random seed (default 31)")
    ap.add_argument("-o", "--output", help="output file (default stdout)")
    args = ap.parse_args()
    if args.fbs < 10:
        ap.error("--fbs must be at least 10")
    g = Gen(args.fbs, args.seed)
    g.seed_value = args.seed
    text = g.generate()
    if args.output:
        with open(args.output, "w", encoding="ascii", newline="\n") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    n_fbs = len(g.leaves) + len(g.units) + len(g.areas) + len(g.lines)
    print("gen_scale.py: %d lines, %d FUNCTION_BLOCKs (%d leaves, %d units, %d areas, %d lines), "
          "%d PROGRAMs, %d enum types" % (text.count("\n"), n_fbs, len(g.leaves), len(g.units), len(g.areas),
                                           len(g.lines), len(g.programs), len(g.enums)), file=sys.stderr)


if __name__ == "__main__":
    main()
