// matiec_kernels.hpp: hand translations to C++ of the MATIEC baseline kernels in this
// directory (statemachine, intloop, realmath, arrays, fbcalls) and of plcfi's own
// nested_fbs and crc16, used by bench_matiec.cpp as the in-run stand-in for MATIEC.
//
// Each is roughly what gcc gets from MATIEC's generated C without its per-variable
// overhead: the program and every FB instance a plain struct of its variables (same
// initial values, kept across scans), one inline function per POU body, the standard
// FBs (TON, R_TRIG, CTU) inline functions written the way MATIEC's standard library
// implements them, no force flags, no EN/ENO, no bounds checks.
//
// Types: BOOL bool, BYTE uint8_t, INT int16_t, WORD uint16_t, DINT int32_t, REAL float,
// LREAL double, TIME int64_t nanoseconds. Integer / and MOD truncate toward zero (C's
// semantics, as in MATIEC); no DINT computation in these kernels overflows.
// REAL_TO_DINT / LREAL_TO_DINT round exact halves to even (std::nearbyint in the default
// rounding mode), computed in 64 bits and then narrowed. REAL SQRT and SIN are computed
// in double and rounded once to float, as MATIEC's C does.
//
// The clock: every state has `now_ns`, the IEC time of the scan it runs next. Scan k
// (0-based) runs at k x 10 ms; the caller adds 10'000'000 after every scan.
//
// Build with strict IEEE float semantics (no -ffast-math; -ffp-contract=off).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace plcfi::bench::matiec {

constexpr int64_t kMs = 1'000'000;  // T#1ms in ns

// ---------------------------------------------------------------- standard FBs

// TON as MATIEC's standard library writes it: a rising IN starts the timer (Q stays
// FALSE in that call), then Q rises on the first call where START + PT <= now; IN FALSE
// resets Q, ET and the state.
struct Ton {
  bool in = false, q = false, prev_in = false;
  int8_t state = 0;
  int64_t pt = 0, et = 0, start = 0;
};
inline void ton(Ton& t, bool in, int64_t pt, int64_t now) {
  t.in = in;
  t.pt = pt;
  if (t.state == 0 && !t.prev_in && in) {
    t.state = 1;
    t.q = false;
    t.start = now;
  } else if (!in) {
    t.et = 0;
    t.q = false;
    t.state = 0;
  } else if (t.state == 1) {
    if (t.start + t.pt <= now) {
      t.state = 2;
      t.q = true;
      t.et = t.pt;
    } else {
      t.et = now - t.start;
    }
  }
  t.prev_in = in;
}

// R_TRIG: Q := CLK AND NOT M; M := CLK.
struct RTrig {
  bool clk = false, q = false, m = false;
};
inline void r_trig(RTrig& r, bool clk) {
  r.clk = clk;
  r.q = clk && !r.m;
  r.m = clk;
}

// CTU on INT: an R_TRIG on CU; R resets CV; a CU edge counts while CV < 32767; Q := CV >= PV.
struct Ctu {
  bool cu = false, r = false, q = false;
  int16_t pv = 0, cv = 0;
  RTrig cu_t;
};
inline void ctu(Ctu& c, bool cu, bool r, int16_t pv) {
  c.cu = cu;
  c.r = r;
  c.pv = pv;
  r_trig(c.cu_t, cu);
  if (r) {
    c.cv = 0;
  } else if (c.cu_t.q && c.cv < 32767) {
    c.cv = static_cast<int16_t>(c.cv + 1);
  }
  c.q = c.cv >= c.pv;
}

// REAL/LREAL -> DINT: nearest, exact halves to even, in 64 bits, then narrowed.
inline int32_t to_dint(double x) { return static_cast<int32_t>(static_cast<int64_t>(std::nearbyint(x))); }

// ---------------------------------------------------------------- statemachine.st

struct StateMachine {
  int64_t now_ns = 0;
  int16_t state = 0;
  int32_t scan = 0;
  bool start_btn = false, part_sensor = false, press_down_sw = false, press_up_sw = true;
  int32_t sim_feed = 0, sim_press = 0;
  bool feeder_out = false, clamp_out = false, press_out = false, eject_out = false;
  Ton t_feed, t_clamp, t_dwell, t_eject;
  RTrig start_edge, down_edge;
  Ctu parts;
  int32_t cycles = 0, batches = 0, outs = 0, checksum = 0;
};

inline void statemachine_scan(StateMachine& s) {
  const int64_t now = s.now_ns;
  s.start_btn = s.scan % 37 < 18;
  if (s.feeder_out) {
    s.sim_feed = s.sim_feed + 1;
  } else {
    s.sim_feed = 0;
  }
  s.part_sensor = s.sim_feed >= 3 + s.cycles % 4;
  if (s.press_out) {
    s.sim_press = s.sim_press + 2 + s.cycles % 3;
    if (s.sim_press > 20) s.sim_press = 20;
  } else {
    s.sim_press = s.sim_press - 2;
    if (s.sim_press < 0) s.sim_press = 0;
  }
  s.press_down_sw = s.sim_press >= 20;
  s.press_up_sw = s.sim_press <= 0;

  r_trig(s.start_edge, s.start_btn);
  r_trig(s.down_edge, s.press_down_sw);
  ton(s.t_feed, s.state == 1 && s.part_sensor, 30 * kMs, now);
  ton(s.t_clamp, s.state == 2, 20 * kMs, now);
  ton(s.t_dwell, s.state == 4, 50 * kMs, now);
  ton(s.t_eject, s.state == 6, 20 * kMs, now);
  ctu(s.parts, s.state == 6 && s.t_eject.q, s.state == 7, 5);

  switch (s.state) {
    case 0:
      s.feeder_out = s.clamp_out = s.press_out = s.eject_out = false;
      if (s.start_edge.q) s.state = 1;
      break;
    case 1:
      s.feeder_out = true;
      if (s.t_feed.q) {
        s.feeder_out = false;
        s.state = 2;
      }
      break;
    case 2:
      s.clamp_out = true;
      if (s.t_clamp.q) s.state = 3;
      break;
    case 3:
      s.press_out = true;
      if (s.down_edge.q) s.state = 4;
      break;
    case 4:
      if (s.t_dwell.q) {
        s.press_out = false;
        s.state = 5;
      }
      break;
    case 5:
      s.press_out = false;
      if (s.press_up_sw) {
        s.clamp_out = false;
        s.state = 6;
      }
      break;
    case 6:
      s.eject_out = true;
      if (s.t_eject.q) {
        s.eject_out = false;
        s.cycles = s.cycles + 1;
        s.state = s.parts.q ? 7 : 1;
      }
      break;
    case 7:
      s.batches = s.batches + 1;
      s.state = 0;
      break;
    default:
      s.state = 0;
      break;
  }

  s.outs = 0;
  if (s.feeder_out) s.outs += 1;
  if (s.clamp_out) s.outs += 2;
  if (s.press_out) s.outs += 4;
  if (s.eject_out) s.outs += 8;
  s.checksum = (s.checksum * 31 + int32_t{s.state} * 17 + s.outs + int32_t{s.parts.cv} * 5 + s.sim_press +
                s.cycles % 1000) %
               1000003;
  s.scan = s.scan + 1;
}

// ---------------------------------------------------------------- intloop.st

struct IntLoop {
  int64_t now_ns = 0;
  int32_t i = 0, acc = 1, cnt = 0, mx = 0, mix = 0, scan = 0, checksum = 0;
};

inline void intloop_scan(IntLoop& s) {
  s.acc = (s.acc + s.scan) % 1000003;
  s.mx = 0;
  for (s.i = 1; s.i <= 1000; ++s.i) {
    const int32_t i = s.i;
    s.acc = (s.acc * 17 + i * 3) % 1000003;
    if (s.acc % 3 == 0) {
      s.cnt = s.cnt + 1;
    } else if (s.acc > 500000) {
      s.acc = s.acc - i;
    } else {
      s.acc = s.acc + i % 7;
    }
    if (s.acc > s.mx) s.mx = s.acc;
    s.mix = (s.mix + (s.acc * i) % 65521) % 1000000;
  }
  s.cnt = s.cnt % 65536;
  s.checksum = (s.checksum * 3 + s.acc + s.cnt + s.mx + s.mix) % 100000007;
  s.scan = s.scan + 1;
}

// ---------------------------------------------------------------- realmath.st

struct RealMath {
  int64_t now_ns = 0;
  int16_t i = 0;
  double x = 0, y = 0, s = 0, energy = 0, filt = 0, phase = 0;
  float rx = 0, ry = 0, rfilt = 0;
  int32_t scan = 0, checksum = 0;
};

inline void realmath_scan(RealMath& s) {
  s.phase = s.phase + 0.0123;
  if (s.phase > 6.283185307179586) s.phase = s.phase - 6.283185307179586;
  s.energy = 0.0;
  for (s.i = 1; s.i <= 200; ++s.i) {
    s.x = static_cast<double>(s.i) * 0.05 + s.phase;
    s.y = std::sqrt(s.x * s.x + 1.0);
    s.s = std::sin(s.x);
    s.energy = s.energy + s.y * s.s;
    s.filt = s.filt + 0.05 * (s.y * s.s - s.filt);
    s.rx = static_cast<float>(s.i) * 0.0078125f + static_cast<float>(s.phase);
    s.ry = static_cast<float>(std::sqrt(static_cast<double>(s.rx))) +
           static_cast<float>(std::sin(static_cast<double>(s.rx)));
    s.rfilt = s.rfilt + 0.125f * (s.ry - s.rfilt);
  }
  // rfilt * 10000.0 is a double product in MATIEC's C, but REAL_TO_DINT takes a REAL, so
  // it is rounded to float first: the float product (the double one changes the checksum).
  s.checksum = (s.checksum * 7 + to_dint(s.energy * 100.0) + 1000000 + to_dint(s.filt * 10000.0) + 1000000 +
                to_dint(s.rfilt * 10000.0f)) %
               100000007;
  s.scan = s.scan + 1;
}

// ---------------------------------------------------------------- arrays.st

struct Item {
  int32_t id = 0, value = 0;
  int16_t weight = 0;
};

struct Arrays {
  int64_t now_ns = 0;
  std::array<int32_t, 256> ring{};    // [1..256] at index - 1
  int16_t head = 1;
  std::array<int32_t, 32> sortbuf{};  // [1..32]
  std::array<Item, 16> items{};       // [1..16]
  int32_t seed = 12345;
  int16_t i = 0;
  int32_t tmp = 0, sum = 0, wsum = 0, isum = 0, swaps = 0, scan = 0, checksum = 0;
};

inline void arrays_scan(Arrays& s) {
  s.seed = (s.seed * 75 + 74) % 65537;
  s.ring[s.head - 1] = s.seed;
  s.head = static_cast<int16_t>(s.head % 256 + 1);
  s.sum = 0;
  for (int i = 1; i <= 256; ++i) s.sum = s.sum + s.ring[i - 1];
  s.sortbuf[s.scan % 32] = s.seed;
  for (int i = 1; i <= 31; ++i) {
    if (s.sortbuf[i - 1] > s.sortbuf[i]) {
      s.tmp = s.sortbuf[i - 1];
      s.sortbuf[i - 1] = s.sortbuf[i];
      s.sortbuf[i] = s.tmp;
      s.swaps = s.swaps + 1;
    }
  }
  s.wsum = 0;
  for (int i = 1; i <= 32; ++i) s.wsum = s.wsum + s.sortbuf[i - 1] * i;
  s.isum = 0;
  for (int i = 1; i <= 16; ++i) {
    Item& it = s.items[i - 1];
    it.id = i;
    it.value = (it.value + s.ring[i * 16 - 1] + it.id) % 100000;
    it.weight = static_cast<int16_t>((it.weight + 3) % 97);
    s.isum = s.isum + it.value * int32_t{it.weight};
  }
  s.i = 16;  // what MATIEC's loop leaves; ST's would be 17 (nothing reads it)
  s.swaps = s.swaps % 1000000;
  s.checksum = (s.checksum * 7 + s.sum + s.wsum + s.isum + s.swaps) % 100000007;
  s.scan = s.scan + 1;
}

// ---------------------------------------------------------------- fbcalls.st

struct PiCtrl {
  float sp = 0, pv = 0, kp = 0.5f, ki = 0.125f, out_min = 0.0f, out_max = 100.0f;
  float out = 0;
  bool sat = false;
  float integ = 0, err = 0, raw = 0;
};

inline void pi_ctrl(PiCtrl& c, float sp, float pv) {
  c.sp = sp;
  c.pv = pv;
  c.err = c.sp - c.pv;
  c.integ = c.integ + c.ki * c.err;
  if (c.integ > c.out_max) {
    c.integ = c.out_max;
  } else if (c.integ < c.out_min) {
    c.integ = c.out_min;
  }
  c.raw = c.kp * c.err + c.integ;
  if (c.raw > c.out_max) {
    c.out = c.out_max;
    c.sat = true;
  } else if (c.raw < c.out_min) {
    c.out = c.out_min;
    c.sat = true;
  } else {
    c.out = c.raw;
    c.sat = false;
  }
}

inline int32_t scale_clamp(int32_t x, int32_t gain, int32_t lo, int32_t hi) {
  int32_t t = (x * gain) / 16;
  if (t < lo) {
    t = lo;
  } else if (t > hi) {
    t = hi;
  }
  return t;
}

struct FbCalls {
  int64_t now_ns = 0;
  std::array<PiCtrl, 50> c{};  // c1..c50
  std::array<float, 50> u{}, pv{};
  std::array<bool, 50> sat{};
  int16_t i = 0;
  int32_t k = 0;
  float sp = 0.0f, outsum = 0.0f;
  int32_t satcount = 0, facc = 0, scan = 0, checksum = 0;
};

inline void fbcalls_scan(FbCalls& s) {
  s.sp = 20.0f + 8.0f * static_cast<float>((s.scan / 250) % 7);
  // c1(SP := sp + 1.0, PV := pv[1], OUT => u[1], SAT => sat[1]); ... c50: 50 calls
  for (int n = 1; n <= 50; ++n) {
    PiCtrl& c = s.c[n - 1];
    pi_ctrl(c, s.sp + static_cast<float>(n), s.pv[n - 1]);
    s.u[n - 1] = c.out;
    s.sat[n - 1] = c.sat;
  }
  s.outsum = 0.0f;
  for (int i = 1; i <= 50; ++i) {
    s.pv[i - 1] = s.pv[i - 1] + 0.0625f * (s.u[i - 1] - s.pv[i - 1]);
    s.outsum = s.outsum + s.u[i - 1];
    if (s.sat[i - 1]) s.satcount = s.satcount + 1;
  }
  s.satcount = s.satcount % 1000000;
  s.facc = 0;
  for (int k = 1; k <= 200; ++k) s.facc = s.facc + scale_clamp((k * 37 + s.scan) % 1000 - 500, 40, -1000, 1000);
  s.checksum = (s.checksum * 7 + to_dint(s.outsum * 16.0f) + to_dint(s.pv[0] * 1024.0f) + to_dint(s.pv[49] * 1024.0f) +
                s.satcount + s.facc + 200000) %
               100000007;
  s.scan = s.scan + 1;
}

// ---------------------------------------------------------------- nested_fbs.st (plcfi's)

struct NfValve {
  bool cmd = false;
  int64_t stroke = 0;
  bool open = false;
  int32_t opens = 0;
  Ton t_stroke;
  RTrig cmd_edge;
};
inline void nf_valve(NfValve& v, bool cmd, int64_t stroke, int64_t now) {
  v.cmd = cmd;
  v.stroke = stroke;
  r_trig(v.cmd_edge, v.cmd);
  if (v.cmd_edge.q) v.opens = v.opens + 1;
  ton(v.t_stroke, v.cmd, v.stroke, now);
  v.open = v.t_stroke.q;
}

struct NfAxis {
  bool go = false;
  int32_t speed = 0;
  int64_t stroke = 0;
  int32_t pos = 0;
  bool done = false;
  int32_t moves = 0, opens = 0;
  NfValve brake;
  Ton t_settle;
  RTrig done_edge;
};
inline void nf_axis(NfAxis& a, bool go, int32_t speed, int64_t stroke, int64_t now) {
  a.go = go;
  a.speed = speed;
  a.stroke = stroke;
  nf_valve(a.brake, a.go, a.stroke, now);
  a.opens = a.brake.opens;
  if (a.brake.open) {
    a.pos = a.pos + a.speed;
    if (a.pos > 1000) a.pos = 1000;
  } else if (a.pos > 0) {
    a.pos = a.pos - a.speed / 2;
    if (a.pos < 0) a.pos = 0;
  }
  ton(a.t_settle, a.pos >= 1000, 30 * kMs, now);
  a.done = a.t_settle.q;
  r_trig(a.done_edge, a.done);
  if (a.done_edge.q) a.moves = a.moves + 1;
}

struct NfStation {
  bool enable = false;
  int32_t speed = 0;
  int16_t step = 0;
  int32_t cycles = 0, sig = 0;
  NfAxis ax1, ax2;
  Ton t_dwell;
};
inline void nf_station(NfStation& st, bool enable, int32_t speed, int64_t now) {
  st.enable = enable;
  st.speed = speed;
  switch (st.step) {
    case 0:
      if (st.enable) st.step = 1;
      break;
    case 1:
      if (st.ax1.done) st.step = 2;
      break;
    case 2:
      if (st.ax2.done) st.step = 3;
      break;
    case 3:
      if (st.t_dwell.q) st.step = 4;
      break;
    case 4:
      if (st.ax1.pos == 0 && st.ax2.pos == 0) {
        st.cycles = st.cycles + 1;
        st.step = 0;
      }
      break;
    default:
      st.step = 0;
      break;
  }
  nf_axis(st.ax1, st.step >= 1 && st.step <= 3, st.speed, 20 * kMs, now);
  nf_axis(st.ax2, st.step == 2 || st.step == 3, st.speed + 7, 40 * kMs, now);
  ton(st.t_dwell, st.step == 3, 50 * kMs, now);
  st.sig = st.ax1.pos + st.ax2.pos * 3 + int32_t{st.step} * 7 + st.ax1.moves + st.ax2.moves * 5 + st.ax1.opens +
           st.ax2.opens;
}

struct NestedFbs {
  int64_t now_ns = 0;
  std::array<NfStation, 8> st{};  // st1..st8
  int32_t sigsum = 0, cycles = 0, scan = 0, checksum = 0;
};

inline void nested_fbs_scan(NestedFbs& s) {
  const int64_t now = s.now_ns;
  // st<n>(enable := (scan + 25 * (n - 1)) MOD 200 < 150, speed := 35 + 25 * n), n = 1..8
  for (int n = 1; n <= 8; ++n) nf_station(s.st[n - 1], (s.scan + 25 * (n - 1)) % 200 < 150, 35 + 25 * n, now);
  s.sigsum = 0;
  s.cycles = 0;
  for (const NfStation& st : s.st) {
    s.sigsum = s.sigsum + st.sig;
    s.cycles = s.cycles + st.cycles;
  }
  s.checksum = (s.checksum * 31 + s.sigsum + s.cycles) % 1000003;
  s.scan = s.scan + 1;
}

// ---------------------------------------------------------------- crc16.st (plcfi's)

// One CRC-16/MODBUS step over a byte: XOR it in, then 8 shift/test/XOR steps.
inline uint16_t crc16_modbus_byte(uint16_t crc, uint8_t b) {
  crc = static_cast<uint16_t>(crc ^ b);
  for (int j = 1; j <= 8; ++j) crc = (crc & 1u) != 0 ? static_cast<uint16_t>((crc >> 1) ^ 0xA001u) : crc >> 1;
  return crc;
}

struct Crc16 {
  int64_t now_ns = 0;
  std::array<uint8_t, 128> frame{};
  int32_t i = 0;
  int16_t j = 0;
  uint16_t lfsr = 0xACE1, crc = 0xFFFF;
  uint8_t x8 = 0;
  int32_t scan = 0, checksum = 0;
};

inline void crc16_scan(Crc16& s) {
  for (int32_t i = 0; i <= 15; ++i) {
    s.lfsr = (s.lfsr & 1u) != 0 ? static_cast<uint16_t>((s.lfsr >> 1) ^ 0xB400u) : static_cast<uint16_t>(s.lfsr >> 1);
    s.frame[static_cast<size_t>((s.scan * 16 + i) % 128)] = static_cast<uint8_t>(s.lfsr ^ (s.lfsr >> 8));
  }
  s.crc = 0xFFFF;
  for (int i = 0; i <= 127; ++i) s.crc = crc16_modbus_byte(s.crc, s.frame[static_cast<size_t>(i)]);
  s.x8 = 0;
  for (int i = 0; i <= 127; ++i) {
    s.x8 = static_cast<uint8_t>(static_cast<uint8_t>((s.x8 << 1) | (s.x8 >> 7)) ^ s.frame[static_cast<size_t>(i)]);
  }
  s.i = 128;
  s.j = 9;
  s.checksum = (s.checksum * 31 + int32_t{s.crc} + int32_t{s.x8} * 65536) % 1000003;
  s.scan = s.scan + 1;
}

}  // namespace plcfi::bench::matiec
