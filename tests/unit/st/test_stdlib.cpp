// The standard function blocks called directly on their instances with the scan clock set between calls: timers, counters, edge detectors and bistables.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "engine.hpp"

namespace plcfi::st {
namespace {

const char* kInstances = R"(PROGRAM Main
VAR
  never : BOOL;
  ton1 : TON; tof1 : TOF; tp1 : TP;
  ctu1 : CTU; ctd1 : CTD; ctud1 : CTUD; ctu_d : CTU_DINT; ctud_u : CTUD_UDINT;
  rt : R_TRIG; ft : F_TRIG; sr1 : SR; rs1 : RS;
END_VAR
IF never THEN
  ton1(); tof1(); tp1(); ctu1(); ctd1(); ctud1(); ctu_d(); ctud_u(); rt(); ft(); sr1(); rs1();
END_IF;
END_PROGRAM
)";

constexpr int64_t kMs = 1'000'000;

class Stdlib : public ::testing::Test {
 protected:
  void SetUp() override {
    b = build_sources({{"fbs.st", kInstances}}, CompileOptions{});
    ASSERT_TRUE(b->ok()) << b->diags.render_all();
    m = std::make_unique<Machine>(*b->app);
  }
  VarHandle h(const std::string& path) {
    std::string err;
    auto r = resolve(*b->app, path, &err);
    EXPECT_TRUE(r.has_value()) << err;
    return r.value_or(VarHandle{});
  }
  // Calls the FB instance Main.<fb> once at time `ms`.
  void call(const std::string& fb, int64_t ms) {
    VarHandle inst = h("Main." + fb);
    ASSERT_EQ(TypeKind::Pou, inst.type->kind);
    m->set_now(ms * kMs);
    ASSERT_TRUE(m->call(inst.type->pou->entry, inst.addr)) << m->trap().message;
  }
  void set(const std::string& fb, const std::string& var, int64_t v) { write_int(*m, h("Main." + fb + "." + var), v); }
  int64_t get(const std::string& fb, const std::string& var) { return read_int(*m, h("Main." + fb + "." + var)); }
  bool q(const std::string& fb, const char* out = "Q") { return read_bool(*m, h("Main." + fb + "." + out)); }
  int64_t et_ms(const std::string& fb) { return get(fb, "ET") / kMs; }
  // Timer step: IN and the time, then Q and ET (ms) after the call.
  void timer(const std::string& fb, bool in, int64_t ms, bool want_q, int64_t want_et) {
    set(fb, "IN", in);
    call(fb, ms);
    EXPECT_EQ(want_q, q(fb)) << fb << " Q at t=" << ms << "ms";
    EXPECT_EQ(want_et, et_ms(fb)) << fb << " ET at t=" << ms << "ms";
  }

  std::unique_ptr<Build> b;
  std::unique_ptr<Machine> m;
};

// ------------------------------------------------------------------ TON

TEST_F(Stdlib, TonRisesAfterPtAndFallsWithIn) {
  set("ton1", "PT", 100 * kMs);
  timer("ton1", false, 0, false, 0);
  timer("ton1", true, 10, false, 0);
  timer("ton1", true, 60, false, 50);
  timer("ton1", true, 109, false, 99);
  timer("ton1", true, 110, true, 100);
  timer("ton1", true, 500, true, 100);  // ET stops at PT
  timer("ton1", false, 501, false, 0);
}

TEST_F(Stdlib, TonRestartsWhenInDropsBeforePt) {
  set("ton1", "PT", 100 * kMs);
  timer("ton1", true, 0, false, 0);
  timer("ton1", true, 90, false, 90);
  timer("ton1", false, 95, false, 0);
  timer("ton1", true, 100, false, 0);
  timer("ton1", true, 190, false, 90);
  timer("ton1", true, 200, true, 100);
}

TEST_F(Stdlib, TonWithZeroPtIsOnAtOnce) {
  set("ton1", "PT", 0);
  timer("ton1", false, 0, false, 0);
  timer("ton1", true, 5, true, 0);
  timer("ton1", false, 6, false, 0);
}

// ------------------------------------------------------------------ TOF

TEST_F(Stdlib, TofFollowsInUpAndFallsPtAfterInFalls) {
  set("tof1", "PT", 100 * kMs);
  timer("tof1", false, 0, false, 0);  // no pulse at start
  timer("tof1", true, 10, true, 0);
  timer("tof1", false, 20, true, 0);
  timer("tof1", false, 70, true, 50);
  timer("tof1", false, 119, true, 99);
  timer("tof1", false, 120, false, 100);
  timer("tof1", false, 300, false, 100);  // ET stays at PT while IN is FALSE
  timer("tof1", true, 301, true, 0);
}

TEST_F(Stdlib, TofRetriggeredByInDuringTheDelay) {
  set("tof1", "PT", 100 * kMs);
  timer("tof1", true, 0, true, 0);
  timer("tof1", false, 10, true, 0);
  timer("tof1", false, 90, true, 80);
  timer("tof1", true, 95, true, 0);
  timer("tof1", false, 100, true, 0);  // the full delay starts again
  timer("tof1", false, 199, true, 99);
  timer("tof1", false, 200, false, 100);
}

TEST_F(Stdlib, TofWithZeroPtFallsWithIn) {
  set("tof1", "PT", 0);
  timer("tof1", true, 0, true, 0);
  timer("tof1", false, 1, false, 0);
}

// ------------------------------------------------------------------ TP

TEST_F(Stdlib, TpPulseHasLengthPtWhateverInDoes) {
  set("tp1", "PT", 100 * kMs);
  timer("tp1", false, 0, false, 0);
  timer("tp1", true, 10, true, 0);
  timer("tp1", false, 40, true, 30);  // IN falling does not end the pulse
  timer("tp1", true, 50, true, 40);   // a new edge does not retrigger it
  timer("tp1", true, 109, true, 99);
  timer("tp1", true, 110, false, 100);
  timer("tp1", true, 200, false, 100);  // ET holds PT while IN stays TRUE
  timer("tp1", false, 210, false, 0);
  timer("tp1", true, 220, true, 0);  // next rising edge, next pulse
  timer("tp1", true, 320, false, 100);
}

TEST_F(Stdlib, TpHeldInputGivesOnePulse) {
  set("tp1", "PT", 20 * kMs);
  timer("tp1", true, 0, true, 0);
  timer("tp1", true, 20, false, 20);
  timer("tp1", true, 40, false, 20);
  timer("tp1", true, 1000, false, 20);
}

TEST_F(Stdlib, TpWithZeroPtGivesNoPulse) {
  set("tp1", "PT", 0);
  timer("tp1", true, 0, false, 0);
  timer("tp1", true, 1, false, 0);
}

// ------------------------------------------------------------------ counters

// One counter step: the inputs, then CV and Q after the call.
TEST_F(Stdlib, CtuCountsRisingEdgesUpToAndBeyondPv) {
  set("ctu1", "PV", 3);
  int64_t t = 0;
  auto step = [&](bool cu, bool r, int64_t cv, bool out) {
    set("ctu1", "CU", cu);
    set("ctu1", "R", r);
    call("ctu1", t++);
    EXPECT_EQ(cv, get("ctu1", "CV")) << "step " << t;
    EXPECT_EQ(out, q("ctu1")) << "step " << t;
  };
  step(true, false, 1, false);
  step(true, false, 1, false);  // held: no edge
  step(false, false, 1, false);
  step(true, false, 2, false);
  step(false, false, 2, false);
  step(true, false, 3, true);
  step(false, false, 3, true);
  step(true, false, 4, true);
  step(false, true, 0, false);
  step(true, true, 0, false);    // R wins over an edge on CU
  step(true, false, 0, false);   // CU was already TRUE: no edge
}

TEST_F(Stdlib, CtuStopsAtTheLargestValue) {
  set("ctu1", "PV", 100);
  set("ctu1", "CV", 32766);
  for (int i = 0; i < 3; ++i) {
    set("ctu1", "CU", 1);
    call("ctu1", 2 * i);
    set("ctu1", "CU", 0);
    call("ctu1", 2 * i + 1);
  }
  EXPECT_EQ(32767, get("ctu1", "CV"));
  set("ctu_d", "CV", 2147483646);
  for (int i = 0; i < 3; ++i) {
    set("ctu_d", "CU", 1);
    call("ctu_d", 10 + 2 * i);
    set("ctu_d", "CU", 0);
    call("ctu_d", 11 + 2 * i);
  }
  EXPECT_EQ(2147483647, get("ctu_d", "CV"));
}

TEST_F(Stdlib, CtdLoadsAndCountsDown) {
  int64_t t = 0;
  auto step = [&](bool cd, bool ld, int64_t pv, int64_t cv, bool out) {
    set("ctd1", "CD", cd);
    set("ctd1", "LD", ld);
    set("ctd1", "PV", pv);
    call("ctd1", t++);
    EXPECT_EQ(cv, get("ctd1", "CV")) << "step " << t;
    EXPECT_EQ(out, q("ctd1")) << "step " << t;
  };
  step(false, false, 2, 0, true);  // CV = 0 at start: Q is TRUE
  step(false, true, 2, 2, false);
  step(true, false, 2, 1, false);
  step(true, false, 2, 1, false);
  step(false, false, 2, 1, false);
  step(true, false, 2, 0, true);
  step(false, false, 2, 0, true);
  step(true, false, 2, -1, true);  // counts below zero
  step(false, false, 2, -1, true);
  step(true, true, 5, 5, false);   // LD wins over an edge on CD
  step(true, false, 5, 5, false);  // CD already TRUE: no edge
}

TEST_F(Stdlib, CtdStopsAtTheSmallestValue) {
  set("ctd1", "CV", -32767);
  for (int i = 0; i < 3; ++i) {
    set("ctd1", "CD", 1);
    call("ctd1", 2 * i);
    set("ctd1", "CD", 0);
    call("ctd1", 2 * i + 1);
  }
  EXPECT_EQ(-32768, get("ctd1", "CV"));
}

TEST_F(Stdlib, CtudCountsBothWaysWithResetBeforeLoad) {
  set("ctud1", "PV", 2);
  int64_t t = 0;
  auto step = [&](bool cu, bool cd, bool r, bool ld, int64_t cv, bool qu, bool qd) {
    set("ctud1", "CU", cu);
    set("ctud1", "CD", cd);
    set("ctud1", "R", r);
    set("ctud1", "LD", ld);
    call("ctud1", t++);
    EXPECT_EQ(cv, get("ctud1", "CV")) << "step " << t;
    EXPECT_EQ(qu, q("ctud1", "QU")) << "step " << t;
    EXPECT_EQ(qd, q("ctud1", "QD")) << "step " << t;
  };
  step(false, false, false, false, 0, false, true);
  step(true, false, false, false, 1, false, false);
  step(false, false, false, false, 1, false, false);
  step(true, false, false, false, 2, true, false);
  step(false, false, false, false, 2, true, false);
  step(true, true, false, false, 2, true, false);  // both edges at once: no change
  step(false, false, false, false, 2, true, false);
  step(false, true, false, false, 1, false, false);
  step(false, false, false, true, 2, true, false);   // LD loads PV
  step(false, false, true, true, 0, false, true);    // R wins over LD
  step(false, true, false, false, -1, false, true);
}

TEST_F(Stdlib, CtudUdintDoesNotCountBelowZero) {
  set("ctud_u", "PV", 1);
  set("ctud_u", "CD", 1);
  call("ctud_u", 0);
  EXPECT_EQ(0, get("ctud_u", "CV"));
  EXPECT_TRUE(q("ctud_u", "QD"));
  set("ctud_u", "CD", 0);
  set("ctud_u", "CU", 1);
  call("ctud_u", 1);
  EXPECT_EQ(1, get("ctud_u", "CV"));
  EXPECT_TRUE(q("ctud_u", "QU"));
}

// ------------------------------------------------------------------ edges and bistables

TEST_F(Stdlib, RTrigIsTrueForOneCallOnARisingEdge) {
  const bool clk[] = {true, true, false, false, true, false, true};
  const bool want[] = {true, false, false, false, true, false, true};
  for (int i = 0; i < 7; ++i) {
    set("rt", "CLK", clk[i]);
    call("rt", i);
    EXPECT_EQ(want[i], q("rt")) << "call " << i;
  }
}

TEST_F(Stdlib, FTrigIsTrueForOneCallOnAFallingEdge) {
  // IEC 61131-3 (2nd edition): a first call with CLK FALSE is a falling edge (M starts
  // FALSE and holds NOT CLK).
  const bool clk[] = {false, true, true, false, false, true, false};
  const bool want[] = {true, false, false, true, false, false, true};
  for (int i = 0; i < 7; ++i) {
    set("ft", "CLK", clk[i]);
    call("ft", i);
    EXPECT_EQ(want[i], q("ft")) << "call " << i;
  }
}

TEST_F(Stdlib, SrIsSetDominantAndRsIsResetDominant) {
  struct {
    bool s, r, sr_q, rs_q;
  } steps[] = {
      {false, false, false, false},
      {true, false, true, true},
      {false, false, true, true},   // both latch
      {true, true, true, false},    // SR: set wins; RS: reset wins
      {false, false, true, false},  // each keeps what it had
      {false, true, false, false},
      {true, true, true, false},
  };
  int i = 0;
  for (auto s : steps) {
    set("sr1", "S1", s.s);
    set("sr1", "R", s.r);
    set("rs1", "S", s.s);
    set("rs1", "R1", s.r);
    call("sr1", i);
    call("rs1", i);
    EXPECT_EQ(s.sr_q, q("sr1", "Q1")) << "step " << i;
    EXPECT_EQ(s.rs_q, q("rs1", "Q1")) << "step " << i;
    ++i;
  }
}

}  // namespace
}  // namespace plcfi::st
