// Fault models: parsing (with error columns), fit checks, and every model acting through
// a real scan runtime: sensor faults change what the program reads but not the raw layer,
// actuator faults change what reaches the plant but not the program's variables.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include <cmath>
#include <numeric>

#include "engine.hpp"
#include "faults/fault_model.hpp"
#include "runtime/runtime.hpp"
#include "../../support/fake_backend.hpp"

namespace plcfi::faults {
namespace {

// Scripted plant side on the shared fake: delivers `bit` on %IX0.0 and `word` on %IW2,
// reads back %QX0.0 / %QW2.
struct ScriptPlant {
  ScriptPlant() : io(6, 6, "script") {
    io.on_read = [this](uint8_t* in, int64_t) {
      in[0] = bit ? 1 : 0;
      testing_support::FakeBackend::put_u16(in + 4, static_cast<uint16_t>(word));
    };
  }
  bool out_bit() const { return io.outputs[0] & 1; }
  int16_t out_word() const { return io.output_i16(4); }

  testing_support::FakeBackend io;
  bool bit = false;
  int16_t word = 0;
};

// The program copies its inputs and drives outputs from commands the test sets.
const char* kProgram = R"(
PROGRAM P
VAR
  x AT %IX0.0 : BOOL;
  p AT %IW2 : INT;
  y AT %QX0.0 : BOOL;
  sp AT %QW2 : INT;
  seenX : BOOL;
  seenP : INT;
  cmdY : BOOL;
  cmdSp : INT;
END_VAR
seenX := x;
seenP := p;
y := cmdY;
sp := cmdSp;
END_PROGRAM
)";

class FaultFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    b_ = st::build_sources({{"p.st", kProgram}}, st::CompileOptions{});
    ASSERT_TRUE(b_->ok()) << b_->diags.render_all();
    std::string err;
    ASSERT_TRUE(sched_.single_program(*b_->app, "P", 10'000'000, &err)) << err;
    rt_ = std::make_unique<rt::Runtime>(*b_->app, sched_, &plant_.io);
    rt_->cold_restart(1);
    for (const char* v : {"P.seenX", "P.seenP", "P.cmdY", "P.cmdSp", "P.y", "P.sp"}) h_[v] = *st::resolve(*b_->app, v, &err);
  }
  rt::ImageRef ref(const std::string& addr) {
    rt::ImageRef r;
    std::string err;
    EXPECT_TRUE(rt::parse_image_ref(*b_->app, addr, &r, &err)) << err;
    return r;
  }
  // Injects `text` on `addr` now, with the current raw input / delivered output as baseline.
  void inject(const std::string& text, const std::string& addr, uint64_t seed = 7) {
    FaultSpec f;
    std::string err;
    uint32_t col = 0;
    ASSERT_TRUE(parse_fault(text, &f, &err, &col)) << err;
    InjectionContext ctx;
    ctx.ref = ref(addr);
    ctx.baseline = ctx.ref.area == 'I' ? ctx.ref.get(rt_->raw_inputs()) : ctx.ref.get(rt_->delivered_outputs());
    ctx.inject_ns = rt_->now();
    ctx.tick_ns = 10'000'000;
    ctx.seed = seed;
    auto rule = make_rule(f, ctx, &err);
    ASSERT_TRUE(rule) << err;
    (ctx.ref.area == 'I' ? rt_->input_overlay() : rt_->output_overlay()).add(std::move(rule));
  }
  int64_t get(const char* v) { return st::read_int(rt_->machine(), h_[v]); }
  void set(const char* v, int64_t x) { st::write_int(rt_->machine(), h_[v], x); }
  int64_t raw_word() const { return static_cast<int16_t>(rt_->raw_inputs()[4] | (rt_->raw_inputs()[5] << 8)); }
  // Scans once with the plant delivering `word` and returns what the program read.
  int64_t scan_word(int16_t word) {
    plant_.word = word;
    rt_->scan();
    EXPECT_EQ(raw_word(), word);  // the raw layer always holds what the plant delivered
    return get("P.seenP");
  }

  std::unique_ptr<st::Build> b_;
  rt::Schedule sched_;
  ScriptPlant plant_;
  std::unique_ptr<rt::Runtime> rt_;
  std::map<std::string, st::VarHandle> h_;
};

// ------------------------------------------------------------------ parsing

TEST(FaultParse, CanonicalForms) {
  struct Case {
    const char* in;
    Kind kind;
    const char* text;
  };
  for (const Case& c : {Case{"stuck", Kind::StuckCurrent, "stuck"}, Case{" Stuck_At ( TRUE )", Kind::StuckAt, "stuck_at(true)"},
                        Case{"stuck_at(6000)", Kind::StuckAt, "stuck_at(6000)"}, Case{"FROZEN", Kind::Frozen, "frozen"},
                        Case{"offset(-150)", Kind::Offset, "offset(-150)"}, Case{"gain(1.2)", Kind::Gain, "gain(1.2)"},
                        Case{"drift(6/min)", Kind::Drift, "drift(0.1/s)"}, Case{"noise(50)", Kind::Noise, "noise(50)"},
                        Case{"delay(T#200ms)", Kind::Delay, "delay(200ms)"},
                        Case{"intermittent(1s, 0.25)", Kind::Intermittent, "intermittent(1s, 0.25)"},
                        Case{"intermittent(random, 0.3, 100ms)", Kind::Intermittent, "intermittent(random, 0.3, 100ms)"},
                        Case{"inverted", Kind::Inverted, "inverted"}, Case{"open_wire(-32768)", Kind::OpenWire, "open_wire(-32768)"},
                        Case{"no_effect", Kind::NoEffect, "no_effect"}, Case{"stuck_on", Kind::StuckOn, "stuck_on"},
                        Case{"stuck_off", Kind::StuckOff, "stuck_off"}, Case{"delayed(1.5s)", Kind::Delayed, "delayed(1500ms)"}}) {
    FaultSpec f;
    std::string err;
    uint32_t col = 0;
    ASSERT_TRUE(parse_fault(c.in, &f, &err, &col)) << c.in << ": " << err;
    EXPECT_EQ(f.kind, c.kind) << c.in;
    EXPECT_EQ(f.text, c.text) << c.in;
  }
  EXPECT_TRUE(is_actuator_fault(Kind::NoEffect));
  EXPECT_FALSE(is_actuator_fault(Kind::Drift));
}

TEST(FaultParse, ErrorsPointAtTheColumn) {
  struct Case {
    const char* in;
    uint32_t col;
    const char* msg;
  };
  for (const Case& c : {Case{"stuk", 0, "unknown fault model 'stuk'"}, Case{"offset(", 7, "missing ')'"},
                        Case{"gain(abc)", 5, "'abc' is not a number"}, Case{"drift(5)", 6, "rate per time unit"},
                        Case{"drift(5/d)", 8, "unit 'd'"}, Case{"intermittent(1s, 1.5)", 17, "duty cycle must be in 0..1"},
                        Case{"delay(-5ms)", 6, "delay"}, Case{"noise(0)", 6, "sigma must be positive"},
                        Case{"stuck(1)", 6, "stuck takes no arguments"}, Case{"offset(1) x", 10, "unexpected text"},
                        Case{"offset(1,,2)", 9, "empty argument"}, Case{"", 0, "expected a fault model"},
                        Case{"intermittent(random, 2, 1s)", 21, "probability must be in 0..1"}}) {
    FaultSpec f;
    std::string err;
    uint32_t col = 99;
    EXPECT_FALSE(parse_fault(c.in, &f, &err, &col)) << c.in;
    EXPECT_EQ(col, c.col) << c.in << ": " << err;
    EXPECT_NE(err.find(c.msg), std::string::npos) << c.in << ": " << err;
  }
}

TEST_F(FaultFixture, MisfitsNameFaultAndAddress) {
  struct Case {
    const char* fault;
    const char* addr;
    const char* msg;
  };
  for (const Case& c : {Case{"offset(1)", "%IX0.0", "needs an analog signal; %IX0.0 is BOOL"},
                        Case{"stuck_on", "%QW2", "needs a BOOL signal"},
                        Case{"stuck_on", "%IX0.0", "actuator fault; %IX0.0 is not an output"},
                        Case{"stuck", "%QX0.0", "sensor fault; %QX0.0 is not an input"},
                        Case{"stuck_at(5)", "%IX0.0", "is BOOL"}, Case{"inverted", "%IW2", "needs a BOOL signal"}}) {
    FaultSpec f;
    std::string err;
    uint32_t col = 0;
    ASSERT_TRUE(parse_fault(c.fault, &f, &err, &col)) << err;
    InjectionContext ctx;
    ctx.ref = ref(c.addr);
    EXPECT_FALSE(make_rule(f, ctx, &err)) << c.fault << " on " << c.addr;
    EXPECT_NE(err.find(c.msg), std::string::npos) << err;
  }
}

// ------------------------------------------------------------------ sensor faults

TEST_F(FaultFixture, StuckKeepsThePreFaultValueWhileTheRawLayerMoves) {
  plant_.bit = false;
  rt_->scan();
  inject("stuck", "%IX0.0");
  plant_.bit = true;  // the sensor should switch...
  for (int i = 0; i < 5; ++i) rt_->scan();
  EXPECT_EQ(get("P.seenX"), 0);                // ...the program never sees it
  EXPECT_EQ(rt_->raw_inputs()[0] & 1, 1);      // the plant's value is untouched
  rt_->input_overlay().clear();                // withdrawn: the true value again
  rt_->scan();
  EXPECT_EQ(get("P.seenX"), 1);
}

TEST_F(FaultFixture, StuckAtFrozenOpenWire) {
  scan_word(1234);
  inject("frozen", "%IW2");
  EXPECT_EQ(scan_word(5000), 1234);
  rt_->input_overlay().clear();
  inject("stuck_at(6000)", "%IW2");
  EXPECT_EQ(scan_word(10), 6000);
  rt_->input_overlay().clear();
  inject("open_wire", "%IW2");
  EXPECT_EQ(scan_word(10), 0);
  rt_->input_overlay().clear();
  inject("open_wire(-32768)", "P.p");  // through the INT the program declared there
  EXPECT_EQ(scan_word(10), -32768);
  rt_->input_overlay().clear();
  inject("open_wire(-32768)", "%IW2");  // the address takes the INT declared AT it
  EXPECT_EQ(scan_word(10), -32768);
  rt_->input_overlay().clear();
  plant_.bit = true;
  inject("open_wire", "%IX0.0");
  rt_->scan();
  EXPECT_EQ(get("P.seenX"), 0);
  rt_->input_overlay().clear();
  inject("stuck_at(TRUE)", "%IX0.0");
  plant_.bit = false;
  rt_->scan();
  EXPECT_EQ(get("P.seenX"), 1);
}

TEST_F(FaultFixture, OffsetGainAndClampingToTheType) {
  inject("offset(150)", "P.p");
  EXPECT_EQ(scan_word(1000), 1150);
  EXPECT_EQ(scan_word(32700), 32767);  // INT saturates instead of wrapping
  rt_->input_overlay().clear();
  inject("gain(1.5)", "P.p");
  EXPECT_EQ(scan_word(1000), 1500);
  EXPECT_EQ(scan_word(-30000), -32768);
  EXPECT_EQ(scan_word(3), 5);  // 4.5 rounds away from zero
}

TEST_F(FaultFixture, DriftGrowsWithTimeSinceTheInjection) {
  scan_word(100);
  inject("drift(100/s)", "%IW2");  // 1 per 10 ms scan
  EXPECT_EQ(scan_word(100), 100);  // injection scan: no time elapsed yet
  EXPECT_EQ(scan_word(100), 101);
  for (int i = 0; i < 97; ++i) scan_word(100);
  EXPECT_EQ(scan_word(100), 199);
}

TEST_F(FaultFixture, TransportDelay) {
  scan_word(0);
  inject("delay(30ms)", "%IW2");
  std::vector<int64_t> seen;
  for (int16_t v : {10, 20, 30, 40, 50, 60}) seen.push_back(scan_word(v));
  // Three scans of 10 ms: the program sees the baseline, then each value 30 ms late.
  EXPECT_EQ(seen, (std::vector<int64_t>{0, 0, 0, 10, 20, 30}));
}

TEST_F(FaultFixture, IntermittentPeriodicDropsToThePreFaultValue) {
  plant_.bit = false;
  rt_->scan();
  inject("intermittent(100ms, 0.3)", "%IX0.0");
  plant_.bit = true;
  std::string pattern;
  for (int i = 0; i < 20; ++i) {
    rt_->scan();
    pattern += get("P.seenX") ? '1' : '0';
  }
  EXPECT_EQ(pattern, "00011111110001111111");
}

TEST_F(FaultFixture, IntermittentRandomIsSeededAndRoughlyP) {
  auto run = [&](uint64_t seed) {
    rt_->input_overlay().clear();
    plant_.bit = false;
    rt_->scan();
    inject("intermittent(random, 0.3, 10ms)", "%IX0.0", seed);
    plant_.bit = true;
    std::string s;
    for (int i = 0; i < 1000; ++i) {
      rt_->scan();
      s += get("P.seenX") ? '1' : '0';
    }
    return s;
  };
  std::string a = run(1), b = run(1), c = run(2);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  double dropped = static_cast<double>(std::count(a.begin(), a.end(), '0')) / 1000.0;
  EXPECT_NEAR(dropped, 0.3, 0.06);
}

TEST_F(FaultFixture, NoiseIsSeededWithTheGivenSigma) {
  auto run = [&](uint64_t seed) {
    rt_->input_overlay().clear();
    scan_word(5000);
    inject("noise(50)", "%IW2", seed);
    std::vector<double> v;
    for (int i = 0; i < 2000; ++i) v.push_back(static_cast<double>(scan_word(5000)));
    return v;
  };
  auto a = run(3), b = run(3), c = run(4);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  double mean = std::accumulate(a.begin(), a.end(), 0.0) / static_cast<double>(a.size());
  double var = 0;
  for (double x : a) var += (x - mean) * (x - mean);
  double sd = std::sqrt(var / static_cast<double>(a.size() - 1));
  EXPECT_NEAR(mean, 5000, 5);
  EXPECT_NEAR(sd, 50, 5);
}

TEST_F(FaultFixture, InvertedNegatesABool) {
  inject("inverted", "%IX0.0");
  plant_.bit = true;
  rt_->scan();
  EXPECT_EQ(get("P.seenX"), 0);
  plant_.bit = false;
  rt_->scan();
  EXPECT_EQ(get("P.seenX"), 1);
}

// ------------------------------------------------------------------ actuator faults

TEST_F(FaultFixture, NoEffectKeepsThePlantOnThePreFaultCommand) {
  set("P.cmdY", 0);
  rt_->scan();
  inject("no_effect", "%QX0.0");
  set("P.cmdY", 1);
  rt_->scan();
  EXPECT_EQ(get("P.y"), 1);       // the program commands...
  EXPECT_FALSE(plant_.out_bit());   // ...the plant never gets it
  rt_->output_overlay().clear();
  rt_->scan();
  EXPECT_TRUE(plant_.out_bit());
}

TEST_F(FaultFixture, StuckOnAndStuckOff) {
  inject("stuck_on", "%QX0.0");
  set("P.cmdY", 0);
  rt_->scan();
  EXPECT_TRUE(plant_.out_bit());
  EXPECT_EQ(get("P.y"), 0);
  rt_->output_overlay().clear();
  inject("stuck_off", "%QW2");
  set("P.cmdSp", 6000);
  rt_->scan();
  EXPECT_EQ(plant_.out_word(), 0);
  EXPECT_EQ(get("P.sp"), 6000);
}

TEST_F(FaultFixture, DelayedCommandsReachThePlantLate) {
  rt_->scan();
  inject("delayed(20ms)", "%QW2");
  std::vector<int> got;
  for (int v : {100, 200, 300, 400}) {
    set("P.cmdSp", v);
    rt_->scan();
    got.push_back(plant_.out_word());
  }
  EXPECT_EQ(got, (std::vector<int>{0, 0, 100, 200}));
}

TEST_F(FaultFixture, RulesDescribeThemselves) {
  scan_word(42);
  inject("stuck", "%IW2");
  ASSERT_EQ(rt_->input_overlay().rules().size(), 1u);
  EXPECT_EQ(rt_->input_overlay().rules()[0]->describe(), "%IW2: stuck at 42 (its value at the injection)");
}

}  // namespace
}  // namespace plcfi::faults

// ------------------------------------------------------------------ REAL analog values

namespace plcfi::faults {
namespace {

// A REAL sensor is faulted by value (offset, gain, frozen, drift, open wire), not by its bits.
TEST(FaultReal, AnalogRealSensorsAreFaultedByValue) {
  auto b = st::build_sources({{"r.st", "PROGRAM P\nVAR\n  level AT %ID1 : REAL;\n  seen : REAL;\nEND_VAR\nseen := level;\nEND_PROGRAM\n"}},
                             st::CompileOptions{});
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  rt::Schedule sched;
  std::string err;
  ASSERT_TRUE(sched.single_program(*b->app, "P", 10'000'000, &err)) << err;
  float level = 0;
  testing_support::FakeBackend plant(8, 0, "real");  // a REAL at %ID1 (bytes 4..7)
  plant.on_read = [&level](uint8_t* in, int64_t) { std::memcpy(in + 4, &level, 4); };
  rt::Runtime r(*b->app, sched, &plant);
  r.cold_restart(1);
  auto seen = *st::resolve(*b->app, "P.seen", &err);
  rt::ImageRef ref;
  ASSERT_TRUE(rt::parse_image_ref(*b->app, "%ID1", &ref, &err)) << err;
  ASSERT_EQ(ref.type->name, "REAL");
  auto inject = [&](const char* text) {
    FaultSpec f;
    uint32_t col = 0;
    ASSERT_TRUE(parse_fault(text, &f, &err, &col)) << err;
    InjectionContext ctx;
    ctx.ref = ref;
    ctx.baseline = ref.get(r.raw_inputs());
    ctx.inject_ns = r.now();
    ctx.tick_ns = 10'000'000;
    auto rule = make_rule(f, ctx, &err);
    ASSERT_TRUE(rule) << err;
    r.input_overlay().clear();
    r.input_overlay().add(std::move(rule));
  };
  auto scan = [&](float v) {
    level = v;
    r.scan();
    return st::read_real(r.machine(), seen);
  };
  EXPECT_EQ(scan(10.25f), 10.25);
  inject("offset(1.5)");
  EXPECT_EQ(scan(10.25f), 11.75);
  inject("gain(2)");
  EXPECT_EQ(scan(10.25f), 20.5);
  inject("frozen");
  EXPECT_EQ(scan(3.0f), 10.25);  // the value at the injection, whatever the plant delivers
  inject("open_wire(-1.5)");
  EXPECT_EQ(scan(3.0f), -1.5);
  scan(4.0f);
  inject("drift(0.5/s)");
  double v = 0;
  for (int i = 0; i < 100; ++i) v = scan(4.0f);  // one second later
  EXPECT_NEAR(v, 4.5, 0.01);
  r.input_overlay().clear();
  EXPECT_EQ(scan(7.0f), 7.0);
}

}  // namespace
}  // namespace plcfi::faults

namespace plcfi::faults {
namespace {

// Garbage never crashes the parser (nor trips the sanitizers), every error column lies
// within the text, and what it accepts reads back to the same canonical form.
TEST(FaultParse, RandomTextNeverCrashesAndColumnsStayInTheText) {
  const std::string alphabet = "stuck_aoffsetgindrlymw()0123456789.,-+#/ TF";
  std::mt19937_64 rng(11);
  int accepted = 0;
  for (int i = 0; i < 5000; ++i) {
    std::string text;
    size_t len = rng() % 24;
    for (size_t k = 0; k < len; ++k) text += alphabet[rng() % alphabet.size()];
    if (i % 3 == 0) text = std::string(i % 2 ? "delay(" : "stuck_at(") + text;
    FaultSpec f;
    std::string err;
    uint32_t col = 0;
    if (parse_fault(text, &f, &err, &col)) {
      ++accepted;
      FaultSpec again;
      EXPECT_TRUE(parse_fault(f.text, &again, &err, &col)) << text << " -> " << f.text << ": " << err;
      EXPECT_EQ(f.text, again.text);
    } else {
      EXPECT_LE(col, text.size()) << text << ": " << err;
      EXPECT_FALSE(err.empty()) << text;
    }
  }
  EXPECT_LT(accepted, 5000);
}

}  // namespace
}  // namespace plcfi::faults
