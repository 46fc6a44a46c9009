// native_kernels.hpp: hand translations of the ST benchmark kernels in this directory to
// plain C++, used as the "native" baseline next to the VM. Each kernel has a state struct
// holding the PROGRAM's variables (same initial values, persisting across scans) and a
// function `<name>_scan(State&)` doing exactly one scan of the same computation with the
// same types: BOOL bool, INT int16_t, DINT int32_t, REAL float, LREAL double, DWORD
// uint32_t, TIME int64_t nanoseconds. DINT arithmetic that can overflow is done in
// uint32_t (wraps modulo 2^32 like the VM); integer / and % truncate toward zero like ST;
// REAL_TO_DINT rounds to nearest with ties to even (std::lrint, default rounding mode).
//
// Timers read `now_ns`, a clock member of each state that the benchmark sets: the first
// scan runs at now_ns = 0 and the harness adds 10 ms (10'000'000 ns) after every scan.
//
// Build with strict IEEE float semantics (no -ffast-math, and -ffp-contract=off when
// FMA instructions are enabled) or real_math's result will differ from the VM's.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace plcfi::bench {

// ---------------------------------------------------------------- standard FBs

// TON: Q becomes TRUE on the first call where now - start >= PT (start = the call where IN
// rose); ET = min(elapsed, PT); IN FALSE resets Q and ET.
struct NativeTon {
  bool in = false, q = false;
  int64_t pt = 0, et = 0, start = 0;
  void operator()(bool in_, int64_t pt_, int64_t now) {
    pt = pt_;
    if (!in_) {
      q = false;
      et = 0;
    } else {
      if (!in) start = now;
      int64_t e = now - start;
      if (e >= pt) {
        q = true;
        et = pt;
      } else {
        q = false;
        et = e;
      }
    }
    in = in_;
  }
};

// R_TRIG: Q := CLK AND NOT M; M := CLK.
struct NativeRTrig {
  bool m = false, q = false;
  void operator()(bool clk) {
    q = clk && !m;
    m = clk;
  }
};

// CTU (INT counter): IF R THEN CV := 0 ELSIF rising(CU) AND CV < 32767 THEN CV := CV + 1;
// Q := CV >= PV. The CU edge memory is updated on every call.
struct NativeCtu {
  bool prev_cu = false, q = false;
  int16_t cv = 0, pv = 0;
  void operator()(bool cu, bool r, int16_t pv_) {
    pv = pv_;
    bool edge = cu && !prev_cu;
    prev_cu = cu;
    if (r) {
      cv = 0;
    } else if (edge && cv < 32767) {
      cv = static_cast<int16_t>(cv + 1);
    }
    q = cv >= pv;
  }
};

inline int32_t wrap_add(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) + static_cast<uint32_t>(b));
}
inline int32_t wrap_mul(int32_t a, int32_t b) {
  return static_cast<int32_t>(static_cast<uint32_t>(a) * static_cast<uint32_t>(b));
}
inline uint32_t rol32(uint32_t w, unsigned n) { return (w << n) | (w >> (32 - n)); }

constexpr int64_t kMs = 1'000'000;  // T#1ms in ns

// ---------------------------------------------------------------- state_machine
// state_machine.st: BenchCylinder -> NativeCylinder (two NativeTon: motion, watchdog);
// PROGRAM vars -> StateMachineState; CASE seq -> switch; TIME_TO_DINT(ET) -> et / 1 ms.

struct NativeCylinder {
  // inputs
  bool extend = false;
  int64_t travel = 50 * kMs, max_travel = 200 * kMs;
  // outputs
  bool extended = false, retracted = true, fault = false;
  int32_t moves = 0;
  // locals
  NativeTon motion, watchdog;
  bool target = false;

  void operator()(bool extend_, int64_t travel_, int64_t max_travel_, int64_t now) {
    extend = extend_;
    travel = travel_;
    max_travel = max_travel_;
    if (extend != target) {
      target = extend;
      moves = wrap_add(moves, 1);
      extended = false;
      retracted = false;
      motion(false, travel, now);
    }
    motion(true, travel, now);
    if (motion.q) {
      extended = target;
      retracted = !target;
    }
    watchdog(!(extended || retracted), max_travel, now);
    fault = watchdog.q;
  }
};

struct StateMachineState {
  int64_t now_ns = 0;
  int16_t seq = 0;
  NativeCylinder cylA, cylB;
  bool cmdA = false, cmdB = false;
  NativeTon dwell, pause;
  int32_t cycles = 0;
  int32_t scans = 0;
  int32_t result = 0;
};

inline void state_machine_scan(StateMachineState& s) {
  const int64_t now = s.now_ns;
  s.scans = wrap_add(s.scans, 1);
  switch (s.seq) {
    case 0:
      s.cmdA = false;
      s.cmdB = false;
      if (s.cylA.retracted && s.cylB.retracted) s.seq = 1;
      break;
    case 1:
      s.cmdA = true;
      if (s.cylA.extended) s.seq = 2;
      break;
    case 2:
      s.cmdB = true;
      if (s.cylB.extended) s.seq = 3;
      break;
    case 3:
      s.dwell(true, 30 * kMs, now);
      if (s.dwell.q) {
        s.dwell(false, 30 * kMs, now);
        s.seq = 4;
      }
      break;
    case 4:
      s.cmdB = false;
      if (s.cylB.retracted) s.seq = 5;
      break;
    case 5:
      s.cmdA = false;
      if (s.cylA.retracted) s.seq = 6;
      break;
    case 6:
      s.cycles = wrap_add(s.cycles, 1);
      s.seq = 7;
      break;
    case 7:
      s.pause(true, 20 * kMs, now);
      if (s.pause.q) {
        s.pause(false, 20 * kMs, now);
        s.seq = 1;
      }
      break;
    case 99:
      s.cmdA = false;
      s.cmdB = false;
      break;
    default:
      break;
  }
  s.cylA(s.cmdA, 40 * kMs, 200 * kMs, now);
  s.cylB(s.cmdB, 70 * kMs, 200 * kMs, now);
  if (s.cylA.fault || s.cylB.fault) s.seq = 99;
  // (result * 31 + seq * 7 + cycles + TIME_TO_DINT(dwell.ET) + moves A + moves B) MOD 1000003
  int32_t t = wrap_mul(s.result, 31);
  t = wrap_add(t, wrap_mul(static_cast<int32_t>(s.seq), 7));
  t = wrap_add(t, s.cycles);
  t = wrap_add(t, static_cast<int32_t>(s.dwell.et / kMs));
  t = wrap_add(t, s.cylA.moves);
  t = wrap_add(t, s.cylB.moves);
  s.result = t % 1000003;
}

// ---------------------------------------------------------------- int_loop
// int_loop.st: DINT -> int32_t with wrap_add/wrap_mul where the ST wraps; DWORD ->
// uint32_t; ROL/SHL/SHR on DWORD -> rol32/<</>> on uint32_t; DINT_TO_DWORD and
// DWORD_TO_DINT reinterpret the bits.

struct IntLoopState {
  int64_t now_ns = 0;
  int32_t i = 0;
  int32_t acc = 17;
  uint32_t w = 0x12345678u;
  int32_t k = 0;
  int32_t scans = 0;
  int32_t result = 0;
};

inline void int_loop_scan(IntLoopState& s) {
  s.scans = wrap_add(s.scans, 1);
  for (s.i = 1; s.i <= 1000; ++s.i) {
    s.acc = wrap_add(wrap_add(wrap_mul(s.acc, 31), s.i), s.scans);
    s.k = s.acc % 97;
    if (s.k < 0) s.k = -s.k;
    s.w = (rol32(s.w, 3) ^ static_cast<uint32_t>(s.acc)) ^ (s.w << 1);
    if (s.i % 7 == 0) s.acc = s.acc / 3;
    s.result = wrap_add(wrap_add(s.result, s.k), static_cast<int32_t>(s.w >> 24));
  }
  // ST leaves the FOR variable one step past the end; nothing reads it afterwards.
}

// ---------------------------------------------------------------- real_math
// real_math.st: REAL -> float, LREAL -> double; same evaluation order (left-associative);
// SQRT on REAL -> std::sqrt(float); SIN on LREAL -> std::sin(double); REAL -> LREAL
// widening -> static_cast<double>; LIMIT(MN, IN, MX) -> min(max(IN, MN), MX);
// REAL_TO_DINT -> std::lrint (ties to even).

struct RealMathState {
  int64_t now_ns = 0;
  int16_t i = 0;
  float sp = 50.0f, pv = 0.0f, err = 0.0f, integ = 0.0f, deriv = 0.0f, prevErr = 0.0f, u = 0.0f;
  float kp = 0.8f, ki = 0.05f, kd = 0.1f, dts = 0.01f, lim = 100.0f, ilim = 100.0f;
  float plantGain = 0.05f, leak = 0.1f, ten = 10.0f;
  double phase = 0.0, dphase = 0.001, half = 0.5, acc = 0.0;
  int32_t rsum = 0;
  double result = 0.0;
};

inline void real_math_scan(RealMathState& s) {
  for (s.i = 1; s.i <= 200; ++s.i) {
    s.err = s.sp - s.pv;
    s.integ = s.integ + s.err * s.dts;
    if (s.integ > s.ilim) {
      s.integ = s.ilim;
    } else if (s.integ < -s.ilim) {
      s.integ = -s.ilim;
    }
    s.deriv = (s.err - s.prevErr) / s.dts;
    s.prevErr = s.err;
    s.u = s.kp * s.err + s.ki * s.integ + s.kd * s.deriv * s.dts;
    {
      float mn = -s.lim, mx = s.lim, in = s.u;
      float lo = in < mn ? mn : in;
      s.u = lo > mx ? mx : lo;
    }
    s.pv = s.pv + (s.u - s.pv * s.leak) * s.plantGain;
    s.phase = s.phase + s.dphase;
    s.acc = s.acc + static_cast<double>(std::sqrt(std::fabs(s.pv))) + std::sin(s.phase) * s.half;
    s.rsum = wrap_add(s.rsum, static_cast<int32_t>(std::lrint(s.u * s.ten)));
  }
  s.sp = -s.sp;
  s.result = s.acc + static_cast<double>(s.rsum);
}

// ---------------------------------------------------------------- array_struct
// array_struct.st: BenchItem -> NativeBenchItem {int32_t, int16_t, float};
// ARRAY[1..256] -> std::array index i-1; struct assignment -> struct copy;
// DINT_TO_REAL -> static_cast<float>; REAL_TO_DINT -> std::lrint.

struct NativeBenchItem {
  int32_t value = 0;
  int16_t weight = 1;
  float avg = 0.0f;
};

struct ArrayStructState {
  int64_t now_ns = 0;
  std::array<NativeBenchItem, 256> items{};
  int16_t i = 0;
  NativeBenchItem tmp{};
  int32_t seed = 12345;
  float alpha = 0.25f;
  int32_t sum = 0, ma = 0;
  int32_t result = 0;
};

inline void array_struct_scan(ArrayStructState& s) {
  auto& it = s.items;
  for (int i = 1; i <= 256; ++i) {
    NativeBenchItem& e = it[i - 1];
    s.seed = wrap_add(wrap_mul(s.seed, 1103515245), 12345);
    e.value = (s.seed / 65536) % 1000;
    e.weight = static_cast<int16_t>(e.weight + 1);
    if (e.weight > 50) e.weight = 1;
    e.avg = e.avg + (static_cast<float>(e.value) - e.avg) * s.alpha;
  }
  for (int i = 1; i <= 255; ++i) {
    if (it[i - 1].value > it[i].value) {
      s.tmp = it[i - 1];
      it[i - 1] = it[i];
      it[i] = s.tmp;
    }
  }
  s.sum = 0;
  for (int i = 2; i <= 255; ++i) {
    s.ma = (it[i - 2].value + it[i - 1].value + it[i].value) / 3;
    s.sum = wrap_add(s.sum, wrap_add(wrap_mul(s.ma, it[i - 1].weight),
                                     static_cast<int32_t>(std::lrint(it[i - 1].avg))));
  }
  s.i = 256;
  s.result = wrap_add(s.result, s.sum) % 1000000007;
}

// ---------------------------------------------------------------- fb_calls
// fb_calls.st: BenchAccum -> NativeBenchAccum; ARRAY[1..100] OF BenchAccum ->
// std::array index i-1; R_TRIG -> NativeRTrig; CTU -> NativeCtu; `yout => q` copies the
// output after the call.

struct NativeBenchAccum {
  int32_t xin = 0, gain = 1;
  bool enable = false;
  int32_t yout = 0;
  int16_t count = 0;
  int32_t last = 0;
  void operator()(int32_t xin_, int32_t gain_, bool enable_) {
    xin = xin_;
    gain = gain_;
    enable = enable_;
    if (enable) {
      yout = wrap_add(yout, wrap_mul(wrap_add(xin, -last), gain));
      last = xin;
      count = static_cast<int16_t>(count + 1);
    } else {
      yout = yout / 2;
    }
  }
};

struct FbCallsState {
  int64_t now_ns = 0;
  std::array<NativeBenchAccum, 100> accs{};
  NativeRTrig trig;
  NativeCtu ctr;
  int16_t i = 0;
  int32_t tick = 0;
  int32_t q = 0;
  int32_t result = 0;
};

inline void fb_calls_scan(FbCallsState& s) {
  s.tick = wrap_add(s.tick, 1);
  s.trig(s.tick % 3 == 0);
  s.ctr(s.trig.q, s.ctr.cv >= 20, 10);
  for (int i = 1; i <= 100; ++i) {
    NativeBenchAccum& a = s.accs[i - 1];
    a(wrap_add(wrap_mul(s.tick, i), s.ctr.cv), (i % 5) + 1, ((s.tick + i) % 4) != 0);
    s.q = a.yout;
    s.result = wrap_add(wrap_add(s.result, s.q % 1000), a.count);
  }
  s.i = 101;
  if (s.ctr.q) s.result = wrap_add(s.result, 1);
}

}  // namespace plcfi::bench
